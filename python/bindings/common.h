// python/bindings/common.h — what the binding files share: the registration functions each
// file defines (module.cc calls them), keyword arguments read like the command line's flags,
// and numpy arrays over C++ storage without a copy.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/core/notice.h"
#include "plumb/core/option_name.h"
#include "plumb/core/session.h"
#include "plumb/correction/calibration_file.h"
#include "plumb/geo/site.h"
#include "plumb/report/json_report.h"

namespace plumb::python {

/// `option` (core/option_name.h) as this module's keyword: "max_iterations", acc_unit="g" (a
/// value in capitals, a placeholder, unquoted: heading=DEG); an option the module does not
/// take keeps the library's name. The module's init installs it (plumb::SetOptionSpeller).
std::string SpellKeyword(Option option, std::string_view value);
/// `option` as a message names it (the speller the module's init installs): SpellKeyword, a
/// switch as the keyword set ("drop_nan=True", as the command's "--drop-nan").
std::string SpellKeywordInText(Option option, std::string_view value);

namespace py = pybind11;

/// `notices` (core/notice.h) as a list of dicts {code, message, options}, the options a tuple
/// of this module's keywords (SpellKeyword), as plumb.Error's .options: the structured form of
/// a `warnings` list, in its order.
py::list NoticesToPython(const std::vector<Notice>& notices);

/// Each of `notices` emitted through Python's warnings module as a plumb.PlumbWarning (with
/// .code and .options), at the Python line that called the module; raises (an
/// error_already_set) where a warnings filter turns them into errors.
void Warn(const std::vector<Notice>& notices);

/// An input file that is not there: raised as plumb.MissingFileError, which is both a
/// plumb.InputError and Python's FileNotFoundError (errno ENOENT, filename).
class MissingFile : public InputError {
 public:
  explicit MissingFile(const std::string& path);
};

void RegisterErrors(py::module_& m);
void RegisterSession(py::module_& m);
void RegisterCalibrate(py::module_& m);
void RegisterDiagnose(py::module_& m);
void RegisterSimulate(py::module_& m);
void RegisterSweep(py::module_& m);
void RegisterApply(py::module_& m);

/// A session as Python holds it: the samples and what the reader said, and the inputs as given
/// (a calibration document's "inputs").
struct PySession {
  Session session;
  std::vector<std::string> inputs;
};

/// A calibration ready to apply, and the JSON text it was read from (its pickled state).
struct PyCalibration {
  correction::CalibrationFile file;
  std::string text;
};
/// The calibration in the JSON document `text` (a `plumb calibrate --json` document), named
/// `name` in messages, read as load_calibration reads a file: IMU `imu` of a board's (SPEC 6).
std::shared_ptr<PyCalibration> CalibrationOfText(const std::string& text, const std::string& name,
                                                 int imu = 0);

/// A session's state for pickle (a dict of copies: the arrays, units, source, inputs,
/// warnings, site, segments, the log's parameters and motion) and the session it restores,
/// equal in every field.
py::dict SessionState(const PySession& session);
std::shared_ptr<PySession> SessionOfState(const py::dict& state);
/// Notices as picklable tuples (code, message, [option as int]) and back.
py::list NoticesState(const std::vector<Notice>& notices);
std::vector<Notice> NoticesOfState(const py::handle& state);

/// The keyword arguments of one call, taken one by one by name; Finish() refuses the ones no
/// Take asked for (plumb::Error naming them and the accepted names), so that a misspelt
/// option is an error, not silently ignored.
class Keywords {
 public:
  Keywords(std::string function, const py::kwargs& kwargs);
  /// The value of `name` converted to T, or nothing when not given (or None).
  template <typename T>
  std::optional<T> Take(const std::string& name) {
    known_.insert(name);
    if (!kwargs_.contains(name.c_str())) return std::nullopt;
    const py::object value = kwargs_[name.c_str()];
    if (value.is_none()) return std::nullopt;
    try {
      return value.cast<T>();
    } catch (const py::cast_error&) {
      Fail(name, value);
    }
    return std::nullopt;
  }
  template <typename T>
  T Take(const std::string& name, T fallback) {
    return Take<T>(name).value_or(fallback);
  }
  bool Given(const std::string& name) const;
  void Finish() const;

 private:
  [[noreturn]] void Fail(const std::string& name, const py::object& value) const;
  std::string function_;
  py::dict kwargs_;
  std::set<std::string> known_;
};

/// The site from Python: None (nothing given), (lat_deg, lon_deg[, height_m]) or a dict with
/// lat_deg, lon_deg[, height_m]; source "flags" as the command line's --lat/--lon.
std::optional<SiteInput> SiteFromPython(const py::object& site);

/// A read-only numpy array over `data` (rows x cols of T, row stride `row_bytes`), kept alive
/// by `owner` (the Python object that holds the storage).
template <typename T>
py::array View(const T* data, std::size_t rows, std::size_t cols, std::size_t row_bytes,
               const py::object& owner) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(rows)};
  std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(row_bytes)};
  if (cols > 0) {
    shape.push_back(static_cast<py::ssize_t>(cols));
    strides.push_back(static_cast<py::ssize_t>(sizeof(T)));
  }
  py::array out(py::dtype::of<T>(), shape, strides, data, owner);
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

/// Adds `document` (the whole `plumb COMMAND --json` document as a dict) and `to_json()` (its
/// text, byte for byte what the command writes) to a class whose objects hold it as `document`.
template <typename Class>
Class& DocumentMethods(Class& c, const std::string& command);

/// A JSON document as Python objects (dict, list, float, ...), through Python's json module
/// so that numbers keep every bit.
py::object ToPython(const nlohmann::json& doc);
/// A Python dict / list / number ... as JSON (through Python's json module).
nlohmann::json FromPython(const py::handle& object);

template <typename Class>
Class& DocumentMethods(Class& c, const std::string& command) {
  using T = typename Class::type;
  c.def_property_readonly("document", [](const T& t) { return ToPython(t.document); },
                          ("The whole " + command + " --json document as a dict.").c_str());
  c.def("to_json", [](const T& t) { return report::JsonText(t.document); },
        ("The " + command + " --json document as text, byte for byte what the command writes "
         "(the options its messages name spelled as this module's keywords).")
            .c_str());
  return c;
}

}  // namespace plumb::python

#include "plumb/pipeline/fit_setup.h"

namespace plumb::python {

/// What a fit takes besides the samples, from the keywords calibrate() and diagnose() share
/// (the command's --segments, still detection, site, --gravity, --heading, --temp-ref and, with
/// `fit_options`, --level-north, --max-iterations, --strict and the bias wander options), made
/// by the library's pipeline as the command makes it (plumb/pipeline/fit_setup.h).
struct FitInputs {
  segmentation::SegmentationResult segmentation;
  pipeline::FitSetup setup;
  bool strict = false;
};
FitInputs PrepareFit(const PySession& session, const std::string& model_spec,
                     const py::object& site, Keywords& k, bool fit_options);

}  // namespace plumb::python

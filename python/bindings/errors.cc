// plumb's errors as Python exceptions: plumb::Error -> plumb.Error (a subclass of ValueError),
// plumb::InputError -> plumb.InputError (with .file and .where), plumb::InsufficientDataError
// -> plumb.InsufficientDataError, both subclasses of plumb.Error; the message is plumb's.
// Every plumb.Error has .options, a tuple of the options its message points to as this module's
// keywords (plumb::Error::options(); the library's name where no keyword takes it), and
// .option, the first of them or None. Warnings are rendered the same way (NoticesToPython): a
// Session's and a Result's .notices, beside their .warnings.
// A JSON document of the wrong shape (nlohmann::json's exceptions) is a plumb.Error too.
// An input file that is not there (MissingFile, raised by open() before the library reads) is
// plumb.MissingFileError: a plumb.InputError and a FileNotFoundError (errno ENOENT, filename).
// Warnings (Notice) are also emitted through Python's warnings module as plumb.PlumbWarning
// (a UserWarning) with .code and .options (Warn).
#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>

#include "common.h"
#include "plumb/core/error.h"

namespace plumb::python {

py::list NoticesToPython(const std::vector<Notice>& notices) {
  py::list out;
  for (const Notice& n : notices) {
    py::list options;
    for (const Option o : n.options) options.append(SpellKeyword(o, ""));
    py::dict d;
    d["code"] = n.code;
    d["message"] = n.message;
    d["options"] = py::tuple(options);
    out.append(d);
  }
  return out;
}

namespace {
PyObject* warning_type = nullptr;   // plumb.PlumbWarning
PyObject* missing_type = nullptr;   // plumb.MissingFileError
}  // namespace

MissingFile::MissingFile(const std::string& path)
    : InputError(path, "", std::string("cannot open: ") + std::strerror(ENOENT)) {}

void Warn(const std::vector<Notice>& notices) {
  for (const Notice& n : notices) {
    py::list options;
    for (const Option o : n.options) options.append(SpellKeyword(o, ""));
    py::object warning = py::reinterpret_borrow<py::object>(warning_type)(n.message);
    warning.attr("code") = n.code;
    warning.attr("options") = py::tuple(options);
    // stacklevel 1: the Python line that called into the module.
    py::module_::import("warnings").attr("warn")(warning, py::arg("stacklevel") = 1);
  }
}

void RegisterErrors(py::module_& m) {
  static py::exception<Error> error(m, "Error", PyExc_ValueError);
  error.doc() = "plumb's error: the message names the file and the place (line, byte) and what "
                "was expected; .options lists the options it points to (keywords), .option the "
                "first or None.";
  static py::exception<InputError> input_error(m, "InputError", error.ptr());
  input_error.doc() = "Bad input: .file and .where (e.g. 'line 12') say where.";
  static py::exception<InsufficientDataError> insufficient(m, "InsufficientDataError", error.ptr());
  insufficient.doc() = "The data cannot support the model: the message says what to record.";
  const py::object builtins = py::module_::import("builtins");
  const py::object type = builtins.attr("type");
  py::dict missing_body;
  missing_body["__doc__"] = "An input file that is not there: a plumb.InputError and a "
                            "FileNotFoundError (errno ENOENT, filename, .file).";
  missing_body["__module__"] = "plumb";
  py::object missing = type("MissingFileError",
                            py::make_tuple(builtins.attr("FileNotFoundError"), input_error),
                            missing_body);
  m.attr("MissingFileError") = missing;
  missing_type = missing.release().ptr();
  py::dict warning_body;
  warning_body["__doc__"] = "A warning of plumb (a session's or a fit's): the message as in "
                            ".warnings, .code its stable code, .options the keywords it points to.";
  warning_body["__module__"] = "plumb";
  warning_body["code"] = "";
  warning_body["options"] = py::tuple();
  py::object warning = type("PlumbWarning", py::make_tuple(builtins.attr("UserWarning")),
                            warning_body);
  m.attr("PlumbWarning") = warning;
  warning_type = warning.release().ptr();
  // Errors raised without options (a JSON document of the wrong shape) read them from the class.
  error.attr("option") = py::none();
  error.attr("options") = py::tuple();
  // The exception object of class `type` for `e`, with .options and .option.
  static const auto make = [](PyObject* type, const Error& e) {
    py::object value = py::reinterpret_borrow<py::object>(type)(e.what());
    py::list options;
    for (const Option o : e.options()) options.append(SpellKeyword(o, ""));
    value.attr("option") = options.empty() ? py::none() : py::object(options[0]);
    value.attr("options") = py::tuple(options);
    return value;
  };
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const MissingFile& e) {
      py::object value = py::reinterpret_borrow<py::object>(missing_type)(ENOENT, e.what(), e.file());
      value.attr("file") = e.file();
      value.attr("where") = e.where();
      value.attr("option") = py::none();
      value.attr("options") = py::tuple();
      PyErr_SetObject(missing_type, value.ptr());
    } catch (const InputError& e) {
      py::object value = make(input_error.ptr(), e);
      value.attr("file") = e.file();
      value.attr("where") = e.where();
      PyErr_SetObject(input_error.ptr(), value.ptr());
    } catch (const InsufficientDataError& e) {
      PyErr_SetObject(insufficient.ptr(), make(insufficient.ptr(), e).ptr());
    } catch (const Error& e) {
      PyErr_SetObject(error.ptr(), make(error.ptr(), e).ptr());
    } catch (const nlohmann::json::exception& e) {
      PyErr_SetString(error.ptr(), (std::string("JSON: ") + e.what()).c_str());
    }
  });
}

}  // namespace plumb::python

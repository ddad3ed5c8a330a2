// plumb.load_calibration(path) -> Calibration, and Calibration.apply(acc, gyr, temp): the
// corrected specific force and angular rate through the inverse of every effect, as
// `plumb apply` computes them (correction/apply.h).
#include <pybind11/stl.h>

#include <cstring>

#include "common.h"
#include "plumb/core/error.h"
#include "plumb/correction/apply.h"
#include "plumb/correction/calibration_file.h"
#include "plumb/io/text/json_file.h"

namespace plumb::python {
namespace {

const char* const kApplyDoc = R"doc(Apply the calibration to samples: the true specific force
f_b (m/s^2) and angular rate omega_b (rad/s) that produced each output, body FRD.

acc: N x 3 accelerometer output (m/s^2, or the calibration's units), or a Session (then gyr,
     temp and time come from it, read without a copy).
gyr: N x 3 gyroscope output (rad/s); None for an accelerometer-only calibration.
temp: N temperatures (degC), needed by temperature effects.
time: N sample times (s), needed by drift and angular-acceleration effects (alpha_b is
      E^-1 d y_g / dt by central differences, as plumb apply); None: every sample at the
      calibration's reference time (no drift, no angular acceleration).
sigma: also return the calibration's standard deviation of every corrected value.
The samples are taken as float32, plumb's storage (what `plumb apply` reads from a file), so
equal inputs give plumb apply's numbers bit for bit. Returns (f_b, omega_b) as float64 N x 3
arrays (omega_b None without gyr), and with sigma=True (f_b, omega_b, f_sigma, omega_sigma).)doc";

struct PyCalibration {
  correction::CalibrationFile file;
};

/// `array` (N x cols, any float dtype) into `out`, rows as Vec3f.
void Triads(const py::object& array, const char* name, std::vector<Vec3f>& out) {
  const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != 2 || a.shape(1) != 3) {
    throw Error(std::string("apply: ") + name + " must be an N x 3 array of numbers");
  }
  const float* p = a.data();
  out.resize(static_cast<std::size_t>(a.shape(0)));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Vec3f(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
}

ImuSeries SeriesFrom(const PyCalibration& c, const py::object& acc, const py::object& gyr,
                     const py::object& temp, const py::object& time) {
  ImuSeries s;
  Triads(acc, "acc", s.acc);
  const std::size_t n = s.acc.size();
  if (!gyr.is_none()) Triads(gyr, "gyr", s.gyr);
  if (!gyr.is_none() && s.gyr.size() != n) throw Error("apply: acc and gyr differ in length");
  if (!temp.is_none()) {
    const auto t = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(temp);
    if (!t || t.ndim() != 1 || static_cast<std::size_t>(t.shape(0)) != n) {
      throw Error("apply: temp must be N numbers, as many as acc's rows");
    }
    s.temp_c.assign(t.data(), t.data() + n);
  }
  if (time.is_none()) {
    for (const auto& term : c.file.model.terms()) {
      const auto& e = term.effect->info().excitation;
      if (e.time || e.angular_acceleration) {
        throw Error("apply: the model '" + c.file.model.spec() + "' has the effect '" +
                    term.effect->info().name + "', which needs the sample times: give time=");
      }
    }
    s.t_s.assign(n, c.file.model.t_ref_s);
  } else {
    const auto t = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(time);
    if (!t || t.ndim() != 1 || static_cast<std::size_t>(t.shape(0)) != n) {
      throw Error("apply: time must be N numbers, as many as acc's rows");
    }
    s.t_s.assign(t.data(), t.data() + n);
  }
  s.acc_unit = c.file.acc_unit.empty() ? s.acc_unit : c.file.acc_unit;
  s.gyr_unit = c.file.gyr_unit.empty() ? s.gyr_unit : c.file.gyr_unit;
  return s;
}

py::array_t<double> Rows(const std::vector<Vec3>& v) {
  py::array_t<double> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  if (!v.empty()) std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(Vec3));
  return out;
}

py::tuple Apply(const PyCalibration& c, const py::object& acc, const py::object& gyr,
                const py::object& temp, const py::object& time, bool sigma) {
  correction::ApplyOptions options;
  options.uncertainty = sigma;
  correction::CorrectedSeries r;
  if (py::isinstance<PySession>(acc)) {
    if (!gyr.is_none() || !temp.is_none() || !time.is_none()) {
      throw Error("apply: a Session carries its gyr, temp and time: give it alone");
    }
    const PySession& s = acc.cast<const PySession&>();
    py::gil_scoped_release release;
    r = correction::ApplyCalibration(c.file, s.session.series, options);
  } else {
    const ImuSeries series = SeriesFrom(c, acc, gyr, temp, time);
    py::gil_scoped_release release;
    r = correction::ApplyCalibration(c.file, series, options);
  }
  const py::object omega = r.omega_b.empty() ? py::object(py::none()) : Rows(r.omega_b);
  if (!sigma) return py::make_tuple(Rows(r.f_b), omega);
  const py::object omega_sigma =
      r.omega_sigma.empty() ? py::object(py::none()) : Rows(r.omega_sigma);
  return py::make_tuple(Rows(r.f_b), omega, Rows(r.f_sigma), omega_sigma);
}

}  // namespace

void RegisterApply(py::module_& m) {
  py::class_<PyCalibration, std::shared_ptr<PyCalibration>>(
      m, "Calibration",
      "A calibration read back from a `plumb calibrate --json` file: its model, parameters and "
      "covariance, ready to apply to samples.")
      .def_property_readonly("path", [](const PyCalibration& c) { return c.file.path; },
                             "The file it was read from.")
      .def_property_readonly("model", [](const PyCalibration& c) { return c.file.model.spec(); },
                             "The model's spec.")
      .def_property_readonly(
          "parameters",
          [](const PyCalibration& c) {
            const auto names = c.file.model.ParameterNames();
            const auto values = model::ReportedValues(c.file.model, c.file.theta);
            py::dict out;
            for (std::size_t i = 0; i < names.size(); ++i) out[names[i].c_str()] = values[i];
            return out;
          },
          "name -> value, SI (as reported).")
      .def_property_readonly(
          "covariance",
          [](const PyCalibration& c) {
            py::array_t<double> out({c.file.covariance.rows(), c.file.covariance.cols()});
            for (Eigen::Index i = 0; i < c.file.covariance.rows(); ++i) {
              for (Eigen::Index j = 0; j < c.file.covariance.cols(); ++j) {
                out.mutable_at(i, j) = c.file.covariance(i, j);
              }
            }
            return out;
          },
          "The covariance over parameter_names (units squared); 0 x 0 when the file has none.")
      .def_property_readonly("parameter_names",
                             [](const PyCalibration& c) { return c.file.covariance_names; },
                             "The rows and columns of covariance.")
      .def("apply", &Apply, py::arg("acc"), py::arg("gyr") = py::none(),
           py::arg("temp") = py::none(), py::kw_only(), py::arg("time") = py::none(),
           py::arg("sigma") = false, kApplyDoc);
  m.def(
      "load_calibration",
      [](const std::string& path) {
        auto out = std::make_shared<PyCalibration>();
        out->file = correction::ReadCalibrationFile(io::ReadJsonFile(path), path);
        return out;
      },
      py::arg("path"),
      "Read a `plumb calibrate --json` file (Result.save writes one). Raises plumb.InputError "
      "naming the file and the key when it is not such a document.");
}

}  // namespace plumb::python

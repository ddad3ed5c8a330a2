// plumb.load_calibration(path) -> Calibration (also Result.calibration), and
// Calibration.apply(acc, gyr, temp, acc_unit=, gyr_unit=): the
// corrected specific force and angular rate through the inverse of every effect, as
// `plumb apply` computes them (correction/apply.h).
#include <pybind11/stl.h>

#include <cstring>
#include <filesystem>

#include "common.h"
#include "plumb/core/error.h"
#include "plumb/correction/apply.h"
#include "plumb/correction/calibration_file.h"
#include "plumb/io/input/input_spec.h"
#include "plumb/io/text/json_file.h"

namespace plumb::python {
namespace {

const char* const kApplyDoc = R"doc(Apply the calibration to samples: the true specific force
f_b and angular rate omega_b that produced each output, body FRD.

acc: N x 3 accelerometer output in acc_unit, or a Session (then gyr, temp and time come from
     it, read without a copy, in its own units).
gyr: N x 3 gyroscope output in gyr_unit; None for an accelerometer-only calibration.
temp: N temperatures (degC), needed by temperature effects.
time: N sample times (s), needed by drift and angular-acceleration effects (alpha_b is
      E^-1 d y_g / dt by central differences, as plumb apply); None: every sample at the
      calibration's reference time (no drift, no angular acceleration).
sigma: also return the calibration's standard deviation of every corrected value.
acc_unit: 'm/s^2' (default) or 'g'; gyr_unit: 'rad/s' (default) or 'deg/s' (the units open()
      and the command's --acc-unit/--gyr-unit take; a calibration of counts takes 'counts',
      or the default, for samples as they are). The results come back in the same units.
The samples are taken as float32 in SI, plumb's storage (what `plumb apply` reads from a file),
so equal inputs give plumb apply's numbers bit for bit. Returns (f_b, omega_b) as float64
N x 3 arrays (omega_b None without gyr), and with sigma=True (f_b, omega_b, f_sigma,
omega_sigma).)doc";

/// `array` (N x 3, any number dtype) in a unit of `factor` SI units into `out`, rows as Vec3f
/// in SI (float32, as plumb keeps samples: each value v as float(v * factor)).
void Triads(const py::object& array, const char* name, double factor, std::vector<Vec3f>& out) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != 2 || a.shape(1) != 3) {
    throw Error(std::string("apply: ") + name + " must be an N x 3 array of numbers");
  }
  const double* p = a.data();
  out.resize(static_cast<std::size_t>(a.shape(0)));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = Vec3f(static_cast<float>(p[3 * i] * factor), static_cast<float>(p[3 * i + 1] * factor),
                   static_cast<float>(p[3 * i + 2] * factor));
  }
}

/// SI units per unit of the samples given to apply (io::UnitFactor, the units open() takes),
/// checked against the calibration's: a calibration of counts takes counts as they are.
struct Units {
  double acc = 1.0, gyr = 1.0;
};
Units UnitsOf(const PyCalibration& c, const std::string& acc_unit, const std::string& gyr_unit) {
  const io::AccUnit acc = io::ParseAccUnit(acc_unit, "apply: acc_unit");
  const io::GyrUnit gyr = io::ParseGyrUnit(gyr_unit, "apply: gyr_unit");
  const bool acc_counts = c.file.acc_unit == "counts", gyr_counts = c.file.gyr_unit == "counts";
  if (acc_counts != (acc == io::AccUnit::kCounts) && !(acc_counts && acc_unit == "m/s^2")) {
    throw Error("apply: acc_unit='" + acc_unit + "' but the calibration's accelerometer is in " +
                (acc_counts ? "counts" : "m/s^2") + " (" + (acc_counts ? "counts" : "m/s^2 or g") +
                " expected)");
  }
  if (gyr_counts != (gyr == io::GyrUnit::kCounts) && !(gyr_counts && gyr_unit == "rad/s")) {
    throw Error("apply: gyr_unit='" + gyr_unit + "' but the calibration's gyroscope is in " +
                (gyr_counts ? "counts" : "rad/s") + " (" + (gyr_counts ? "counts" : "rad/s or deg/s") +
                " expected)");
  }
  return Units{io::UnitFactor(acc), io::UnitFactor(gyr)};
}

ImuSeries SeriesFrom(const PyCalibration& c, const py::object& acc, const py::object& gyr,
                     const py::object& temp, const py::object& time, const Units& units) {
  ImuSeries s;
  Triads(acc, "acc", units.acc, s.acc);
  const std::size_t n = s.acc.size();
  if (!gyr.is_none()) Triads(gyr, "gyr", units.gyr, s.gyr);
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

/// `v` in units of `factor` SI units (v / factor; as is for 1).
py::array_t<double> Rows(const std::vector<Vec3>& v, double factor) {
  py::array_t<double> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  if (!v.empty()) std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(Vec3));
  if (factor != 1.0) {
    double* p = out.mutable_data();
    for (std::size_t i = 0; i < 3 * v.size(); ++i) p[i] /= factor;
  }
  return out;
}

py::tuple Apply(const PyCalibration& c, const py::object& acc, const py::object& gyr,
                const py::object& temp, const py::object& time, bool sigma,
                const std::string& acc_unit, const std::string& gyr_unit) {
  const Units units = UnitsOf(c, acc_unit, gyr_unit);
  correction::ApplyOptions options;
  options.uncertainty = sigma;
  correction::CorrectedSeries r;
  if (py::isinstance<PySession>(acc)) {
    if (!gyr.is_none() || !temp.is_none() || !time.is_none() || units.acc != 1.0 ||
        units.gyr != 1.0) {
      throw Error("apply: a Session carries its gyr, temp, time and units: give it alone");
    }
    const PySession& s = acc.cast<const PySession&>();
    py::gil_scoped_release release;
    r = correction::ApplyCalibration(c.file, s.session.series, options);
  } else {
    const ImuSeries series = SeriesFrom(c, acc, gyr, temp, time, units);
    py::gil_scoped_release release;
    r = correction::ApplyCalibration(c.file, series, options);
  }
  const py::object omega = r.omega_b.empty() ? py::object(py::none()) : Rows(r.omega_b, units.gyr);
  if (!sigma) return py::make_tuple(Rows(r.f_b, units.acc), omega);
  const py::object omega_sigma =
      r.omega_sigma.empty() ? py::object(py::none()) : Rows(r.omega_sigma, units.gyr);
  return py::make_tuple(Rows(r.f_b, units.acc), omega, Rows(r.f_sigma, units.acc), omega_sigma);
}

std::string Repr(const PyCalibration& c) {
  const correction::CalibrationFile& f = c.file;
  const std::size_t n = f.model.ParameterNames().size();
  return "<plumb.Calibration " + f.model.spec() + " from " + f.path + ": " + std::to_string(n) +
         " parameters, " + std::to_string(f.covariance_names.size()) + " with covariance; " +
         (f.acc_unit.empty() ? "m/s^2" : f.acc_unit) + ", " + (f.gyr_unit.empty() ? "rad/s" : f.gyr_unit) +
         ">";
}

}  // namespace

namespace {

/// IMU `imu`'s calibration in `doc` (read from `path`): IMU 0 as a lone IMU's; a board's IMU k
/// through its own calibration into the body frame (correction::ReadBoardCalibrationFile).
correction::CalibrationFile ImuOf(const nlohmann::json& doc, const std::string& path, int imu) {
  if (imu == 0) return correction::ReadCalibrationFile(doc, path);
  return correction::ImuCalibration(correction::ReadBoardCalibrationFile(doc, path), imu);
}

}  // namespace

std::shared_ptr<PyCalibration> CalibrationOfText(const std::string& text, const std::string& name,
                                                 int imu) {
  auto out = std::make_shared<PyCalibration>();
  out->file = ImuOf(ParseJsonText(name, [&] { return nlohmann::json::parse(text); }), name, imu);
  out->text = text;
  return out;
}

void RegisterApply(py::module_& m) {
  py::class_<PyCalibration, std::shared_ptr<PyCalibration>>(
      m, "Calibration",
      "A calibration: read back from a `plumb calibrate --json` file (load_calibration) or "
      "a Result's (result.calibration); its model, parameters and covariance, ready to apply "
      "to samples. Pickles.")
      .def_property_readonly("path", [](const PyCalibration& c) { return c.file.path; },
                             "The file it was read from ('<plumb.Result>' for result.calibration).")
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
           py::arg("sigma") = false, py::arg("acc_unit") = "m/s^2", py::arg("gyr_unit") = "rad/s",
           kApplyDoc)
      .def("__repr__", &Repr)
      .def_property_readonly("imu", [](const PyCalibration& c) { return c.file.instance; },
                             "The board's IMU it calibrates (SPEC 6; 0 for a lone IMU). A board "
                             "IMU's apply() gives its samples in the body frame.")
      .def(py::pickle(
          [](const PyCalibration& c) {
            return py::make_tuple(2, c.file.path, c.text, c.file.instance);
          },
          [](const py::tuple& t) {
            const int imu = t[0].cast<int>() >= 2 ? t[3].cast<int>() : 0;
            return CalibrationOfText(t[2].cast<std::string>(), t[1].cast<std::string>(), imu);
          }));
  m.def(
      "load_calibration",
      [](const std::string& path, int imu) {
        if (!std::filesystem::exists(path)) throw MissingFile(path);
        const nlohmann::json doc = io::ReadJsonFile(path);
        auto out = std::make_shared<PyCalibration>();
        out->file = ImuOf(doc, path, imu);
        out->text = doc.dump();
        return out;
      },
      py::arg("path"), py::kw_only(), py::arg("imu") = 0,
      "Read a `plumb calibrate --json` file (Result.save writes one); imu=k: IMU k of a board's "
      "(calibrate --imus), whose apply() gives its samples in the body frame, as plumb apply "
      "--imus. Raises plumb.InputError naming the file and the key when it is not such a "
      "document or has no IMU k.");
}

}  // namespace plumb::python

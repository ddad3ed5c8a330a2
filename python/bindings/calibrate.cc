// plumb.calibrate(session, model=..., site=..., **options) -> Result: the generalized fit, as
// `plumb calibrate` makes it; Result.to_json() is the command's `calibrate --json` document,
// made by the same writer (report/json_report.h).
#include <pybind11/stl.h>

#include "common.h"
#include "plumb/core/error.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/uncertainty.h"
#include "plumb/io/text/segments_file.h"
#include "plumb/report/json_report.h"
#include "plumb/segmentation/given_segments.h"

namespace plumb::python {
namespace {

const char* const kCalibrateDoc = R"doc(Calibrate the accelerometer and gyroscope from a session
of still poses joined by turns (the generalized least-squares fit of `plumb calibrate`).

session: a Session (plumb.open, plumb.simulate(...).session).
model: the error model spec: 'base', 'paper', or 'base+EFFECT[:OPTION]+...' (plumb effects).
site: None (the log's GPS, else no site: standard gravity, no Earth rate), or
      (lat_deg, lon_deg[, height_m]) / dict(lat_deg=, lon_deg=, height_m=) as --lat --lon --height.
Keywords (the command's options, '-' as '_'):
  segments (file of given still segments), init_still (s), window (s), min_still (s),
  false_alarm, still_accel_only (bool); gravity (m/s^2, fixed magnitude); heading (deg);
  level_north (bool); temp_ref (degC, 25); max_iterations (200); strict (bool: raise when the
  data cannot determine the model or a gate fails); accel_rw (m/s^3/sqrt(Hz)), gyro_rw
  (rad/s^2/sqrt(Hz)), estimate_rw (bool), accel_bi (m/s^2), gyro_bi (rad/s), bi_time (s),
  constant_bias (bool): the bias wander, SI numbers only.
Returns a Result. Raises plumb.Error (plumb.InsufficientDataError when the data cannot
support the model).)doc";

/// The fitted calibration and what the document says beside it.
struct PyResult {
  estimation::CalibrationResult result;
  segmentation::SegmentationResult segmentation;
  std::vector<std::string> inputs, input_warnings;
  nlohmann::json document;  ///< report::CalibrationJson, made once
};

segmentation::SegmentationResult FindSegments(const ImuSeries& series, Keywords& k) {
  const std::optional<std::string> path = k.Take<std::string>("segments");
  segmentation::StillDetectorOptions d;
  d.init_still_s = k.Take<double>("init_still", d.init_still_s);
  d.window_s = k.Take<double>("window", d.window_s);
  d.min_still_s = k.Take<double>("min_still", d.min_still_s);
  d.false_alarm = k.Take<double>("false_alarm", d.false_alarm);
  d.use_gyro = !k.Take<bool>("still_accel_only", false);
  if (path) return segmentation::UseGivenSegments(series, io::ReadSegments(*path, series));
  d.acc_unit = series.acc_unit;
  d.gyr_unit = series.gyr_unit;
  return segmentation::DetectStillSegments(series, d);
}

void WanderOptions(Keywords& k, estimation::CalibrationOptions& o) {
  o.accel_walk_density = k.Take<double>("accel_rw");
  o.gyro_walk_density = k.Take<double>("gyro_rw");
  o.estimate_walk = k.Take<bool>("estimate_rw", false);
  o.accel_instability = k.Take<double>("accel_bi");
  o.gyro_instability = k.Take<double>("gyro_bi");
  o.instability_time_s = k.Take<double>("bi_time", o.instability_time_s);
  o.constant_bias = k.Take<bool>("constant_bias", false);
  if (o.constant_bias && (o.accel_walk_density || o.gyro_walk_density || o.estimate_walk ||
                          o.accel_instability || o.gyro_instability)) {
    throw Error("constant_bias excludes accel_rw, gyro_rw, estimate_rw, accel_bi, gyro_bi");
  }
}

py::dict Parameters(const PyResult& r) {
  py::module_ ns = py::module_::import("types");
  const double scale = estimation::SigmaScale(r.result.fit);
  py::dict out;
  for (const auto& p : r.result.calibration.parameters) {
    out[p.name.c_str()] = ns.attr("SimpleNamespace")(
        py::arg("value") = p.value, py::arg("sigma") = p.sigma * scale,
        py::arg("sigma_formal") = p.sigma, py::arg("unit") = p.unit,
        py::arg("observable") = p.observable, py::arg("fixed") = p.fixed);
  }
  return out;
}

py::array_t<double> Matrix(const Eigen::MatrixXd& m) {
  py::array_t<double> out({m.rows(), m.cols()});
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j) out.mutable_at(i, j) = m(i, j);
  }
  return out;
}

std::shared_ptr<PyResult> Calibrate(const PySession& s, const std::string& model,
                                    const py::object& site, const py::kwargs& kwargs) {
  Keywords k("calibrate", kwargs);
  FitInputs fit = PrepareFit(s, model, site, k, true);
  k.Finish();
  auto out = std::make_shared<PyResult>();
  {
    py::gil_scoped_release release;
    out->result = estimation::Calibrate(s.session.series, fit.segments, fit.model, fit.site,
                                        fit.options);
  }
  if (fit.strict && !out->result.fit.gates.empty()) {
    std::string names;
    for (const auto& g : out->result.fit.gates) names += (names.empty() ? "" : ", ") + g.name;
    throw Error("the fit of " + s.session.source + " failed gates (" + names +
                ") under strict=True");
  }
  out->segmentation = std::move(fit.segmentation);
  out->inputs = s.inputs;
  out->input_warnings = fit.input_warnings;
  out->document = report::CalibrationJson(out->result, out->segmentation, out->inputs,
                                          out->input_warnings);
  return out;
}

}  // namespace

FitInputs PrepareFit(const PySession& s, const std::string& model_spec, const py::object& site,
                     Keywords& k, bool fit_options) {
  const ImuSeries& series = s.session.series;
  FitInputs out;
  out.segmentation = FindSegments(series, k);
  out.segments = out.segmentation.segments;
  const std::optional<double> gravity = k.Take<double>("gravity");
  out.site = geo::ResolveSite(SiteFromPython(site), s.session.site, gravity);
  out.input_warnings = s.session.warnings;
  if (gravity && out.site.known) {
    out.input_warnings.push_back("gravity fixed at " + std::to_string(*gravity) +
                                 " m/s^2 by --gravity instead of WGS84 normal gravity");
  }
  out.model = model::Model::Parse(model_spec);
  out.model.t_ref_s = series.t_s.front();
  out.model.temp_ref_c = k.Take<double>("temp_ref", 25.0);
  if (const auto heading = k.Take<double>("heading")) out.options.first_heading_deg = *heading;
  if (!fit_options) return out;
  if (k.Take<bool>("level_north", false)) {
    if (out.options.first_heading_deg) throw Error("level_north excludes heading");
    if (!out.segments.empty()) out.segments.front().known_R_n_b = Quat::Identity();
  }
  out.strict = k.Take<bool>("strict", false);
  if (out.strict) out.options.on_insufficient = estimation::InsufficientData::kError;
  out.options.max_iterations = k.Take<int>("max_iterations", out.options.max_iterations);
  if (out.options.max_iterations < 1) throw Error("max_iterations must be >= 1");
  WanderOptions(k, out.options);
  return out;
}

void RegisterCalibrate(py::module_& m) {
  py::class_<PyResult, std::shared_ptr<PyResult>>(
      m, "Result",
      "A calibration and how its fit went: what `plumb calibrate --json` writes, as Python "
      "objects. SI units (sensor units for counts).")
      .def_property_readonly("model", [](const PyResult& r) { return r.result.calibration.model.spec(); },
                             "The fitted model's spec.")
      .def_property_readonly("parameters", &Parameters,
                             "name -> (value, sigma, sigma_formal, unit, observable, fixed): "
                             "the value in SI (unit); sigma one standard deviation as reported "
                             "(scaled by sqrt(chi2/dof) when chi2/dof is above its band), "
                             "sigma_formal unscaled; NaN where unobservable or fixed.")
      .def_property_readonly(
          "covariance",
          [](const PyResult& r) {
            const double scale = estimation::SigmaScale(r.result.fit);
            return Matrix(scale * scale *
                          estimation::ParameterCovariance(r.result.calibration).matrix);
          },
          "Covariance of the free, observable parameters (numpy, units of parameter_names "
          "squared), as the JSON's covariance.matrix: scaled by chi2/dof when above its band.")
      .def_property_readonly(
          "parameter_names",
          [](const PyResult& r) { return estimation::ParameterCovariance(r.result.calibration).names; },
          "The rows and columns of covariance, in model order.")
      .def_property_readonly(
          "sigma_scale", [](const PyResult& r) { return estimation::SigmaScale(r.result.fit); },
          "The factor on every reported sigma: sqrt(chi2/dof) above its band, else 1.")
      .def_property_readonly("observability",
                             [](const PyResult& r) { return ToPython(r.document["observability"]); },
                             "rank, unobservable directions, determined combinations (value, "
                             "sigma): the JSON's observability.")
      .def_property_readonly(
          "fit",
          [](const PyResult& r) {
            py::dict fit = ToPython(r.document["fit"]);
            fit["gates"] = ToPython(r.document["gates"]);
            return fit;
          },
          "chi2, dof, chi2_dof, RMS, convergence, verdict ... (the JSON's fit) and gates (the "
          "checks failed: name, message).")
      .def_property_readonly("site", [](const PyResult& r) { return ToPython(r.document["site"]); },
                             "The site used: lat_deg, lon_deg (degrees), height_m (m), gravity "
                             "(m/s^2), source.")
      .def_property_readonly("warnings", [](const PyResult& r) { return ToPython(r.document["warnings"]); },
                             "What the user must know, in words.")
      .def_property_readonly("document", [](const PyResult& r) { return ToPython(r.document); },
                             "The whole calibrate --json document as a dict.")
      .def("to_json", [](const PyResult& r) { return report::JsonText(r.document); },
           "The calibrate --json document as text, byte for byte what the command writes.")
      .def("save", [](const PyResult& r, const std::string& path) { report::WriteJson(path, r.document); },
           py::arg("path"), "Write the calibrate --json document to path (atomically).")
      .def("__repr__", [](const PyResult& r) {
        return "<plumb.Result " + r.result.calibration.model.spec() + ": chi2/dof " +
               Number(r.result.fit.chi2_dof()) + ">";
      });
  m.def("calibrate", &Calibrate, py::arg("session"), py::arg("model") = "base",
        py::arg("site") = py::none(), kCalibrateDoc);
}

}  // namespace plumb::python

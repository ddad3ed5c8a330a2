// plumb.calibrate(session, model=..., site=..., **options) -> Result: the generalized fit, as
// `plumb calibrate` makes it; Result.to_json() is the command's `calibrate --json` document,
// made by the same writer (report/json_report.h).
#include <pybind11/stl.h>

#include "common.h"
#include "plumb/core/datasheet_level.h"
#include "plumb/core/error.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/correction/calibration_file.h"
#include "plumb/estimation/uncertainty.h"
#include "plumb/report/json_report.h"

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
  constant_bias (bool): the bias wander, each level a number in SI or a text with a datasheet's
  unit as the command takes it ('4 deg/h', '40 ug', '0.3 deg/h/sqrt(h)', '10 ug/sqrt(h)');
  white_turns (bool: the turns' velocity residuals weighted by the white noise alone);
  imu_models (dict: a board IMU's own model, {2: 'base+gyro_g_sensitivity'}, the number as its
  parameters are named, imu2.; the others take model). A session opened with imus= is fitted
  as one board: Result.imus, Result.imus_covariance.
Returns a Result; the fit's warnings (and gravity's) are also emitted as plumb.PlumbWarning
(warnings module). Raises plumb.Error (plumb.InsufficientDataError when the data cannot
support the model).)doc";

/// A calibration and how its fit went, as Python reads them: plain data made once from the
/// fit (so that a pickle of it restores it exactly), the calibration ready to apply.
struct PyResult {
  nlohmann::json document;  ///< report::CalibrationJson, made once
  std::string model;        ///< the fitted model's spec
  /// Every parameter, in model order (`place` not kept).
  std::vector<estimation::ParameterEstimate> parameters;
  double sigma_scale = 1.0;  ///< estimation::SigmaScale
  double chi2_dof = 0.0;
  estimation::NamedCovariance covariance;  ///< formal, of the free observable parameters
  std::vector<estimation::Gate> gates;
  std::vector<Notice> notices;  ///< the input warnings (the session's, gravity's), the fit's
  Eigen::MatrixXd null_space;   ///< Observability::null_space
  std::vector<std::string> null_space_names;
  std::shared_ptr<PyCalibration> calibration;  ///< from the document, as load_calibration
};

/// The calibration of `document` as load_calibration reads it from the file Result.save
/// writes: the document's text parsed again, so that it applies bit for bit alike.
std::shared_ptr<PyCalibration> CalibrationOf(const nlohmann::json& document) {
  return CalibrationOfText(report::JsonText(document), "<plumb.Result>");
}

pipeline::SegmentRequest Segments(Keywords& k) {
  pipeline::SegmentRequest r;
  r.segments_path = k.Take<std::string>("segments", "");
  r.detector.init_still_s = k.Take<double>("init_still", r.detector.init_still_s);
  r.detector.window_s = k.Take<double>("window", r.detector.window_s);
  r.detector.min_still_s = k.Take<double>("min_still", r.detector.min_still_s);
  r.detector.false_alarm = k.Take<double>("false_alarm", r.detector.false_alarm);
  r.still_accel_only = k.Take<bool>("still_accel_only", false);
  return r;
}

/// A bias wander level: a number (SI) or a datasheet's text ("4 deg/h"), both through the
/// command's parser (plumb/core/datasheet_level.h), so that the same checks apply.
std::optional<double> Level(Keywords& k, const char* name, WanderLevel level) {
  const std::optional<py::object> value = k.Take<py::object>(name);
  if (!value) return std::nullopt;
  const std::string text = py::str(*value).cast<std::string>();
  if (!py::isinstance<py::str>(*value) && !py::isinstance<py::float_>(*value) &&
      !(py::isinstance<py::int_>(*value) && !py::isinstance<py::bool_>(*value))) {
    throw Error(std::string("calibrate: ") + name + " must be a number or a text such as '4 deg/h', "
                "got " + py::str(py::repr(*value)).cast<std::string>());
  }
  try {
    return ParseDatasheetLevel(text, level);
  } catch (const Error& e) {
    throw Error(std::string("calibrate: ") + name + ": " + e.what());
  }
}

void WanderOptions(Keywords& k, estimation::CalibrationOptions& o) {
  o.accel_walk_density = Level(k, "accel_rw", WanderLevel::kAccelWalk);
  o.gyro_walk_density = Level(k, "gyro_rw", WanderLevel::kGyroWalk);
  o.estimate_walk = k.Take<bool>("estimate_rw", false);
  o.accel_instability = Level(k, "accel_bi", WanderLevel::kAccelInstability);
  o.gyro_instability = Level(k, "gyro_bi", WanderLevel::kGyroInstability);
  o.instability_time_s = k.Take<double>("bi_time", o.instability_time_s);
  o.constant_bias = k.Take<bool>("constant_bias", false);
  o.turn_vibration = !k.Take<bool>("white_turns", false);
  if (o.constant_bias && (o.accel_walk_density || o.gyro_walk_density || o.estimate_walk ||
                          o.accel_instability || o.gyro_instability)) {
    throw Error("constant_bias excludes accel_rw, gyro_rw, estimate_rw, accel_bi, gyro_bi");
  }
}

py::dict Parameters(const PyResult& r) {
  py::module_ ns = py::module_::import("types");
  py::dict out;
  for (const auto& p : r.parameters) {
    out[p.name.c_str()] = ns.attr("SimpleNamespace")(
        py::arg("value") = p.value, py::arg("sigma") = p.sigma * r.sigma_scale,
        py::arg("sigma_formal") = p.sigma, py::arg("unit") = p.unit,
        py::arg("observable") = p.observable, py::arg("fixed") = p.fixed);
  }
  return out;
}

/// The value (`sigma` false) or the reported sigma of every parameter of parameter_names.
py::array_t<double> Aligned(const PyResult& r, bool sigma) {
  py::array_t<double> out(static_cast<py::ssize_t>(r.covariance.names.size()));
  for (std::size_t i = 0; i < r.covariance.names.size(); ++i) {
    for (const auto& p : r.parameters) {
      if (p.name != r.covariance.names[i]) continue;
      out.mutable_at(static_cast<py::ssize_t>(i)) = sigma ? p.sigma * r.sigma_scale : p.value;
    }
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
  estimation::CalibrationResult result;
  {
    py::gil_scoped_release release;
    result = pipeline::CalibrateSession(s.session, fit.setup);
  }
  if (fit.strict && !result.fit.gates.empty()) {
    throw Error(pipeline::GateFailure(result.fit, s.session.source) + " under strict=True");
  }
  auto out = std::make_shared<PyResult>();
  out->document = report::CalibrationJson(result, fit.segmentation, s.inputs,
                                          fit.setup.input_warnings);
  out->model = result.calibration.model.spec();
  out->parameters = result.calibration.parameters;
  out->sigma_scale = estimation::SigmaScale(result.fit);
  out->chi2_dof = result.fit.chi2_dof();
  out->covariance = estimation::ParameterCovariance(result.calibration);
  out->gates = result.fit.gates;
  out->notices = fit.setup.input_warnings;
  out->notices.insert(out->notices.end(), result.fit.warnings.begin(), result.fit.warnings.end());
  out->null_space = result.calibration.observability.null_space;
  out->null_space_names = result.calibration.observability.null_space_names;
  out->calibration = CalibrationOf(out->document);
  // The warnings the session did not already give when it was opened.
  Warn(std::vector<Notice>(out->notices.begin() + static_cast<std::ptrdiff_t>(s.session.warnings.size()),
                           out->notices.end()));
  return out;
}

py::tuple ResultState(const PyResult& r) {
  py::list parameters;
  for (const auto& p : r.parameters) {
    parameters.append(py::make_tuple(p.name, p.unit, p.value, p.sigma, p.observable, p.fixed));
  }
  py::list gates;
  for (const auto& g : r.gates) {
    py::list options;
    for (const Option o : g.options) options.append(static_cast<int>(o));
    gates.append(py::make_tuple(g.name, g.message, options));
  }
  const auto bytes = nlohmann::json::to_cbor(r.document);
  return py::make_tuple(1, py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                        r.model, parameters, r.sigma_scale, r.chi2_dof, r.covariance.names,
                        Matrix(r.covariance.matrix), gates, NoticesState(r.notices),
                        Matrix(r.null_space), r.null_space_names);
}

Eigen::MatrixXd MatrixOf(const py::handle& array) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
  if (!a || a.ndim() != 2) throw Error("Result state: not a matrix");
  Eigen::MatrixXd out(a.shape(0), a.shape(1));
  for (Eigen::Index i = 0; i < out.rows(); ++i) {
    for (Eigen::Index j = 0; j < out.cols(); ++j) out(i, j) = a.at(i, j);
  }
  return out;
}

std::shared_ptr<PyResult> ResultOfState(const py::tuple& t) {
  if (t.size() != 12 || t[0].cast<int>() != 1) throw Error("Result: a pickled state of another version of plumb");
  auto out = std::make_shared<PyResult>();
  const std::string cbor = t[1].cast<std::string>();
  out->document = nlohmann::json::from_cbor(cbor.begin(), cbor.end());
  out->model = t[2].cast<std::string>();
  for (const auto& item : t[3]) {
    const py::tuple p = item.cast<py::tuple>();
    estimation::ParameterEstimate e;
    e.name = p[0].cast<std::string>();
    e.unit = p[1].cast<std::string>();
    e.value = p[2].cast<double>();
    e.sigma = p[3].cast<double>();
    e.observable = p[4].cast<bool>();
    e.fixed = p[5].cast<bool>();
    out->parameters.push_back(std::move(e));
  }
  out->sigma_scale = t[4].cast<double>();
  out->chi2_dof = t[5].cast<double>();
  out->covariance.names = t[6].cast<std::vector<std::string>>();
  out->covariance.matrix = MatrixOf(t[7]);
  for (const auto& item : t[8]) {
    const py::tuple g = item.cast<py::tuple>();
    std::vector<Option> options;
    for (const auto& o : g[2]) options.push_back(static_cast<Option>(o.cast<int>()));
    out->gates.push_back(estimation::Gate{g[0].cast<std::string>(), g[1].cast<std::string>(), options});
  }
  out->notices = NoticesOfState(t[9]);
  out->null_space = MatrixOf(t[10]);
  out->null_space_names = t[11].cast<std::vector<std::string>>();
  out->calibration = CalibrationOf(out->document);
  return out;
}

}  // namespace

FitInputs PrepareFit(const PySession& s, const std::string& model_spec, const py::object& site,
                     Keywords& k, bool fit_options) {
  FitInputs out;
  out.segmentation = pipeline::FindSegments(s.session.series, Segments(k));
  pipeline::FitRequest request;
  request.site = SiteFromPython(site);
  request.gravity_m_s2 = k.Take<double>("gravity");
  request.model = model::Model::Parse(model_spec);
  request.temp_ref_c = k.Take<double>("temp_ref", request.temp_ref_c);
  estimation::CalibrationOptions& o = request.options;
  o.first_heading_deg = k.Take<double>("heading");
  if (fit_options) {
    request.level_north = k.Take<bool>("level_north", false);
    if (request.level_north && o.first_heading_deg) throw Error("level_north excludes heading");
    out.strict = k.Take<bool>("strict", false);
    if (out.strict) o.on_insufficient = estimation::InsufficientData::kError;
    o.max_iterations = k.Take<int>("max_iterations", o.max_iterations);
    if (o.max_iterations < 1) throw Error("max_iterations must be >= 1");
    WanderOptions(k, o);
    // The board's IMUs' own models (SPEC 6; the command's --imu-model K=SPEC).
    if (const std::optional<py::object> own = k.Take<py::object>("imu_models")) {
      if (!py::isinstance<py::dict>(*own)) {
        throw Error("imu_models must be a dict of IMU number (as in imuK.) to model spec");
      }
      for (const auto& [key, spec] : own->cast<py::dict>()) {
        request.imu_models.emplace(key.cast<int>(), model::Model::Parse(spec.cast<std::string>()));
      }
    }
  }
  out.setup = pipeline::PrepareFit(s.session, out.segmentation, std::move(request));
  return out;
}

void RegisterCalibrate(py::module_& m) {
  py::class_<PyResult, std::shared_ptr<PyResult>> result(
      m, "Result",
      "A calibration and how its fit went: what `plumb calibrate --json` writes, as Python "
      "objects. SI units (sensor units for counts).");
  DocumentMethods(result, "calibrate")
      .def_property_readonly("model", [](const PyResult& r) { return r.model; },
                             "The fitted model's spec.")
      .def_property_readonly("parameters", &Parameters,
                             "name -> (value, sigma, sigma_formal, unit, observable, fixed): "
                             "the value in SI (unit); sigma one standard deviation as reported "
                             "(scaled by sqrt(chi2/dof) when chi2/dof is above its band), "
                             "sigma_formal unscaled; NaN where unobservable or fixed.")
      .def_property_readonly(
          "covariance",
          [](const PyResult& r) {
            return Matrix(r.sigma_scale * r.sigma_scale * r.covariance.matrix);
          },
          "Covariance of the free, observable parameters (numpy, units of parameter_names "
          "squared), as the JSON's covariance.matrix: scaled by chi2/dof when above its band.")
      .def_property_readonly(
          "parameter_names",
          [](const PyResult& r) { return r.covariance.names; },
          "The free, observable parameters, in model order: the rows and columns of covariance, "
          "the entries of values and sigmas.")
      .def_property_readonly("values", [](const PyResult& r) { return Aligned(r, false); },
                             "The values of parameter_names (numpy float64), SI (their unit).")
      .def_property_readonly("sigmas", [](const PyResult& r) { return Aligned(r, true); },
                             "The reported sigmas of parameter_names (numpy float64; scaled as "
                             "parameters' sigma): the square root of covariance's diagonal.")
      .def_property_readonly("null_space", [](const PyResult& r) { return Matrix(r.null_space); },
                             "The unobservable directions (numpy, k x len(null_space_names)): "
                             "row i is observability['unobservable'][i] as numbers (reduced "
                             "row-echelon form, SI), moving the unknowns along it changes no "
                             "prediction; 0 rows when everything is observable.")
      .def_property_readonly("null_space_names", [](const PyResult& r) { return r.null_space_names; },
                             "The columns of null_space: the fit's free unknowns (the model's "
                             "free parameters, then the poses' attitudes ...).")
      .def_property_readonly("calibration", [](const PyResult& r) { return r.calibration; },
                             "The calibration, ready to apply (result.calibration.apply(acc, "
                             "gyr)): a Calibration as load_calibration reads from the file save "
                             "writes, giving the same numbers bit for bit.")
      .def_property_readonly(
          "sigma_scale", [](const PyResult& r) { return r.sigma_scale; },
          "The factor on every reported sigma: sqrt(chi2/dof) above its band, else 1.")
      .def_property_readonly("observability",
                             [](const PyResult& r) { return ToPython(r.document["observability"]); },
                             "rank, unobservable directions, weakly determined combinations "
                             "(held where the fit starts), determined combinations (value, "
                             "sigma): the JSON's observability.")
      .def_property_readonly(
          "fit",
          [](const PyResult& r) {
            py::dict fit = ToPython(r.document["fit"]);
            py::list gates;
            for (const estimation::Gate& g : r.gates) {
              py::dict gate;
              gate["name"] = g.name;
              gate["message"] = g.message;
              py::list options;
              for (const Option o : g.options) options.append(SpellKeyword(o, ""));
              gate["options"] = py::tuple(options);
              gates.append(gate);
            }
            fit["gates"] = gates;
            return fit;
          },
          "chi2, dof, chi2_dof, RMS, convergence, verdict ... (the JSON's fit) and gates (the "
          "checks failed: name, its stable code; message; options, the keywords it points to).")
      .def_property_readonly(
          "imus",
          [](const PyResult& r) -> py::object {
            if (!r.document.contains("imus")) return py::none();
            return ToPython(r.document["imus"]);
          },
          "With the board's IMUs (plumb.open(..., imus=...)): one dict per IMU, IMU 0 first, as "
          "the JSON's imus: instance, model, accel, gyro, effects, parameters, rotation (matrix, "
          "vector, sigma: its frame into the body), lever_arm, time_offset; None without a board.")
      .def_property_readonly(
          "imus_covariance",
          [](const PyResult& r) -> py::object {
            if (!r.document.contains("imus_covariance")) return py::none();
            const nlohmann::json& c = r.document["imus_covariance"];
            const auto n = static_cast<Eigen::Index>(c["parameters"].size());
            Eigen::MatrixXd m(n, n);
            for (Eigen::Index i = 0; i < n; ++i) {
              for (Eigen::Index j = 0; j < n; ++j) {
                const nlohmann::json& v = c["matrix"][static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
                m(i, j) = v.is_number() ? v.get<double>() : std::nan("");
              }
            }
            return Matrix(m);
          },
          "With the board's IMUs: the one covariance over every IMU's parameters (numpy, rows "
          "as imus_parameter_names: IMU 0's, then imu1.*, ...), scaled as covariance; None "
          "without a board.")
      .def_property_readonly(
          "imus_parameter_names",
          [](const PyResult& r) -> py::object {
            if (!r.document.contains("imus_covariance")) return py::none();
            return ToPython(r.document["imus_covariance"]["parameters"]);
          },
          "The names of imus_covariance's rows and columns; None without a board.")
      .def_property_readonly("site", [](const PyResult& r) { return ToPython(r.document["site"]); },
                             "The site used: lat_deg, lon_deg (degrees), height_m (m), gravity "
                             "(m/s^2), source.")
      .def_property_readonly("warnings", [](const PyResult& r) { return ToPython(r.document["warnings"]); },
                             "What the user must know, in words.")
      .def_property_readonly(
          "notices",
          [](const PyResult& r) { return NoticesToPython(r.notices); },
          "The warnings as dicts, in their order: code (stable, e.g. 'site_unknown'), message "
          "(as in warnings), options (the keywords it points to, as plumb.Error's .options).")
      .def("save", [](const PyResult& r, const std::string& path) { report::WriteJson(path, r.document); },
           py::arg("path"), "Write the calibrate --json document to path (atomically).")
      .def("__repr__", [](const PyResult& r) {
        return "<plumb.Result " + r.model + ": chi2/dof " + Number(r.chi2_dof) + ">";
      })
      .def(py::pickle([](const PyResult& r) { return ResultState(r); },
                      [](const py::tuple& t) { return ResultOfState(t); }));
  m.def("calibrate", &Calibrate, py::arg("session"), py::arg("model") = "base",
        py::arg("site") = py::none(), kCalibrateDoc);
}

}  // namespace plumb::python

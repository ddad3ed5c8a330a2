#include "plumb/document/calibration_document.h"

#include <algorithm>
#include <cmath>

#include "plumb/core/calibration_checks.h"
#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/core/number_text.h"
#include "plumb/document/calibration_keys.h"
#include "plumb/document/json_fields.h"
#include "plumb/model/board_mount.h"

namespace plumb::document {
namespace {

using nlohmann::json;
using detail::Field;
using detail::KeyPlace;
namespace k = keys;

std::string TextOr(const json& object, const char* key, const std::string& fallback) {
  return object.is_object() && object.contains(key) && object.at(key).is_string()
             ? object.at(key).get<std::string>()
             : fallback;
}

bool BoolOr(const json& object, const char* key, bool fallback) {
  return object.is_object() && object.contains(key) && object.at(key).is_boolean()
             ? object.at(key).get<bool>()
             : fallback;
}

/// A number, or `fallback` when the key is absent or null (plumb writes null for non-finite
/// values).
double NumberOr(const json& object, const char* key, double fallback) {
  if (!object.is_object() || !object.contains(key) || !object.at(key).is_number()) return fallback;
  return object.at(key).get<double>();
}

/// "model" and "model_reference".
void ReadModel(const json& root, const std::string& path, CalibrationDocument& d) {
  if (root.contains(k::kModel)) {
    const json& spec = root.at(k::kModel);
    if (!spec.is_string()) {
      throw InputError(path, KeyPlace(k::kModel), "expected a model spec (text)");
    }
    d.has_model = true;
    d.model_spec = spec.get<std::string>();
    // An accelerometer-only fit writes its spec with this suffix (model::Model::DropGyro).
    std::string text = d.model_spec;
    const std::string accel_only = k::kAccelerometerOnly;
    const bool drop_gyro = text.size() > accel_only.size() &&
                           text.compare(text.size() - accel_only.size(), accel_only.size(),
                                        accel_only) == 0;
    if (drop_gyro) text.resize(text.size() - accel_only.size());
    try {
      d.model = model::Model::Parse(text);
      if (drop_gyro) d.model->DropGyro();
    } catch (const Error& e) {
      d.model.reset();
      d.model_problem = e.what();
    }
  }
  if (root.contains(k::kModelReference)) {
    const json& ref = root.at(k::kModelReference);
    if (!ref.is_object() || !ref.contains(k::kTRefS) || !ref.contains(k::kTempRefC)) {
      throw InputError(path, KeyPlace(k::kModelReference), "expected {t_ref_s, temp_ref_c}");
    }
    ModelReference r;
    r.t_ref_s = detail::FiniteNumber(ref.at(k::kTRefS), path, "model_reference.t_ref_s");
    r.temp_ref_c = detail::FiniteNumber(ref.at(k::kTempRefC), path, "model_reference.temp_ref_c");
    d.reference = r;
  }
}

/// Whether the document marks a parameter of `sensor`'s matrix ("gyro.matrix.zx") unobservable:
/// its value is one choice among many the data allow.
bool MatrixUndetermined(const std::vector<DocumentParameter>& parameters,
                        const std::string& sensor) {
  const std::string prefix = sensor + ".matrix.";
  return std::any_of(parameters.begin(), parameters.end(), [&](const DocumentParameter& p) {
    return p.name.rfind(prefix, 0) == 0 && !p.observable && !p.fixed;
  });
}

DocumentSensor ReadSensor(const json& sensor, const std::string& name, const std::string& path,
                          const std::vector<DocumentParameter>& parameters) {
  DocumentSensor out;
  out.matrix = detail::Matrix3(
      Field(sensor, k::kMatrix, path, name + ".matrix", "3 rows of 3 numbers"), path,
      name + ".matrix");
  out.bias = detail::Vector3(Field(sensor, k::kBias, path, name + ".bias", "[x, y, z]"), path,
                             name + ".bias");
  if (const std::string p = SensorMatrixProblem(out.matrix); !p.empty()) {
    if (MatrixUndetermined(parameters, name)) {
      throw InputError(path, KeyPlace(name + ".matrix"),
                       "the matrix is " + p + ": its data did not determine it (" + name +
                           ".matrix.* unobservable: a value the fit happened to leave, see "
                           "'observability'); record turns about every axis to calibrate it");
    }
    throw InputError(path, KeyPlace(name + ".matrix"),
                     "the matrix is " + p + ": not a sensor's calibration");
  }
  return out;
}

DocumentParameter ReadParameter(const json& p, const std::string& path, std::size_t index) {
  const std::string where = "parameters[" + std::to_string(index) + "]";
  if (!p.is_object()) throw InputError(path, KeyPlace(where), "expected {name, value, ...}");
  DocumentParameter out;
  const json& name = Field(p, k::kName, path, where + ".name", "a parameter name");
  if (!name.is_string()) throw InputError(path, KeyPlace(where + ".name"), "expected a string");
  out.name = name.get<std::string>();
  out.value = detail::FiniteNumber(Field(p, k::kValue, path, where + ".value", "a number"), path,
                                   where + ".value");
  if (p.contains(k::kSigma) && !p.at(k::kSigma).is_null()) {
    out.sigma = detail::FiniteNumber(p.at(k::kSigma), path, where + ".sigma");
    if (*out.sigma < 0.0) {
      throw InputError(path, KeyPlace(where + ".sigma"),
                       "expected a standard deviation >= 0, not " + p.at(k::kSigma).dump());
    }
  }
  out.observable = BoolOr(p, k::kObservable, true);
  out.fixed = BoolOr(p, k::kFixed, false);
  out.unit = TextOr(p, k::kUnit, "");
  return out;
}

void ReadParameters(const json& root, const std::string& path, CalibrationDocument& d) {
  const json& params = Field(root, k::kParameters, path, "parameters", "a list of parameters");
  if (!params.is_array()) throw InputError(path, KeyPlace("parameters"), "expected a list");
  std::vector<std::string> names;
  for (std::size_t i = 0; i < params.size(); ++i) {
    d.parameters.push_back(ReadParameter(params[i], path, i));
    names.push_back(d.parameters.back().name);
  }
  if (const auto repeat = FirstRepeat(names)) {
    throw InputError(path, KeyPlace("parameters[" + std::to_string(repeat->first) + "].name"),
                     "'" + names[repeat->first] + "' given twice (first at parameters[" +
                         std::to_string(repeat->second) + "])");
  }
}

DocumentSegment ReadSegment(const json& s, const std::string& path, std::size_t index) {
  const std::string where = "segments[" + std::to_string(index) + "]";
  DocumentSegment out;
  out.label = TextOr(s, k::kLabel, where);
  out.acc_mean = detail::Vector3(
      Field(s, k::kAccMean, path, where + ".acc_mean", "the segment's mean accelerometer output"),
      path, where + ".acc_mean");
  out.count = detail::FiniteNumber(
      Field(s, k::kCount, path, where + ".count", "the segment's number of samples"), path,
      where + ".count");
  if (out.count < 0) throw InputError(path, KeyPlace(where + ".count"), "expected a count >= 0");
  return out;
}

/// A square matrix of finite numbers with `n` rows, at `where`.
Eigen::MatrixXd SquareMatrix(const json& m, std::size_t n, const std::string& path,
                             const std::string& where) {
  if (!m.is_array() || m.size() != n) {
    throw InputError(path, KeyPlace(where), "expected " + std::to_string(n) + " rows");
  }
  const auto size = static_cast<Eigen::Index>(n);
  Eigen::MatrixXd out(size, size);
  for (Eigen::Index i = 0; i < size; ++i) {
    const json& row = m[static_cast<std::size_t>(i)];
    const std::string at = where + "[" + std::to_string(i) + "]";
    if (!row.is_array() || row.size() != n) {
      throw InputError(path, KeyPlace(at), "expected " + std::to_string(n) + " numbers");
    }
    for (Eigen::Index j = 0; j < size; ++j) {
      out(i, j) = detail::FiniteNumber(row[static_cast<std::size_t>(j)], path, at);
    }
  }
  return out;
}

/// {"parameters": [names], "matrix": [[...]]} at key `key` (messages): the names, each once,
/// and a covariance over them.
void ReadNamedCovariance(const json& cov, const std::string& key, const std::string& path,
                         std::vector<std::string>& names_out, Eigen::MatrixXd& matrix_out) {
  if (!cov.is_object() || !cov.contains(k::kParameters) || !cov.contains(k::kMatrix) ||
      !cov.at(k::kParameters).is_array()) {
    throw InputError(path, KeyPlace(key), "expected {parameters [...], matrix [[...]]}");
  }
  const json& names = cov.at(k::kParameters);
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!names[i].is_string()) {
      throw InputError(path, KeyPlace(key + ".parameters[" + std::to_string(i) + "]"),
                       "expected a parameter name, not " + names[i].dump());
    }
    names_out.push_back(names[i].get<std::string>());
  }
  if (const auto repeat = FirstRepeat(names_out)) {
    throw InputError(path, KeyPlace(key + ".parameters[" + std::to_string(repeat->first) + "]"),
                     "'" + names_out[repeat->first] + "' given twice (first at [" +
                         std::to_string(repeat->second) + "])");
  }
  matrix_out = SquareMatrix(cov.at(k::kMatrix), names.size(), path, key + ".matrix");
  if (const std::string p = CovarianceProblem(matrix_out); !p.empty()) {
    throw InputError(path, KeyPlace(key + ".matrix"), p);
  }
}

/// "covariance": {"parameters": [names], "matrix": [[...]], "sigma_scaled_by_chi2": bool,
/// "determined": {"matrix": [[...]]}}; null or absent: none.
void ReadCovariance(const json& root, const std::string& path, CalibrationDocument& d) {
  if (!root.contains(k::kCovariance) || root.at(k::kCovariance).is_null()) return;
  const json& cov = root.at(k::kCovariance);
  ReadNamedCovariance(cov, k::kCovariance, path, d.covariance_names, d.covariance);
  d.sigma_scaled_by_chi2 = BoolOr(cov, k::kSigmaScaledByChi2, false);
  if (cov.contains(k::kDetermined) && cov.at(k::kDetermined).is_object() &&
      cov.at(k::kDetermined).contains(k::kMatrix)) {
    const json& m = cov.at(k::kDetermined).at(k::kMatrix);
    if (!m.is_array()) {
      throw InputError(path, KeyPlace("covariance.determined.matrix"), "expected a matrix");
    }
    d.determined_covariance = SquareMatrix(m, m.size(), path, "covariance.determined.matrix");
  }
}

/// "observability.determined": [{combination, parameters, coefficients, value, sigma}, ...].
void ReadDetermined(const json& root, const std::string& path, CalibrationDocument& d) {
  if (!root.contains(k::kObservability) || !root.at(k::kObservability).is_object() ||
      !root.at(k::kObservability).contains(k::kDetermined)) {
    return;
  }
  const json& list = root.at(k::kObservability).at(k::kDetermined);
  if (!list.is_array()) {
    throw InputError(path, KeyPlace("observability.determined"), "expected a list");
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& e = list[i];
    const std::string where = "observability.determined[" + std::to_string(i) + "]";
    if (!e.is_object()) throw InputError(path, KeyPlace(where), "expected an object");
    DocumentCombination c;
    c.text = TextOr(e, k::kCombination, "");
    c.value = detail::FiniteNumber(Field(e, k::kValue, path, where + ".value", "a number"), path,
                                   where + ".value");
    if (e.contains(k::kSigma) && e.at(k::kSigma).is_number()) {
      c.sigma = e.at(k::kSigma).get<double>();
    }
    if (e.contains(k::kParameters) && e.contains(k::kCoefficients)) {
      const json& names = e.at(k::kParameters);
      const json& coefficients = e.at(k::kCoefficients);
      if (!names.is_array() || !coefficients.is_array() || names.size() != coefficients.size()) {
        throw InputError(path, KeyPlace(where),
                         "expected parameters and coefficients, one coefficient each");
      }
      for (std::size_t j = 0; j < names.size(); ++j) {
        if (!names[j].is_string()) {
          throw InputError(path, KeyPlace(where + ".parameters"), "expected names");
        }
        c.names.push_back(names[j].get<std::string>());
        c.coefficients.push_back(
            detail::FiniteNumber(coefficients[j], path, where + ".coefficients"));
      }
    }
    d.determined.push_back(std::move(c));
  }
}

/// The catalogue's description of parameter `name` of `model`, or nullptr.
const model::ParameterInfo* Info(const model::Model& model, const std::string& name) {
  const auto where = model.FindParameter(name);
  if (!where) return nullptr;
  return &model.terms()[static_cast<std::size_t>(where->first)]
              .effect->info()
              .parameters[static_cast<std::size_t>(where->second)];
}

/// The values against their parameters' typical magnitudes (core/calibration_checks.h
/// NoSensorsProblem), where the file's model is one plumb knows (a method's own layout, such
/// as the paper's, is not): the parameters' values, the biases of the sensors' blocks, and the
/// covariance's sigmas.
void CheckMagnitudes(const CalibrationDocument& d) {
  if (!d.model) return;
  const model::Model& m = *d.model;
  const auto problem = [&](const std::string& name, double value) -> std::string {
    const model::ParameterInfo* info = Info(m, name);
    return info ? NoSensorsProblem(value, info->nominal, info->typical, info->unit) : "";
  };
  for (std::size_t i = 0; i < d.parameters.size(); ++i) {
    const DocumentParameter& p = d.parameters[i];
    if (const std::string why = problem(p.name, p.value); !why.empty()) {
      throw InputError(d.path, KeyPlace("parameters[" + std::to_string(i) + "].value"),
                       "'" + p.name + "' = " + why);
    }
  }
  const char* const kAxes[] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    if (d.accel) {
      const std::string why = problem(std::string("accel.bias.") + kAxes[a], d.accel->bias[a]);
      if (!why.empty()) {
        throw InputError(d.path, KeyPlace("accel.bias[" + std::to_string(a) + "]"), why);
      }
    }
    if (d.gyro) {
      const std::string why = problem(std::string("gyro.bias.") + kAxes[a], d.gyro->bias[a]);
      if (!why.empty()) {
        throw InputError(d.path, KeyPlace("gyro.bias[" + std::to_string(a) + "]"), why);
      }
    }
  }
  for (std::size_t i = 0; i < d.covariance_names.size(); ++i) {
    const model::ParameterInfo* info = Info(m, d.covariance_names[i]);
    if (!info) continue;
    const auto at = static_cast<Eigen::Index>(i);
    const double sigma = std::sqrt(d.covariance(at, at));
    if (const std::string p = NoSensorsProblem(sigma, 0.0, info->typical, info->unit); !p.empty()) {
      throw InputError(d.path, KeyPlace("covariance.matrix[" + std::to_string(i) + "]"),
                       "the sigma of '" + d.covariance_names[i] + "', " + p);
    }
  }
}

/// Relative difference allowed between a parameter's "sigma" and the square root of its
/// covariance diagonal: plumb writes both from one matrix at full precision (17 digits), so
/// they agree to rounding; a file whose sigma column says 25586 sigma off while its
/// covariance gives an NEES inside the band was edited.
constexpr double kSigmaAgreement = 1e-6;

/// Each parameter's sigma against the covariance's, where the file gives both.
void CheckSigmasAgree(const CalibrationDocument& d) {
  for (std::size_t i = 0; i < d.parameters.size(); ++i) {
    const DocumentParameter& p = d.parameters[i];
    if (!p.sigma) continue;
    const auto at = std::find(d.covariance_names.begin(), d.covariance_names.end(), p.name);
    if (at == d.covariance_names.end()) continue;
    const auto c = static_cast<Eigen::Index>(at - d.covariance_names.begin());
    const double from_covariance = std::sqrt(std::max(0.0, d.covariance(c, c)));
    if (std::abs(*p.sigma - from_covariance) <=
        kSigmaAgreement * std::max(*p.sigma, from_covariance)) {
      continue;
    }
    throw InputError(d.path, KeyPlace("parameters[" + std::to_string(i) + "].sigma"),
                     "'" + p.name + "' has sigma " + SignificantText(*p.sigma, 6) +
                         " but the covariance gives " + SignificantText(from_covariance, 6) +
                         " (covariance.matrix[" + std::to_string(c) + "][" + std::to_string(c) +
                         "]): plumb writes the two alike; the file was changed after it was "
                         "written");
  }
}

}  // namespace

CalibrationDocument ReadCalibrationDocument(const json& root, const std::string& path,
                                            const ReadOptions& options) {
  if (!root.is_object()) {
    throw InputError(path, "", "expected the JSON object that " + OptionText(Option::kCalibrationJson) + " writes",
                     {Option::kCalibrationJson});
  }
  CalibrationDocument d;
  d.path = path;
  d.method = TextOr(root, k::kMethod, "");
  ReadModel(root, path, d);
  ReadParameters(root, path, d);
  if (root.contains(k::kAccel) && !root.at(k::kAccel).is_null()) {
    d.accel = ReadSensor(root.at(k::kAccel), k::kAccel, path, d.parameters);
  }
  if (root.contains(k::kGyro) && !root.at(k::kGyro).is_null()) {
    d.gyro = ReadSensor(root.at(k::kGyro), k::kGyro, path, d.parameters);
  }
  if (options.still_segments && root.contains(k::kSegments)) {
    const json& segments = root.at(k::kSegments);
    if (!segments.is_array()) throw InputError(path, KeyPlace("segments"), "expected a list");
    for (std::size_t i = 0; i < segments.size(); ++i) {
      d.segments.push_back(ReadSegment(segments[i], path, i));
    }
  }
  const json empty = json::object();
  const json& site = root.contains(k::kSite) ? root.at(k::kSite) : empty;
  d.gravity_m_s2 = NumberOr(site, k::kGravity, 0.0);
  d.site_source = TextOr(site, k::kSource, "");
  const json& fit = root.contains(k::kFit) ? root.at(k::kFit) : empty;
  d.chi2_dof = NumberOr(fit, k::kChi2Dof, std::numeric_limits<double>::quiet_NaN());
  d.dof = static_cast<long>(NumberOr(fit, k::kDof, 0.0));
  const json& noise = root.contains(k::kNoise) ? root.at(k::kNoise) : empty;
  const json& noise_accel =
      noise.is_object() && noise.contains(k::kAccel) ? noise.at(k::kAccel) : empty;
  const bool noise_known = noise_accel.is_array() && noise_accel.size() == 3 &&
                           std::all_of(noise_accel.begin(), noise_accel.end(),
                                       [](const json& v) { return v.is_number(); });
  if (noise_known) d.noise_accel = detail::Vector3(noise_accel, path, "noise.accel");
  ReadCovariance(root, path, d);
  ReadDetermined(root, path, d);
  if (root.contains(k::kInputs) && root.at(k::kInputs).is_array()) {
    for (const auto& input : root.at(k::kInputs)) {
      if (input.is_string()) d.inputs.push_back(input.get<std::string>());
    }
  }
  CheckMagnitudes(d);
  CheckSigmasAgree(d);
  return d;
}

namespace {

/// The names of a board mount's parameters, without a prefix (model/board_mount.h).
bool IsMountParameter(const std::string& name) {
  static const model::EffectInfo kMount = model::board_mount::Describe();
  return std::any_of(kMount.parameters.begin(), kMount.parameters.end(),
                     [&](const model::ParameterInfo& p) { return p.name == name; });
}

/// Entry i of "imus", IMU k > 0: its own document (its keys, the root's model_reference) and
/// its mount's parameters.
BoardImuDocument ReadBoardImu(const json& root, const json& entry, std::size_t i,
                              const std::string& path) {
  const std::string where = std::string(k::kImus) + "[" + std::to_string(i) + "]";
  BoardImuDocument out;
  out.instance = static_cast<int>(detail::FiniteNumber(
      Field(entry, k::kInstance, path, where + "." + k::kInstance, "the IMU's instance"), path,
      where + "." + k::kInstance));
  const std::string prefix = "imu" + std::to_string(out.instance) + ".";
  json own = json::object();
  for (const char* key : {k::kModel, k::kAccel, k::kGyro}) {
    if (entry.contains(key)) own[key] = entry.at(key);
  }
  if (root.contains(k::kModelReference)) own[k::kModelReference] = root.at(k::kModelReference);
  const json& params = Field(entry, k::kParameters, path, where + ".parameters", "a list");
  if (!params.is_array()) throw InputError(path, KeyPlace(where + ".parameters"), "expected a list");
  own[k::kParameters] = json::array();
  const std::string own_path = path + ", " + where;
  for (std::size_t j = 0; j < params.size(); ++j) {
    DocumentParameter p = ReadParameter(params[j], own_path, j);
    if (p.name.rfind(prefix, 0) != 0) {
      throw InputError(path, KeyPlace(where + ".parameters[" + std::to_string(j) + "].name"),
                       "'" + p.name + "' lacks the prefix '" + prefix + "' of IMU " +
                           std::to_string(out.instance));
    }
    p.name.erase(0, prefix.size());
    if (IsMountParameter(p.name)) {
      out.mount.push_back(p);
      continue;
    }
    json stripped = params[j];
    stripped[k::kName] = p.name;
    own[k::kParameters].push_back(stripped);
  }
  ReadOptions options;
  options.still_segments = false;
  out.document = ReadCalibrationDocument(own, own_path, options);
  return out;
}

}  // namespace

BoardDocument ReadBoardDocument(const json& root, const std::string& path) {
  BoardDocument out;
  if (!root.is_object() || !root.contains(k::kImus)) return out;
  const json& imus = root.at(k::kImus);
  if (!imus.is_array() || imus.empty() || !imus[0].is_object()) {
    throw InputError(path, KeyPlace(k::kImus), "expected a list of the board's IMUs, IMU 0 first");
  }
  std::vector<std::string> instances = {"0"};
  for (std::size_t i = 1; i < imus.size(); ++i) {
    if (!imus[i].is_object()) {
      throw InputError(path, KeyPlace(std::string(k::kImus) + "[" + std::to_string(i) + "]"),
                       "expected {instance, model, parameters, ...}");
    }
    out.imus.push_back(ReadBoardImu(root, imus[i], i, path));
    instances.push_back(std::to_string(out.imus.back().instance));
  }
  if (const auto repeat = FirstRepeat(instances)) {
    throw InputError(path,
                     KeyPlace(std::string(k::kImus) + "[" + std::to_string(repeat->first) + "]." +
                              k::kInstance),
                     "IMU " + instances[repeat->first] + " given twice (first at [" +
                         std::to_string(repeat->second) + "])");
  }
  if (root.contains(k::kImusCovariance) && !root.at(k::kImusCovariance).is_null()) {
    ReadNamedCovariance(root.at(k::kImusCovariance), k::kImusCovariance, path,
                        out.covariance_names, out.covariance);
  }
  return out;
}

CalibrationDocument ReadCalibrationDocumentFile(const std::string& path,
                                                const ReadOptions& options) {
  return ReadCalibrationDocument(detail::ParseJsonFile(path), path, options);
}

const DocumentParameter* FindParameter(const CalibrationDocument& document,
                                       const std::string& name) {
  for (const auto& p : document.parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

}  // namespace plumb::document

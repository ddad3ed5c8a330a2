#include "plumb/correction/calibration_file.h"

#include <algorithm>
#include <cmath>

#include "plumb/core/calibration_checks.h"
#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/core/option_name.h"

namespace plumb::correction {
namespace {

using nlohmann::json;

double FiniteNumber(const json& v, const std::string& path, const std::string& key) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    throw InputError(path, "key '" + key + "'", "expected a finite number");
  }
  return v.get<double>();
}

const json& Required(const json& doc, const char* key, const std::string& path) {
  if (!doc.contains(key)) {
    throw InputError(path, "key '" + std::string(key) + "'",
                     "missing: not a calibration written by " + OptionText(Option::kCalibrationJson));
  }
  return doc.at(key);
}

/// The model of the document, with its reference time and temperature.
model::Model ReadModel(const json& doc, const std::string& path) {
  const json& spec = Required(doc, "model", path);
  if (!spec.is_string()) throw InputError(path, "key 'model'", "expected a model spec (text)");
  // An accelerometer-only fit writes its spec with this suffix (model::Model::DropGyro).
  std::string text = spec.get<std::string>();
  const std::string accel_only = " (accelerometer only)";
  const bool drop_gyro = text.size() > accel_only.size() &&
                         text.compare(text.size() - accel_only.size(), accel_only.size(),
                                      accel_only) == 0;
  if (drop_gyro) text.resize(text.size() - accel_only.size());
  model::Model model = [&] {
    try {
      return model::Model::Parse(text);
    } catch (const Error& e) {
      throw InputError(path, "key 'model'", e.what());
    }
  }();
  if (drop_gyro) model.DropGyro();
  const json& ref = Required(doc, "model_reference", path);
  if (!ref.is_object() || !ref.contains("t_ref_s") || !ref.contains("temp_ref_c")) {
    throw InputError(path, "key 'model_reference'", "expected {t_ref_s, temp_ref_c}");
  }
  model.t_ref_s = FiniteNumber(ref.at("t_ref_s"), path, "model_reference.t_ref_s");
  model.temp_ref_c = FiniteNumber(ref.at("temp_ref_c"), path, "model_reference.temp_ref_c");
  return model;
}

/// The catalogue's description of parameter (term t, index i) of `model`.
const model::ParameterInfo& Info(const model::Model& model, int t, int i) {
  return model.terms()[static_cast<std::size_t>(t)]
      .effect->info()
      .parameters[static_cast<std::size_t>(i)];
}


/// The checks of core/calibration_checks.h on the sensors' matrices of `out`.
void CheckMatrices(const CalibrationFile& out) {
  const model::SensorOutput<double> linear =
      out.model.Predict(out.theta, model::SensorInput<double>());
  if (const std::string p = SensorMatrixProblem(linear.F); !p.empty()) {
    throw InputError(out.path, "key 'parameters' (accel.matrix.*)",
                     "the accelerometer's matrix is " + p + ": not a calibration to apply");
  }
  if (!out.model.has_gyro()) return;
  if (const std::string p = SensorMatrixProblem(linear.E); !p.empty()) {
    throw InputError(out.path, "key 'parameters' (gyro.matrix.*)",
                     "the gyroscope's matrix is " + p + ": not a calibration to apply");
  }
}

/// The covariance over named parameters of the model (none: empty).
void ReadCovariance(const json& doc, const std::string& path, CalibrationFile& out) {
  if (!doc.contains("covariance") || doc.at("covariance").is_null()) return;
  const json& cov = doc.at("covariance");
  if (!cov.is_object() || !cov.contains("parameters") || !cov.contains("matrix") ||
      !cov.at("parameters").is_array() || !cov.at("matrix").is_array()) {
    throw InputError(path, "key 'covariance'", "expected {parameters [...], matrix [[...]]}");
  }
  const auto n = static_cast<Eigen::Index>(cov.at("parameters").size());
  for (const json& name : cov.at("parameters")) {
    if (!name.is_string() || !out.model.FindParameter(name.get<std::string>())) {
      throw InputError(path, "key 'covariance.parameters'",
                       "'" + name.dump() + "' is not a parameter of the model '" + out.model.spec() + "'");
    }
    out.covariance_names.push_back(name.get<std::string>());
  }
  if (const auto repeat = FirstRepeat(out.covariance_names)) {
    throw InputError(path, "key 'covariance.parameters[" + std::to_string(repeat->first) + "]'",
                     "'" + out.covariance_names[repeat->first] + "' given twice (first at [" +
                         std::to_string(repeat->second) + "])");
  }
  const json& m = cov.at("matrix");
  if (static_cast<Eigen::Index>(m.size()) != n) {
    throw InputError(path, "key 'covariance.matrix'", "expected " + std::to_string(n) + " rows");
  }
  out.covariance.resize(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const json& row = m.at(static_cast<std::size_t>(i));
    if (!row.is_array() || static_cast<Eigen::Index>(row.size()) != n) {
      throw InputError(path, "key 'covariance.matrix[" + std::to_string(i) + "]'",
                       "expected " + std::to_string(n) + " numbers");
    }
    for (Eigen::Index j = 0; j < n; ++j) {
      out.covariance(i, j) = FiniteNumber(row.at(static_cast<std::size_t>(j)), path,
                                          "covariance.matrix[" + std::to_string(i) + "]");
    }
  }
  if (const std::string p = CovarianceProblem(out.covariance); !p.empty()) {
    throw InputError(path, "key 'covariance.matrix'", p);
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto [t, k] = *out.model.FindParameter(out.covariance_names[static_cast<std::size_t>(i)]);
    const double sigma = std::sqrt(out.covariance(i, i));
    const model::ParameterInfo& info = Info(out.model, t, k);
    if (const std::string p = NoSensorsProblem(sigma, 0.0, info.typical, info.unit); !p.empty()) {
      throw InputError(path, "key 'covariance.matrix[" + std::to_string(i) + "]'",
                       "the sigma of '" + out.covariance_names[static_cast<std::size_t>(i)] +
                           "', " + p);
    }
  }
}

}  // namespace

CalibrationFile ReadCalibrationFile(const json& doc, const std::string& path) {
  if (!doc.is_object()) throw InputError(path, "", "not a JSON object: not a calibration");
  CalibrationFile out;
  out.path = path;
  out.model = ReadModel(doc, path);
  const json& params = Required(doc, "parameters", path);
  if (!params.is_array()) throw InputError(path, "key 'parameters'", "expected a list");
  // An accelerometer-only session's fit dropped the gyroscope terms of its spec.
  const bool gyro_values = std::any_of(params.begin(), params.end(), [](const json& p) {
    return p.is_object() && p.contains("name") && p.at("name").is_string() &&
           p.at("name").get<std::string>().rfind("gyro", 0) == 0;
  });
  if (!gyro_values && out.model.has_gyro()) out.model.DropGyro();
  out.theta = out.model.ZeroParameters();
  std::vector<bool> seen(static_cast<std::size_t>(out.model.num_parameters()), false);
  const std::vector<std::string> names = out.model.ParameterNames();
  std::vector<std::string> given;
  for (const json& p : params) {
    const bool named = p.is_object() && p.contains("name") && p.at("name").is_string();
    given.push_back(named ? p.at("name").get<std::string>() : std::string());
  }
  if (const auto repeat = FirstRepeat(given); repeat && !given[repeat->first].empty()) {
    throw InputError(path, "key 'parameters[" + std::to_string(repeat->first) + "].name'",
                     "'" + given[repeat->first] + "' given twice (first at parameters[" +
                         std::to_string(repeat->second) + "])");
  }
  for (std::size_t k = 0; k < params.size(); ++k) {
    const json& p = params[k];
    const std::string key = "parameters[" + std::to_string(k) + "]";
    if (!p.is_object() || !p.contains("name") || !p.at("name").is_string() || !p.contains("value")) {
      throw InputError(path, "key '" + key + "'", "expected {name, value, ...}");
    }
    const std::string name = p.at("name").get<std::string>();
    const auto where = out.model.FindParameter(name);
    if (!where) {
      throw InputError(path, "key '" + key + ".name'",
                       "'" + name + "' is not a parameter of the model '" + out.model.spec() + "'");
    }
    const auto [t, i] = *where;
    const model::ParameterInfo& info = Info(out.model, t, i);
    const double value = FiniteNumber(p.at("value"), path, key + ".value");
    if (const std::string p = NoSensorsProblem(value, info.nominal, info.typical, info.unit);
        !p.empty()) {
      throw InputError(path, "key '" + key + ".value'", "'" + name + "' = " + p);
    }
    out.theta[static_cast<std::size_t>(t)][static_cast<std::size_t>(i)] = value - info.nominal;
    seen[static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin())] = true;
    if (p.contains("unit") && p.at("unit").is_string()) {
      if (name == "accel.bias.x") out.acc_unit = p.at("unit").get<std::string>();
      if (name == "gyro.bias.x") out.gyr_unit = p.at("unit").get<std::string>();
    }
  }
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (!seen[j]) throw InputError(path, "key 'parameters'", "no value for '" + names[j] + "'");
  }
  CheckMatrices(out);
  ReadCovariance(doc, path, out);
  return out;
}

}  // namespace plumb::correction

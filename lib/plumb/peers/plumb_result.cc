#include "plumb/peers/plumb_result.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <nlohmann/json.hpp>

#include "plumb/core/calibration_checks.h"
#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/core/option_name.h"
#include "plumb/model/model.h"
#include "plumb/peers/json_fields.h"

namespace plumb::peers {
namespace {

using nlohmann::json;
using detail::Field;
using detail::KeyPlace;

std::string TextOr(const json& object, const std::string& key, const std::string& fallback) {
  return object.is_object() && object.contains(key) && object.at(key).is_string()
             ? object.at(key).get<std::string>()
             : fallback;
}

bool BoolOr(const json& object, const std::string& key, bool fallback) {
  return object.contains(key) && object.at(key).is_boolean() ? object.at(key).get<bool>() : fallback;
}

/// A number, or NaN when the key is absent or null (plumb writes null for non-finite values).
double NumberOr(const json& object, const std::string& key, double fallback) {
  if (!object.is_object() || !object.contains(key) || !object.at(key).is_number()) return fallback;
  return object.at(key).get<double>();
}

void ReadSensor(const json& root, const std::string& name, const std::string& path, Mat3& matrix,
                Vec3& bias) {
  const json& sensor = Field(root, name, path, name, "{\"matrix\": ..., \"bias\": ...}");
  matrix = detail::Matrix3(Field(sensor, "matrix", path, name + ".matrix", "3 rows of 3 numbers"),
                           path, name + ".matrix");
  bias = detail::Vector3(Field(sensor, "bias", path, name + ".bias", "[x, y, z]"), path,
                         name + ".bias");
  if (const std::string p = SensorMatrixProblem(matrix); !p.empty()) {
    throw InputError(path, KeyPlace(name + ".matrix"),
                     "the matrix is " + p + ": not a sensor's calibration");
  }
}

PlumbParameter ReadParameter(const json& p, const std::string& path, std::size_t index) {
  const std::string where = "parameters[" + std::to_string(index) + "]";
  PlumbParameter out;
  const json& name = Field(p, "name", path, where + ".name", "a parameter name");
  if (!name.is_string()) throw InputError(path, KeyPlace(where + ".name"), "expected a string");
  out.name = name.get<std::string>();
  out.value = detail::FiniteNumber(Field(p, "value", path, where + ".value", "a number"), path,
                                   where + ".value");
  if (p.contains("sigma") && !p.at("sigma").is_null()) {
    out.sigma = detail::FiniteNumber(p.at("sigma"), path, where + ".sigma");
    if (*out.sigma < 0.0) {
      throw InputError(path, KeyPlace(where + ".sigma"),
                       "expected a standard deviation >= 0, not " + p.at("sigma").dump());
    }
  }
  out.observable = BoolOr(p, "observable", true);
  out.fixed = BoolOr(p, "fixed", false);
  out.unit = TextOr(p, "unit", "");
  return out;
}

PlumbStillSegment ReadSegment(const json& s, const std::string& path, std::size_t index) {
  const std::string where = "segments[" + std::to_string(index) + "]";
  PlumbStillSegment out;
  out.label = TextOr(s, "label", where);
  out.acc_mean = detail::Vector3(
      Field(s, "acc_mean", path, where + ".acc_mean", "the segment's mean accelerometer output"),
      path, where + ".acc_mean");
  out.count = detail::FiniteNumber(
      Field(s, "count", path, where + ".count", "the segment's number of samples"), path,
      where + ".count");
  if (out.count < 0) throw InputError(path, KeyPlace(where + ".count"), "expected a count >= 0");
  return out;
}


/// "covariance": {"parameters": [names], "matrix": [[...]], "sigma_scaled_by_chi2": bool}.
void ReadCovariance(const json& cov, const std::string& path, PlumbResult& r) {
  const json& names = Field(cov, "parameters", path, "covariance.parameters", "a list of names");
  const json& matrix = Field(cov, "matrix", path, "covariance.matrix", "a square matrix");
  if (!names.is_array() || !matrix.is_array() || matrix.size() != names.size()) {
    throw InputError(path, KeyPlace("covariance"),
                     "expected a list of names and a matrix with a row for each");
  }
  const auto n = static_cast<Eigen::Index>(names.size());
  r.covariance.resize(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const json& name = names[static_cast<std::size_t>(i)];
    if (!name.is_string()) throw InputError(path, KeyPlace("covariance.parameters"), "expected names");
    r.covariance_names.push_back(name.get<std::string>());
    const json& row = matrix[static_cast<std::size_t>(i)];
    const std::string where = "covariance.matrix[" + std::to_string(i) + "]";
    if (!row.is_array() || row.size() != names.size()) {
      throw InputError(path, KeyPlace(where), "expected " + std::to_string(n) + " numbers");
    }
    for (Eigen::Index j = 0; j < n; ++j) {
      r.covariance(i, j) = detail::FiniteNumber(row[static_cast<std::size_t>(j)], path, where);
    }
  }
  if (const auto repeat = FirstRepeat(r.covariance_names)) {
    throw InputError(path, KeyPlace("covariance.parameters[" + std::to_string(repeat->first) + "]"),
                     "'" + r.covariance_names[repeat->first] + "' given twice (first at [" +
                         std::to_string(repeat->second) + "])");
  }
  if (const std::string p = CovarianceProblem(r.covariance); !p.empty()) {
    throw InputError(path, KeyPlace("covariance.matrix"), p);
  }
  r.sigma_scaled_by_chi2 = cov.contains("sigma_scaled_by_chi2") &&
                           cov.at("sigma_scaled_by_chi2").is_boolean() &&
                           cov.at("sigma_scaled_by_chi2").get<bool>();
  if (cov.contains("determined") && cov.at("determined").is_object() &&
      cov.at("determined").contains("matrix")) {
    const json& m = cov.at("determined").at("matrix");
    if (!m.is_array()) throw InputError(path, KeyPlace("covariance.determined.matrix"), "expected a matrix");
    const auto k = static_cast<Eigen::Index>(m.size());
    r.determined_covariance.resize(k, k);
    for (Eigen::Index i = 0; i < k; ++i) {
      const json& row = m[static_cast<std::size_t>(i)];
      const std::string where = "covariance.determined.matrix[" + std::to_string(i) + "]";
      if (!row.is_array() || row.size() != m.size()) {
        throw InputError(path, KeyPlace(where), "expected " + std::to_string(k) + " numbers");
      }
      for (Eigen::Index j = 0; j < k; ++j) {
        r.determined_covariance(i, j) =
            detail::FiniteNumber(row[static_cast<std::size_t>(j)], path, where);
      }
    }
  }
}

/// "observability.determined": [{combination, parameters, coefficients, value, sigma}, ...].
void ReadDetermined(const json& list, const std::string& path, PlumbResult& r) {
  if (!list.is_array()) throw InputError(path, KeyPlace("observability.determined"), "expected a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& d = list[i];
    const std::string where = "observability.determined[" + std::to_string(i) + "]";
    if (!d.is_object()) throw InputError(path, KeyPlace(where), "expected an object");
    PlumbCombination c;
    c.text = TextOr(d, "combination", "");
    c.value = detail::FiniteNumber(Field(d, "value", path, where + ".value", "a number"), path,
                                   where + ".value");
    if (d.contains("sigma") && d.at("sigma").is_number()) c.sigma = d.at("sigma").get<double>();
    if (d.contains("parameters") && d.contains("coefficients")) {
      const json& names = d.at("parameters");
      const json& coefficients = d.at("coefficients");
      if (!names.is_array() || !coefficients.is_array() || names.size() != coefficients.size()) {
        throw InputError(path, KeyPlace(where),
                         "expected parameters and coefficients, one coefficient each");
      }
      for (std::size_t j = 0; j < names.size(); ++j) {
        if (!names[j].is_string()) throw InputError(path, KeyPlace(where + ".parameters"), "expected names");
        c.names.push_back(names[j].get<std::string>());
        c.coefficients.push_back(detail::FiniteNumber(coefficients[j], path, where + ".coefficients"));
      }
    }
    r.determined.push_back(std::move(c));
  }
}

/// The values against their parameters' typical magnitudes (core/calibration_checks.h
/// NoSensorsProblem), where the file's model is one plumb knows (a method's own layout, such
/// as the paper's, is not): the parameters' values, and the biases of the sensors' blocks.
void CheckMagnitudes(const PlumbResult& r, const std::string& path) {
  std::optional<model::Model> m;
  try {
    m = model::Model::Parse(r.model);
  } catch (const Error&) {
    return;
  }
  const auto problem = [&](const std::string& name, double value) -> std::string {
    const auto where = m->FindParameter(name);
    if (!where) return "";
    const model::ParameterInfo& info =
        m->terms()[static_cast<std::size_t>(where->first)]
            .effect->info()
            .parameters[static_cast<std::size_t>(where->second)];
    return NoSensorsProblem(value, info.nominal, info.typical, info.unit);
  };
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    const PlumbParameter& p = r.parameters[i];
    if (const std::string why = problem(p.name, p.value); !why.empty()) {
      throw InputError(path, KeyPlace("parameters[" + std::to_string(i) + "].value"),
                       "'" + p.name + "' = " + why);
    }
  }
  const char* const kAxes[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    if (const std::string why = problem(std::string("accel.bias.") + kAxes[k], r.accel_bias[k]);
        !why.empty()) {
      throw InputError(path, KeyPlace("accel.bias[" + std::to_string(k) + "]"), why);
    }
    if (!r.has_gyro) continue;
    if (const std::string why = problem(std::string("gyro.bias.") + kAxes[k], r.gyro_bias[k]);
        !why.empty()) {
      throw InputError(path, KeyPlace("gyro.bias[" + std::to_string(k) + "]"), why);
    }
  }
}

/// Relative difference allowed between a parameter's "sigma" and the square root of its
/// covariance diagonal: plumb writes both from one matrix at full precision (17 digits), so
/// they agree to rounding; a file whose sigma column says 25586 sigma off while its
/// covariance gives an NEES inside the band was edited.
constexpr double kSigmaAgreement = 1e-6;

/// Each parameter's sigma against the covariance's, where the file gives both.
void CheckSigmasAgree(const PlumbResult& r, const std::string& path) {
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    const PlumbParameter& p = r.parameters[i];
    if (!p.sigma) continue;
    const auto at = std::find(r.covariance_names.begin(), r.covariance_names.end(), p.name);
    if (at == r.covariance_names.end()) continue;
    const auto k = static_cast<Eigen::Index>(at - r.covariance_names.begin());
    const double from_covariance = std::sqrt(std::max(0.0, r.covariance(k, k)));
    if (std::abs(*p.sigma - from_covariance) <=
        kSigmaAgreement * std::max(*p.sigma, from_covariance)) {
      continue;
    }
    throw InputError(path, KeyPlace("parameters[" + std::to_string(i) + "].sigma"),
                     "'" + p.name + "' has sigma " + SignificantText(*p.sigma, 6) +
                         " but the covariance gives " + SignificantText(from_covariance, 6) +
                         " (covariance.matrix[" + std::to_string(k) + "][" + std::to_string(k) +
                         "]): plumb writes the two alike; the file was changed after it was "
                         "written");
  }
}

}  // namespace

PlumbResult ReadPlumbResult(const std::string& path) {
  const json root = detail::ParseJsonFile(path);
  if (!root.is_object()) {
    throw InputError(path, "", "expected the JSON object that " + OptionText(Option::kCalibrationJson) + " writes");
  }
  PlumbResult r;
  r.path = path;
  r.method = TextOr(root, "method", "");
  r.model = TextOr(root, "model", "");
  ReadSensor(root, "accel", path, r.accel_matrix, r.accel_bias);
  r.has_gyro = root.contains("gyro") && !root.at("gyro").is_null();
  if (r.has_gyro) ReadSensor(root, "gyro", path, r.gyro_matrix, r.gyro_bias);

  const json& params = Field(root, "parameters", path, "parameters", "a list of parameters");
  if (!params.is_array()) throw InputError(path, KeyPlace("parameters"), "expected a list");
  std::vector<std::string> names;
  for (std::size_t i = 0; i < params.size(); ++i) {
    r.parameters.push_back(ReadParameter(params[i], path, i));
    names.push_back(r.parameters.back().name);
  }
  if (const auto repeat = FirstRepeat(names)) {
    throw InputError(path, KeyPlace("parameters[" + std::to_string(repeat->first) + "].name"),
                     "'" + names[repeat->first] + "' given twice (first at parameters[" +
                         std::to_string(repeat->second) + "])");
  }
  CheckMagnitudes(r, path);
  if (root.contains("segments")) {
    const json& segments = root.at("segments");
    if (!segments.is_array()) throw InputError(path, KeyPlace("segments"), "expected a list");
    for (std::size_t i = 0; i < segments.size(); ++i) {
      r.segments.push_back(ReadSegment(segments[i], path, i));
    }
  }
  const json empty = json::object();
  const json& site = root.contains("site") ? root.at("site") : empty;
  r.gravity_m_s2 = NumberOr(site, "gravity", 0.0);
  r.site_source = TextOr(site, "source", "");
  const json& fit = root.contains("fit") ? root.at("fit") : empty;
  r.chi2_dof = NumberOr(fit, "chi2_dof", std::numeric_limits<double>::quiet_NaN());
  r.dof = static_cast<long>(NumberOr(fit, "dof", 0.0));
  const json& noise = root.contains("noise") ? root.at("noise") : empty;
  const json& noise_accel = noise.is_object() && noise.contains("accel") ? noise.at("accel") : empty;
  const bool noise_known = noise_accel.is_array() && noise_accel.size() == 3 &&
                           std::all_of(noise_accel.begin(), noise_accel.end(),
                                       [](const json& v) { return v.is_number(); });
  if (noise_known) r.noise_accel = detail::Vector3(noise_accel, path, "noise.accel");
  if (root.contains("covariance") && root.at("covariance").is_object()) {
    ReadCovariance(root.at("covariance"), path, r);
  }
  if (root.contains("observability") && root.at("observability").is_object() &&
      root.at("observability").contains("determined")) {
    ReadDetermined(root.at("observability").at("determined"), path, r);
  }
  if (root.contains("inputs") && root.at("inputs").is_array()) {
    for (const auto& input : root.at("inputs")) {
      if (input.is_string()) r.inputs.push_back(input.get<std::string>());
    }
  }
  CheckSigmasAgree(r, path);
  return r;
}

const PlumbParameter* FindParameter(const PlumbResult& result, const std::string& name) {
  for (const auto& p : result.parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

}  // namespace plumb::peers

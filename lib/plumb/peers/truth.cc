#include "plumb/peers/truth.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/document/json_fields.h"
#include "plumb/signal/chi_square.h"

namespace plumb::peers {

namespace detail = document::detail;

namespace {

using nlohmann::json;

const TrueParameter* FindTruth(const std::vector<TrueParameter>& truth, const std::string& name) {
  for (const auto& t : truth) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

/// The true value of a determined combination (the sum of its coefficients times the true
/// parameters); nullopt when a parameter has no truth or the file gives no coefficients.
std::optional<double> TrueCombination(const PlumbCombination& d,
                                      const std::vector<TrueParameter>& truth) {
  if (d.names.empty()) return std::nullopt;
  double sum = 0.0;
  for (std::size_t i = 0; i < d.names.size(); ++i) {
    const TrueParameter* t = FindTruth(truth, d.names[i]);
    if (t == nullptr) return std::nullopt;
    sum += d.coefficients[i] * t->value;
  }
  return sum;
}

/// The errors the NEES is over and their covariance: the covariance's parameters, or (none:
/// a single pose's gauge) the determined combinations. False, with c.nees_note, when missing.
bool NeesErrors(const PlumbResult& result, const std::vector<TrueParameter>& truth,
                TruthComparison& c, Eigen::VectorXd& e, Eigen::MatrixXd& covariance) {
  if (result.covariance_names.empty()) {
    const auto k = static_cast<Eigen::Index>(result.determined.size());
    if (k == 0 || result.determined_covariance.rows() != k) {
      c.nees_note = "no covariance in " + result.path + " (written by an older plumb?)";
      return false;
    }
    e.resize(k);
    for (Eigen::Index j = 0; j < k; ++j) {
      const PlumbCombination& d = result.determined[static_cast<std::size_t>(j)];
      const std::optional<double> t = TrueCombination(d, truth);
      if (!t) {
        c.nees_note = "the determined combination " + d.text +
                      (d.names.empty() ? " has no coefficients (written by an older plumb?)"
                                       : " has a parameter without truth") +
                      ": no NEES";
        return false;
      }
      e[j] = d.value - *t;
    }
    covariance = result.determined_covariance;
    c.nees_over_combinations = true;
    return true;
  }
  const auto n = static_cast<Eigen::Index>(result.covariance_names.size());
  e.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::string& name = result.covariance_names[static_cast<std::size_t>(i)];
    const TrueParameter* t = FindTruth(truth, name);
    const PlumbParameter* p = FindParameter(result, name);
    if (t == nullptr || p == nullptr) {
      c.nees_note = "the covariance's parameter " + name + " has no " +
                    (t == nullptr ? "truth" : "estimate") + ": no NEES";
      return false;
    }
    e[i] = p->value - t->value;
  }
  covariance = result.covariance;
  return true;
}

/// Sets c.nees and its band, or c.nees_note.
void Nees(const PlumbResult& result, const std::vector<TrueParameter>& truth, TruthComparison& c) {
  Eigen::VectorXd e;
  Eigen::MatrixXd covariance;
  if (!NeesErrors(result, truth, c, e, covariance)) return;
  const Eigen::Index n = e.size();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(covariance);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() ||
      (ldlt.vectorD().array() <= 0.0).any()) {
    c.nees_note = "the covariance is not positive definite: no NEES";
    return;
  }
  c.nees = e.dot(ldlt.solve(e));
  c.nees_dof = static_cast<int>(n);
  c.band_low = signal::ChiSquareQuantileExact(0.025, n);
  c.band_high = signal::ChiSquareQuantileExact(0.975, n);
}

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, value);
  return buffer;
}

json Num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

}  // namespace

std::vector<TrueParameter> ReadSimulationTruth(const std::string& path) {
  const json root = detail::ParseJsonFile(path);
  if (!root.is_object() || !root.contains("parameters")) {
    throw InputError(path, detail::KeyPlace("parameters"),
                     "missing; expected the true parameters that " + OptionText(Option::kTruthJson) +
                         " writes",
                     {Option::kTruthJson});
  }
  const json& params = root.at("parameters");
  if (!params.is_array()) throw InputError(path, detail::KeyPlace("parameters"), "expected a list");
  std::vector<TrueParameter> out;
  for (std::size_t i = 0; i < params.size(); ++i) {
    const std::string where = "parameters[" + std::to_string(i) + "]";
    const json& p = params[i];
    if (!p.is_object() || !p.contains("name") || !p.at("name").is_string()) {
      throw InputError(path, detail::KeyPlace(where), "expected {\"name\": ..., \"value\": ...}");
    }
    TrueParameter t;
    t.name = p.at("name").get<std::string>();
    t.value = detail::FiniteNumber(detail::Field(p, "value", path, where + ".value", "a number"),
                                   path, where + ".value");
    if (p.contains("unit") && p.at("unit").is_string()) t.unit = p.at("unit").get<std::string>();
    out.push_back(t);
  }
  return out;
}

TruthComparison CompareWithTruth(const PlumbResult& result, const std::vector<TrueParameter>& truth,
                                 const std::string& truth_path) {
  TruthComparison c;
  c.result_path = result.path;
  c.truth_path = truth_path;
  c.sigma_scaled_by_chi2 = result.sigma_scaled_by_chi2;
  for (const PlumbParameter& p : result.parameters) {
    const TrueParameter* t = FindTruth(truth, p.name);
    if (t == nullptr) continue;
    if (!p.observable && !p.fixed) {  // held at a gauge value the data does not determine
      c.undetermined.push_back(p.name);
      continue;
    }
    TruthRow row{p.name, p.unit, false, p.value, t->value, p.sigma};
    if (row.sigma && std::abs(row.error()) > 3.0 * *row.sigma) ++c.beyond_3_sigma;
    c.rows.push_back(row);
  }
  for (const PlumbCombination& d : result.determined) {
    const std::optional<double> t = TrueCombination(d, truth);
    if (!t) continue;
    TruthRow row{d.text, "", true, d.value, *t, d.sigma};
    if (row.sigma && std::abs(row.error()) > 3.0 * *row.sigma) ++c.beyond_3_sigma;
    c.rows.push_back(row);
  }
  if (c.rows.empty()) {
    throw InputError(truth_path, "", "no parameter of " + result.path + " is in the truth");
  }
  Nees(result, truth, c);
  return c;
}

std::string TruthComparisonText(const TruthComparison& c, bool table) {
  std::string out;
  if (table) {
    out += "plumb's calibration (" + c.result_path + ") against the simulated truth (" +
           c.truth_path + ")\n";
    char head[160];
    std::snprintf(head, sizeof head, "%-28s %15s %15s %11s %10s %8s  %s\n", "parameter",
                  "estimate", "truth", "error", "sigma", "err/sig", "unit");
    out += head;
    for (const TruthRow& r : c.rows) {
      char line[200];
      std::snprintf(line, sizeof line, "%-28s %15.9g %15.9g %11.3g %10s %8s  %s\n",
                    r.name.c_str(), r.estimate, r.truth, r.error(),
                    r.sigma ? Format("%.3g", *r.sigma).c_str() : "-",
                    r.sigma ? Format("%+.2f", r.error() / *r.sigma).c_str() : "-", r.unit.c_str());
      out += line;
    }
    out += std::to_string(c.beyond_3_sigma) + " of " + std::to_string(c.rows.size()) +
           (c.nees_over_combinations ? " parameters and combinations" : " parameters") +
           " beyond 3 sigma\n";
    if (!c.undetermined.empty()) {
      std::string names;
      for (const auto& n : c.undetermined) names += (names.empty() ? "" : ", ") + n;
      out += "not scored: " + std::to_string(c.undetermined.size()) +
             " parameters the data does not determine (held at their gauge values; the "
             "combinations above are what it determines): " + names + "\n";
    }
  }
  if (!c.nees) return out + (table ? "" : c.result_path + ": ") + c.nees_note + "\n";
  const bool inside = *c.nees >= c.band_low && *c.nees <= c.band_high;
  char line[320];
  std::snprintf(line, sizeof line,
                "%s%sNEES %.1f on %d %s (full covariance%s): chi^2(%d) 95%% band %.1f .. "
                "%.1f, %s\n",
                table ? "" : c.result_path.c_str(), table ? "" : ": ", *c.nees, c.nees_dof,
                c.nees_over_combinations ? "determined combinations" : "parameters",
                c.sigma_scaled_by_chi2 ? ", scaled by chi2/dof" : "", c.nees_dof, c.band_low,
                c.band_high,
                inside ? "inside"
                       : (*c.nees > c.band_high ? "above: the sigmas are too small"
                                                : "below: the sigmas are too large"));
  return out + line;
}

json TruthComparisonJson(const TruthComparison& c) {
  json rows = json::array();
  for (const TruthRow& r : c.rows) {
    rows.push_back({{"name", r.name},
                    {"combination", r.combination},
                    {"unit", r.unit},
                    {"estimate", Num(r.estimate)},
                    {"truth", Num(r.truth)},
                    {"error", Num(r.error())},
                    {"sigma", r.sigma ? Num(*r.sigma) : json(nullptr)}});
  }
  json out{{"result", c.result_path},
           {"truth", c.truth_path},
           {"parameters", rows},
           {"beyond_3_sigma", c.beyond_3_sigma},
           {"undetermined", c.undetermined},
           {"sigma_scaled_by_chi2", c.sigma_scaled_by_chi2}};
  if (c.nees) {
    out["nees"] = {{"value", Num(*c.nees)},
                   {"dof", c.nees_dof},
                   {"over", c.nees_over_combinations ? "determined_combinations" : "parameters"},
                   {"band_95", {Num(c.band_low), Num(c.band_high)}}};
  } else {
    out["nees"] = nullptr;
    out["nees_note"] = c.nees_note;
  }
  return out;
}

}  // namespace plumb::peers

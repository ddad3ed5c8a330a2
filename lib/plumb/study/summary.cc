#include "plumb/study/summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <regex>

#include <boost/crc.hpp>

#include "plumb/core/error.h"
#include "plumb/signal/chi_square.h"

namespace plumb::study {
namespace {

using nlohmann::json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

json Num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
double FromNum(const json& v) { return v.is_number() ? v.get<double>() : kNaN; }

/// A number as CSV text: 17 significant digits, "" for NaN.
std::string Csv(double v) {
  if (!std::isfinite(v)) return "";
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

/// The runs with those whose rows differ from most runs' marked failed.
std::vector<RunOutcome> PoolByShape(const std::vector<RunOutcome>& runs) {
  // The rows are the parameters (or determined combinations, run.h) that most runs have, first
  // seen first among equals; a run that determined other combinations cannot be pooled and
  // counts as failed. Combinations are compared by their parameters and signs, not their
  // printed coefficients.
  const auto shape = [](const std::vector<std::string>& names) {
    static const std::regex kNumber("[0-9]+(\\.[0-9]*)?(e[-+]?[0-9]+)?");
    std::vector<std::string> out;
    for (const std::string& n : names) out.push_back(std::regex_replace(n, kNumber, "#"));
    return out;
  };
  std::vector<std::vector<std::string>> shapes;
  std::map<std::vector<std::string>, std::size_t> counts;
  std::size_t best = runs.size(), best_count = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    shapes.push_back(runs[i].failed ? std::vector<std::string>{} : shape(runs[i].names));
    if (runs[i].failed) continue;
    const std::size_t count = ++counts[shapes[i]];
    if (count > best_count) {
      best_count = count;
      best = i;
    }
  }
  std::vector<RunOutcome> pooled = runs;
  for (std::size_t i = 0; i < pooled.size(); ++i) {
    RunOutcome& r = pooled[i];
    if (!r.failed && shapes[i] != shapes[best]) {
      r.failed = true;
      r.failure = "the data determined other combinations of the parameters than most runs "
                  "(an ill-conditioned design): not pooled";
    }
  }
  return pooled;
}

}  // namespace

namespace {

/// FirstOrderCovariance as JSON: {parameters, matrix}, null without uncertain factors.
json FirstOrderJson(const Study& study, const PointSummary& s) {
  const auto cov = FirstOrderCovariance(study, s);
  if (cov.empty()) return nullptr;
  json names = json::array(), matrix = json::array();
  for (const ParameterSummary& p : s.parameters) names.push_back(p.name);
  for (const auto& row : cov) {
    json r = json::array();
    for (double v : row) r.push_back(Num(v));
    matrix.push_back(r);
  }
  return json{{"parameters", names}, {"matrix", matrix}};
}

}  // namespace

PointSummary Summarise(const Point& point, const std::vector<RunOutcome>& runs,
                       const std::vector<std::string>& sensitivity_factors) {
  PointSummary s;
  s.point = point;
  s.runs = static_cast<int>(runs.size());
  double nees_sum = 0.0, nees_unflagged_sum = 0.0, chi2_sum = 0.0;
  int chi2_n = 0;
  const std::vector<RunOutcome> pooled = PoolByShape(runs);
  std::vector<int> d_dp_runs;  // per parameter and factor: runs with a sensitivity
  for (const RunOutcome& r : pooled) {
    s.failed += r.failed ? 1 : 0;
    s.flagged += r.flagged ? 1 : 0;
    if (r.failed && !r.failure.empty() &&
        std::find(s.failures.begin(), s.failures.end(), r.failure) == s.failures.end()) {
      s.failures.push_back(r.failure);
    }
    s.nees.push_back(r.failed ? kNaN : r.nees);
    if (r.failed) continue;
    if (std::isfinite(r.nees)) {
      nees_sum += r.nees;
      s.nees_dof += r.nees_dof;
      if (!r.flagged) {
        nees_unflagged_sum += r.nees;
        s.nees_unflagged_dof += r.nees_dof;
      }
    }
    if (std::isfinite(r.chi2_dof)) {
      chi2_sum += r.chi2_dof;
      ++chi2_n;
    }
    if (s.parameters.empty()) {
      for (std::size_t i = 0; i < r.names.size(); ++i) {
        s.parameters.push_back(ParameterSummary{r.names[i], r.units[i], 0, 0.0, 0.0, 0.0, 0.0,
                                                {}});
      }
      for (ParameterSummary& p : s.parameters) p.mean_d_dp.assign(sensitivity_factors.size(), 0.0);
      d_dp_runs.assign(s.parameters.size() * sensitivity_factors.size(), 0);
    }
    for (std::size_t f = 0; f < r.d_dp.size() && f < sensitivity_factors.size(); ++f) {
      for (std::size_t i = 0; i < r.d_dp[f].size() && i < s.parameters.size(); ++i) {
        if (!std::isfinite(r.d_dp[f][i]) || r.d_dp[f].size() != s.parameters.size()) continue;
        s.parameters[i].mean_d_dp[f] += r.d_dp[f][i];
        ++d_dp_runs[i * sensitivity_factors.size() + f];
      }
    }
    for (std::size_t i = 0; i < r.error.size() && i < s.parameters.size(); ++i) {
      if (!std::isfinite(r.error[i])) continue;
      ParameterSummary& p = s.parameters[i];
      ++p.runs;
      p.mean_error += r.error[i];
      p.rms_error += r.error[i] * r.error[i];
      p.mean_sigma += r.sigma[i];
    }
  }
  for (std::size_t i = 0; i < s.parameters.size(); ++i) {
    for (std::size_t f = 0; f < sensitivity_factors.size(); ++f) {
      const int n = d_dp_runs[i * sensitivity_factors.size() + f];
      s.parameters[i].mean_d_dp[f] = n > 0 ? s.parameters[i].mean_d_dp[f] / n : kNaN;
    }
  }
  for (ParameterSummary& p : s.parameters) {
    if (p.runs == 0) {
      p.mean_error = p.rms_error = p.sd_error = p.mean_sigma = kNaN;
      continue;
    }
    const double n = p.runs;
    const double sum = p.mean_error, sum_sq = p.rms_error;
    p.mean_error = sum / n;
    p.rms_error = std::sqrt(sum_sq / n);
    p.sd_error = p.runs > 1 ? std::sqrt(std::max(0.0, (sum_sq - sum * sum / n) / (n - 1.0))) : kNaN;
    p.mean_sigma /= n;
  }
  const auto pool = [](double sum, int dof, double& per_dof, double& low, double& high) {
    if (dof <= 0) return;
    per_dof = sum / dof;
    low = signal::ChiSquareQuantileExact(0.025, dof) / dof;
    high = signal::ChiSquareQuantileExact(0.975, dof) / dof;
  };
  pool(nees_sum, s.nees_dof, s.nees_per_dof, s.nees_low, s.nees_high);
  pool(nees_unflagged_sum, s.nees_unflagged_dof, s.nees_unflagged_per_dof, s.nees_unflagged_low,
       s.nees_unflagged_high);
  if (chi2_n > 0) s.mean_chi2_dof = chi2_sum / chi2_n;
  return s;
}

std::vector<std::vector<double>> FirstOrderCovariance(const Study& study, const PointSummary& s) {
  const std::vector<std::string> factors = SensitivityFactors(study);
  std::vector<double> sigma(factors.size(), 0.0);
  bool any = false;
  for (std::size_t f = 0; f < factors.size(); ++f) {
    for (const Factor& factor : study.factors) {
      if (factor.name == factors[f]) sigma[f] = factor.sigma;
    }
    any = any || sigma[f] > 0.0;
  }
  if (!any) return {};
  const std::size_t n = s.parameters.size();
  std::vector<std::vector<double>> cov(n, std::vector<double>(n, 0.0));
  for (std::size_t f = 0; f < factors.size(); ++f) {
    if (!(sigma[f] > 0.0)) continue;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        const auto& di = s.parameters[i].mean_d_dp;
        const auto& dj = s.parameters[j].mean_d_dp;
        const double a = f < di.size() ? di[f] : kNaN, b = f < dj.size() ? dj[f] : kNaN;
        cov[i][j] += sigma[f] * sigma[f] * a * b;  // NaN where a sensitivity is missing
      }
    }
  }
  return cov;
}

json PointJson(const Study& study, const PointSummary& s) {
  json params = json::array();
  for (const ParameterSummary& p : s.parameters) {
    json d_dp = json::array();
    for (double v : p.mean_d_dp) d_dp.push_back(Num(v));
    params.push_back({{"name", p.name}, {"unit", p.unit}, {"runs", p.runs},
                      {"mean_error", Num(p.mean_error)}, {"rms_error", Num(p.rms_error)},
                      {"sd_error", Num(p.sd_error)}, {"mean_sigma", Num(p.mean_sigma)},
                      {"mean_d_dp", d_dp}});
  }
  json nees = json::array();
  for (double v : s.nees) nees.push_back(Num(v));
  json values = json::array();
  for (double v : s.point.values) values.push_back(Num(v));
  json doc{{"study", study.source},
              {"point", s.point.index},
              {"values", values},
              {"runs", s.runs},
              {"failed", s.failed},
              {"flagged", s.flagged},
              {"failures", s.failures},
              {"nees_per_dof", Num(s.nees_per_dof)},
              {"nees_dof", s.nees_dof},
              {"nees_band_95", {Num(s.nees_low), Num(s.nees_high)}},
              {"mean_chi2_dof", Num(s.mean_chi2_dof)},
              {"nees_unflagged_per_dof", Num(s.nees_unflagged_per_dof)},
              {"nees_unflagged_dof", s.nees_unflagged_dof},
              {"nees_unflagged_band_95", {Num(s.nees_unflagged_low), Num(s.nees_unflagged_high)}},
              {"nees_per_run", nees},
              {"first_order_covariance", FirstOrderJson(study, s)},
              {"parameters", params}};
  doc["checksum"] = PointChecksum(doc);
  return doc;
}

std::string PointChecksum(json doc) {
  doc.erase("checksum");
  const std::string text = doc.dump(-1, ' ', false, json::error_handler_t::replace);
  boost::crc_32_type crc;
  crc.process_bytes(text.data(), text.size());
  char out[16];
  std::snprintf(out, sizeof out, "crc32:%08x", static_cast<unsigned>(crc.checksum()));
  return out;
}

PointSummary PointFromJson(const Study& study, const json& doc, const std::string& path,
                           const Point& expected) {
  if (!doc.is_object() || !doc.contains("study") || !doc.contains("point")) {
    throw InputError(path, "", "not a point of a study (written by plumb sweep)");
  }
  if (doc.at("study") != study.source) {
    throw InputError(path, "key 'study'", "this point belongs to another study");
  }
  const std::string redo = ": remove the file to run point " + std::to_string(expected.index) +
                           " again";
  if (!doc.contains("checksum") || doc.at("checksum") != PointChecksum(doc)) {
    throw InputError(path, "key 'checksum'",
                     std::string(doc.contains("checksum") ? "does not match the point's content "
                                                            "(edited or damaged)"
                                                          : "missing (edited, or written by an "
                                                            "older plumb)") +
                         redo);
  }
  try {
    PointSummary s;
    s.point.index = doc.at("point").get<int>();
    for (const json& v : doc.at("values")) s.point.values.push_back(FromNum(v));
    if (s.point.index != expected.index || s.point.values != expected.values) {
      throw InputError(path, "key 'point'",
                       "holds point " + std::to_string(s.point.index) + ", not point " +
                           std::to_string(expected.index) + " of the design (a file copied?)" +
                           redo);
    }
    s.runs = doc.at("runs").get<int>();
    s.failed = doc.at("failed").get<int>();
    s.flagged = doc.at("flagged").get<int>();
    s.failures = doc.at("failures").get<std::vector<std::string>>();
    s.nees_per_dof = FromNum(doc.at("nees_per_dof"));
    s.nees_dof = doc.at("nees_dof").get<int>();
    s.nees_low = FromNum(doc.at("nees_band_95").at(0));
    s.nees_high = FromNum(doc.at("nees_band_95").at(1));
    s.mean_chi2_dof = FromNum(doc.at("mean_chi2_dof"));
    s.nees_unflagged_per_dof = FromNum(doc.at("nees_unflagged_per_dof"));
    s.nees_unflagged_dof = doc.at("nees_unflagged_dof").get<int>();
    s.nees_unflagged_low = FromNum(doc.at("nees_unflagged_band_95").at(0));
    s.nees_unflagged_high = FromNum(doc.at("nees_unflagged_band_95").at(1));
    for (const json& v : doc.at("nees_per_run")) s.nees.push_back(FromNum(v));
    for (const json& p : doc.at("parameters")) {
      std::vector<double> d_dp;
      for (const json& v : p.at("mean_d_dp")) d_dp.push_back(FromNum(v));
      s.parameters.push_back(ParameterSummary{
          p.at("name").get<std::string>(), p.at("unit").get<std::string>(), p.at("runs").get<int>(),
          FromNum(p.at("mean_error")), FromNum(p.at("rms_error")), FromNum(p.at("sd_error")),
          FromNum(p.at("mean_sigma")), d_dp});
    }
    return s;
  } catch (const json::exception& e) {
    throw InputError(path, "", std::string("a study point with a missing or malformed key: ") + e.what());
  }
}

std::string ResultsCsv(const Study& study, const std::vector<PointSummary>& points) {
  std::string out = "point";
  for (const Factor& f : study.factors) out += "," + f.name;
  out += ",parameter,unit,runs,failed,flagged,mean_error,rms_error,sd_error,mean_sigma,"
         "nees_per_dof,nees_low,nees_high,mean_chi2_dof";
  const std::vector<std::string> sensitivity = SensitivityFactors(study);
  for (const std::string& f : sensitivity) out += ",d_" + f;
  out += ",nees_unflagged_per_dof,nees_unflagged_low,nees_unflagged_high,sd_first_order\n";
  for (const PointSummary& s : points) {
    std::string head = std::to_string(s.point.index);
    for (double v : s.point.values) head += "," + Csv(v);
    const std::string tail = "," + Csv(s.nees_per_dof) + "," + Csv(s.nees_low) + "," +
                             Csv(s.nees_high) + "," + Csv(s.mean_chi2_dof);
    const std::string unflagged = "," + Csv(s.nees_unflagged_per_dof) + "," +
                                  Csv(s.nees_unflagged_low) + "," + Csv(s.nees_unflagged_high);
    const auto first_order = FirstOrderCovariance(study, s);
    for (std::size_t i = 0; i < s.parameters.size(); ++i) {
      const ParameterSummary& p = s.parameters[i];
      out += head + "," + p.name + "," + p.unit + "," + std::to_string(p.runs) + "," +
             std::to_string(s.failed) + "," + std::to_string(s.flagged) + "," +
             Csv(p.mean_error) + "," + Csv(p.rms_error) + "," + Csv(p.sd_error) + "," +
             Csv(p.mean_sigma) + tail;
      for (std::size_t f = 0; f < sensitivity.size(); ++f) {
        out += "," + (f < p.mean_d_dp.size() ? Csv(p.mean_d_dp[f]) : std::string());
      }
      out += unflagged + "," +
             (first_order.empty() ? std::string() : Csv(std::sqrt(first_order[i][i]))) + "\n";
    }
    if (s.parameters.empty()) {  // every run failed: one row that says so
      out += head + ",,," + std::to_string(0) + "," + std::to_string(s.failed) + "," +
             std::to_string(s.flagged) + ",,,," + tail + std::string(sensitivity.size(), ',') +
             unflagged + ",\n";
    }
  }
  return out;
}

json ResultsJson(const Study& study, const std::vector<PointSummary>& points) {
  json factors = json::array();
  for (const Factor& f : study.factors) factors.push_back(f.name);
  const std::vector<std::string> sensitivity = SensitivityFactors(study);
  json list = json::array();
  for (const PointSummary& s : points) {
    json p = PointJson(study, s);
    p.erase("study");
    list.push_back(p);
  }
  return json{{"study", study.source}, {"factors", factors},
              {"sensitivity_factors", sensitivity}, {"points", list}};
}

}  // namespace plumb::study

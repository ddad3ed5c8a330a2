#include "plumb/peers/comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/core/option_name.h"
#include "plumb/core/units.h"

namespace plumb::peers {
namespace {

using nlohmann::json;

bool IsAccelLowerTriangle(const std::string& name) {
  return name == "accel.matrix.yx" || name == "accel.matrix.zx" || name == "accel.matrix.zy";
}

ComparisonRow MakeRow(const NamedValue& peer, const PlumbParameter* plumb, double sigma_scale) {
  ComparisonRow row;
  row.name = peer.name;
  row.peer_value = peer.value;
  row.in_plumb_model = plumb != nullptr;
  if (plumb != nullptr) {
    row.unit = plumb->unit;
    row.plumb_value = plumb->value;
    row.plumb_sigma = plumb->sigma;
    row.plumb_fixed = plumb->fixed;
    row.plumb_observable = plumb->observable;
  }
  row.difference = row.plumb_value - row.peer_value;
  if (row.plumb_sigma && *row.plumb_sigma > 0.0) {
    row.z = row.difference / *row.plumb_sigma;
    row.z_scaled = *row.z / sigma_scale;
  }
  return row;
}

/// A note when the diagonal scales differ by more than a factor 2: different units.
void CheckUnits(const Mat3& plumb, const Mat3& peer, const std::string& sensor,
                std::vector<Notice>& notes) {
  for (int i = 0; i < 3; ++i) {
    const double ratio = plumb(i, i) / peer(i, i);
    if (!(std::abs(ratio) > 0.5 && std::abs(ratio) < 2.0)) {
      notes.push_back(Notice{
          "scales_differ",
          "WARNING: the " + sensor + " scales (matrix diagonals) differ by a factor " +
              std::to_string(ratio) +
              ": were plumb and the peer given data in different units? (plumb must read the "
              "peer's raw data without " + OptionText(Option::kAccScale) + "/" +
              OptionText(Option::kGyrScale) + "/" + OptionText(Option::kAccOffset) + "/" +
              OptionText(Option::kGyrOffset) + "), or is plumb's estimate unobservable?",
          {Option::kAccScale, Option::kGyrScale, Option::kAccOffset, Option::kGyrOffset}});
      return;
    }
  }
}

bool IsSi(const std::string& unit) { return unit == "m/s^2" || unit == "rad/s"; }

/// Why the rows of a sensor cannot be compared for units (code units_differ), or nullopt:
/// plumb's outputs in SI and the peer's not (or the reverse), or every scale 180/pi apart
/// (deg/s data read as rad/s).
std::optional<Notice> UnitMismatch(const std::string& plumb_unit, const std::string& peer_unit,
                         const Mat3& plumb, const Mat3& peer, const std::string& sensor) {
  if (!plumb_unit.empty() && !peer_unit.empty() && IsSi(plumb_unit) != IsSi(peer_unit)) {
    return Notice{"units_differ",
                  "plumb's " + sensor + " outputs are in " + plumb_unit + ", the peer's in " +
                      peer_unit + ": give both the same data in the same units",
                  {}};
  }
  const double deg = 180.0 / units::kPi;
  bool apart = true;
  for (int i = 0; i < 3; ++i) {
    const double ratio = std::abs(plumb(i, i) / peer(i, i));
    apart = apart && (std::abs(ratio / deg - 1.0) < 0.1 || std::abs(ratio * deg - 1.0) < 0.1);
  }
  if (apart) {
    return Notice{"units_differ",
                  "every " + sensor + " scale differs by 180/pi: data in deg/s were read as "
                  "rad/s on one side (plumb converts deg/s with " +
                      OptionText(Option::kGyrUnit, "deg/s") + ")",
                  {Option::kGyrUnit}};
  }
  return std::nullopt;
}

/// Why the gyroscope matrices cannot be compared for their sign (code gyro_sign_differs), or
/// nullopt.
std::optional<Notice> SignMismatch(const Mat3& plumb, const Mat3& peer,
                                   const std::string& peer_name) {
  std::string axes;
  for (int i = 0; i < 3; ++i) {
    if ((plumb(i, i) > 0.0) != (peer(i, i) > 0.0)) axes += kAxisName[i];
  }
  if (axes.empty()) return std::nullopt;
  std::string why = "the gyroscope matrix's diagonal has the opposite sign in plumb and " +
                    peer_name + " on axes " + axes +
                    ": the two take the rate with opposite signs there";
  if (peer_name == "imucal") {
    why += " (imucal takes its turns as clockwise, expected_angle -360: turns made the other "
           "way give a negative R_g diagonal; recompute with expected_angle +360)";
  }
  return Notice{"gyro_sign_differs", why, {}};
}

void MarkNotCompared(std::vector<ComparisonRow>& rows, const std::vector<std::string>& prefixes,
                     const std::optional<Notice>& why, std::vector<Notice>& notes) {
  if (!why) return;
  std::string which;
  for (const auto& p : prefixes) which += (which.empty() ? "" : ", ") + p + "*";
  notes.push_back(Notice{why->code, "not compared: " + which + ": " + why->message, why->options});
  for (ComparisonRow& row : rows) {
    for (const auto& p : prefixes) {
      if (row.name.rfind(p, 0) != 0) continue;
      row.not_compared = why->message;
      row.difference = 0.0;
      row.z.reset();
      row.z_scaled.reset();
    }
  }
}

std::string BiasUnit(const PlumbResult& r, const std::string& name) {
  const PlumbParameter* p = FindParameter(r, name);
  return p ? p->unit : "";
}

GravityNormComparison Costs(const PlumbResult& r, const ForwardCalibration& peer,
                            const CompareOptions& options) {
  GravityNormComparison c;
  c.segments = static_cast<int>(r.segments.size());
  c.gravity_m_s2 = options.gravity_m_s2 > 0.0 ? options.gravity_m_s2 : r.gravity_m_s2;
  c.gravity_source =
      options.gravity_m_s2 > 0.0 ? OptionText(Option::kGravity) : "the result's site.gravity";
  if (!(c.gravity_m_s2 > 0.0)) {
    c.unavailable_reason = r.path + " has no site.gravity: give " + OptionText(Option::kGravity);
    return c;
  }
  if (r.segments.empty()) {
    c.unavailable_reason = r.path + " has no still-segment means (segments[].acc_mean)";
    return c;
  }
  std::vector<Vec3> means;
  std::vector<StillMean> stills;
  for (const auto& s : r.segments) {
    means.push_back(s.acc_mean);
    stills.push_back({s.acc_mean, s.count});
  }
  c.available = true;
  c.plumb_means = ImuTkAccelCost(r.accel_matrix, r.accel_bias, means, c.gravity_m_s2);
  c.peer_means = ImuTkAccelCost(peer.accel_matrix, peer.accel_bias, means, c.gravity_m_s2);
  c.has_sample_estimate = r.noise_accel.allFinite();
  if (c.has_sample_estimate) {
    c.plumb_samples = ImuTkSampleCostEstimate(r.accel_matrix, r.accel_bias, stills,
                                              r.noise_accel, c.gravity_m_s2);
    c.peer_samples = ImuTkSampleCostEstimate(peer.accel_matrix, peer.accel_bias, stills,
                                             r.noise_accel, c.gravity_m_s2);
  }
  return c;
}

std::string Cell(const std::string& text, std::size_t width) {
  return text.size() >= width ? text + " " : text + std::string(width - text.size(), ' ');
}

/// `v` with `decimals` digits after the point, "-" when absent.
std::string OptionalCell(const std::optional<double>& v, int decimals) {
  return v ? FixedText(*v, decimals) : "-";
}

std::string SigmaCell(const ComparisonRow& row) {
  if (!row.in_plumb_model) return "-";
  if (row.plumb_fixed) return "fixed";
  if (!row.plumb_sigma) return row.plumb_observable ? "-" : "unobs.";
  return Number(*row.plumb_sigma, 3);
}

std::string CostLine(const std::string& who, const ImuTkCost& c) {
  return "    " + Cell(who, 8) + "cost " + Cell(Number(c.cost), 13) + "rms " +
         Cell(Number(c.rms_m_s2, 4), 11) + "max |r| " + Number(c.max_abs_m_s2, 4) + " m/s^2\n";
}

/// The largest |d/sigma| among rows whose name starts with `prefix`, as text.
std::string Largest(const std::vector<ComparisonRow>& rows, const std::string& prefix) {
  const ComparisonRow* worst = nullptr;
  for (const auto& row : rows) {
    if (row.name.rfind(prefix, 0) != 0 || !row.z) continue;
    if (worst == nullptr || std::abs(*row.z) > std::abs(*worst->z)) worst = &row;
  }
  return worst ? Number(std::abs(*worst->z), 3) + " (" + worst->name + ")" : "-";
}

void WriteTable(const Comparison& c, std::ostream& os) {
  const std::string& peer = c.peer.peer;
  const double scale = std::sqrt(std::max(1.0, std::isfinite(c.chi2_dof) ? c.chi2_dof : 1.0));
  os << Cell("parameter", 26) << Cell("unit", 18) << Cell("plumb", 15) << Cell("+- sigma", 11)
     << Cell(peer, 15) << Cell("plumb-" + peer, 14) << Cell("d/sigma", 9)
     << "d/(sigma*" << Number(scale, 3) << ")\n";
  for (const auto& row : c.rows) {
    os << Cell(row.name, 26) << Cell(row.in_plumb_model ? row.unit : "(not in model)", 18)
       << Cell(row.in_plumb_model ? Number(row.plumb_value, 9) : "0", 15)
       << Cell(SigmaCell(row), 11) << Cell(Number(row.peer_value, 9), 15)
       << Cell(row.not_compared.empty() ? Number(row.difference, 4) : "not compared", 14)
       << Cell(OptionalCell(row.z, 2), 9) << OptionalCell(row.z_scaled, 2) << "\n";
  }
  os << "largest |d/sigma|: accel " << Largest(c.rows, "accel.") << ", gyro "
     << Largest(c.rows, "gyro") << "\n";
}

void WriteCosts(const Comparison& c, std::ostream& os) {
  const auto& k = c.cost;
  const std::string& peer = c.peer.peer;
  os << "\nimu_tk's accelerometer cost 0.5 sum (g - |F^-1 (y_a - b_a)|)^2";
  if (!k.available) {
    os << ": not computed: " << k.unavailable_reason << "\n";
    return;
  }
  os << ", g = " << Number(k.gravity_m_s2, 8) << " m/s^2 (" << k.gravity_source << ")\n";
  os << "  on plumb's " << k.segments << " still-segment means, one residual each:\n"
     << CostLine("plumb", k.plumb_means) << CostLine(peer, k.peer_means);
  if (k.has_sample_estimate) {
    os << "  expected as imu_tk computes it, on the first " << kImuTkSamplesPerInterval
       << " samples of each of the " << k.plumb_samples.terms << " segments longer than that ("
       << FixedText(k.plumb_samples.weight, 0) << " residuals, sample noise included):\n"
       << CostLine("plumb", k.plumb_samples) << CostLine(peer, k.peer_samples);
  }
  if (peer == "imu_tk") {
    os << "  imu_tk's own printed cost (" << kImuTkDemoCost << " on its demo data) is over the "
       << "first " << kImuTkSamplesPerInterval << " samples of each of its OWN still intervals ("
       << kImuTkDemoIntervals << " there), not plumb's segments\n";
  }
}

json Num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json Opt(const std::optional<double>& v) { return v ? Num(*v) : json(nullptr); }

json Vec(const Vec3& v) { return json::array({Num(v.x()), Num(v.y()), Num(v.z())}); }

json Mat(const Mat3& m) {
  return json::array({Vec(m.row(0).transpose()), Vec(m.row(1).transpose()), Vec(m.row(2).transpose())});
}

json CostJson(const ImuTkCost& c) {
  return json{{"cost", Num(c.cost)},
              {"rms", Num(c.rms_m_s2)},
              {"max_abs", Num(c.max_abs_m_s2)},
              {"terms", c.terms},
              {"weight", Num(c.weight)}};
}

json PeerJson(const ForwardCalibration& p) {
  json out{{"name", p.peer},
           {"sources", p.sources},
           {"notes", Messages(p.notes)},
           {"R_peer_b", Mat(p.R_peer_b)},
           {"units", {{"accel", p.acc_unit}, {"gyro", p.gyr_unit}}},
           {"accel", {{"matrix", Mat(p.accel_matrix)}, {"bias", Vec(p.accel_bias)}}}};
  out["gyro"] = p.has_gyro ? json{{"matrix", Mat(p.gyro_matrix)}, {"bias", Vec(p.gyro_bias)}}
                           : json(nullptr);
  out["g_sensitivity"] = p.has_g_sensitivity ? Mat(p.g_sensitivity) : json(nullptr);
  return out;
}

json CostsJson(const GravityNormComparison& k) {
  json out{{"available", k.available},
           {"reason", k.unavailable_reason},
           {"gravity", Num(k.gravity_m_s2)},
           {"gravity_source", k.gravity_source},
           {"segments", k.segments},
           {"formula", "0.5 sum_k w_k (g - |F^-1 (y_k - b_a)|)^2 (imu_tk's MultiPosAccResidual)"}};
  out["means"] = k.available ? json{{"plumb", CostJson(k.plumb_means)}, {"peer", CostJson(k.peer_means)}}
                             : json(nullptr);
  out["samples_estimate"] =
      k.has_sample_estimate
          ? json{{"samples_per_segment", kImuTkSamplesPerInterval},
                 {"plumb", CostJson(k.plumb_samples)},
                 {"peer", CostJson(k.peer_samples)}}
          : json(nullptr);
  return out;
}

}  // namespace

Comparison Compare(const PlumbResult& result, const ForwardCalibration& peer,
                   const CompareOptions& options) {
  Comparison c;
  c.result_path = result.path;
  c.method = result.method;
  c.model = result.model_spec;
  c.chi2_dof = result.chi2_dof;
  c.dof = result.dof;
  c.peer = peer;
  const double sigma_scale =
      std::sqrt(std::max(1.0, std::isfinite(result.chi2_dof) ? result.chi2_dof : 1.0));
  const std::vector<NamedValue> peer_values = ForwardParameters(peer);
  for (const auto& v : peer_values) {
    const PlumbParameter* p = FindParameter(result, v.name);
    if (p == nullptr && v.value == 0.0 && IsAccelLowerTriangle(v.name)) continue;  // both 0
    c.rows.push_back(MakeRow(v, p, sigma_scale));
  }
  for (const auto& p : result.parameters) {
    const bool matched = std::any_of(peer_values.begin(), peer_values.end(),
                                     [&](const NamedValue& v) { return v.name == p.name; });
    if (!matched) c.plumb_only.push_back(p.name);
  }
  const std::optional<Notice> acc_units = UnitMismatch(BiasUnit(result, "accel.bias.x"), peer.acc_unit,
                                             result.accel_matrix, peer.accel_matrix,
                                             "accelerometer");
  MarkNotCompared(c.rows, {"accel."}, acc_units, c.notes);
  if (!acc_units) {
    CheckUnits(result.accel_matrix, peer.accel_matrix, "accelerometer", c.notes);
  }
  if (result.has_gyro && peer.has_gyro) {
    const std::optional<Notice> gyr_units =
        UnitMismatch(BiasUnit(result, "gyro.bias.x"), peer.gyr_unit, result.gyro_matrix,
                     peer.gyro_matrix, "gyroscope");
    MarkNotCompared(c.rows, {"gyro.", "gyro_g_sensitivity."}, gyr_units, c.notes);
    if (!gyr_units) {
      MarkNotCompared(c.rows, {"gyro.matrix."},
                      SignMismatch(result.gyro_matrix, peer.gyro_matrix, peer.peer), c.notes);
      CheckUnits(result.gyro_matrix, peer.gyro_matrix, "gyroscope", c.notes);
    }
  }
  c.cost = Costs(result, peer, options);
  return c;
}

std::string ComparisonText(const Comparison& c) {
  std::ostringstream os;
  os << "plumb compare: " << c.result_path << " against " << c.peer.peer;
  std::string sources;
  for (const auto& s : c.peer.sources) sources += (sources.empty() ? "" : ", ") + s;
  os << " (" << sources << ")\n";
  os << "plumb: method " << c.method << ", model " << c.model << ", chi2/dof "
     << Number(c.chi2_dof, 4) << " on " << c.dof << " dof\n";
  for (const Notice& n : c.peer.notes) os << "  " << n.message << "\n";
  for (const Notice& n : c.notes) os << n.message << "\n";
  os << "forward form y = M x + b in the units of the data plumb was given; "
     << "d = plumb - " << c.peer.peer << ", sigma = plumb's\n\n";
  WriteTable(c, os);
  if (!c.plumb_only.empty()) {
    std::string list;
    for (const auto& n : c.plumb_only) list += (list.empty() ? "" : ", ") + n;
    os << "not compared (no " << c.peer.peer << " counterpart): " << list << "\n";
  }
  WriteCosts(c, os);
  return os.str();
}

json ComparisonJson(const Comparison& c) {
  json rows = json::array();
  for (const auto& r : c.rows) {
    rows.push_back({{"name", r.name},
                    {"unit", r.unit},
                    {"in_plumb_model", r.in_plumb_model},
                    {"plumb", Num(r.plumb_value)},
                    {"sigma", Opt(r.plumb_sigma)},
                    {"fixed", r.plumb_fixed},
                    {"observable", r.plumb_observable},
                    {"peer", Num(r.peer_value)},
                    {"difference", r.not_compared.empty() ? Num(r.difference) : json(nullptr)},
                    {"not_compared", r.not_compared.empty() ? json(nullptr) : json(r.not_compared)},
                    {"z", Opt(r.z)},
                    {"z_scaled", Opt(r.z_scaled)}});
  }
  return json{{"result", c.result_path},
              {"plumb", {{"method", c.method}, {"model", c.model}, {"chi2_dof", Num(c.chi2_dof)}, {"dof", c.dof}}},
              {"peer", PeerJson(c.peer)},
              {"rows", rows},
              {"plumb_only", c.plumb_only},
              {"gravity_norm_cost", CostsJson(c.cost)},
              {"notes", Messages(c.notes)}};
}

}  // namespace plumb::peers

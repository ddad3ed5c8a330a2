#include "plumb/report/noise_text.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "plumb/core/number_text.h"
#include "plumb/core/units.h"
#include "plumb/report/json_report.h"

namespace plumb::report {
namespace {

using nlohmann::json;
using signal::NoiseTermKind;
using signal::Sensor;

constexpr const char* kAxisName[3] = {"x", "y", "z"};
/// Terms in the order of the table: N, B, K first (what filters need), then Q and R.
constexpr NoiseTermKind kTableOrder[] = {NoiseTermKind::kWhite, NoiseTermKind::kBiasInstability,
                                         NoiseTermKind::kRandomWalk,
                                         NoiseTermKind::kQuantisation, NoiseTermKind::kRamp};

/// FormattedText, or "n/a" for a value not finite (a term the fit did not resolve).
std::string Format(const char* format, double value) {
  return std::isfinite(value) ? FormattedText(format, value) : "n/a";
}

std::string Pad(const std::string& text, std::size_t width) {
  return text.size() >= width ? text + " " : text + std::string(width - text.size(), ' ');
}

const char* SensorKey(Sensor sensor) { return sensor == Sensor::kAccel ? "accel" : "gyro"; }

std::string TauRange(const signal::NoiseTerm& t) {
  if (!t.resolved || t.tau_min_s == t.tau_max_s) return Format("%.3g", t.tau_min_s);
  return Format("%.3g", t.tau_min_s) + " .. " + Format("%.3g", t.tau_max_s);
}

/// One table row: term name (first axis only), axis, value, units, tau.
std::string TermRow(const signal::AxisNoise& a, const signal::NoiseTerm& t,
                    const NoiseTermLabel& label, bool first_axis) {
  const std::string head =
      first_axis ? std::string(signal::NoiseTermSymbol(t.kind)) + "  " + label.name : "";
  const std::string mark = t.resolved ? "  " : "< ";
  std::string datasheet;
  if (!label.datasheet_unit.empty()) {
    datasheet = mark + Format("%.3g", t.value() * label.datasheet_scale) + " " +
                label.datasheet_unit;
  }
  std::string note;
  if (!t.in_model) note = "  (bound only: not in the model)";
  return "  " + Pad(head, 30) + Pad(kAxisName[a.axis], 5) + mark +
         Pad(Format("%.4g", t.value()), 12) + Pad(label.unit, 18) + Pad(datasheet, 22) +
         TauRange(t) + note + "\n";
}

std::string SensorTable(const signal::StillNoise& noise, Sensor sensor) {
  const std::string unit = sensor == Sensor::kAccel ? noise.acc_unit : noise.gyr_unit;
  std::string out = std::string(signal::SensorName(sensor)) + " (" + unit + ")\n  " +
                    Pad("term", 30) + Pad("axis", 5) + "  " + Pad("value", 12) +
                    Pad("unit", 18) + Pad("  datasheet unit", 22) + "from tau (s)\n";
  for (NoiseTermKind kind : kTableOrder) {
    const NoiseTermLabel label = LabelNoiseTerm(sensor, kind, unit);
    for (int axis = 0; axis < 3; ++axis) {
      const signal::AxisNoise* a = noise.Find(sensor, axis);
      if (a != nullptr) out += TermRow(*a, a->fit.term(kind), label, axis == 0);
    }
  }
  out += "  fitted:";
  for (int axis = 0; axis < 3; ++axis) {
    const signal::AxisNoise* a = noise.Find(sensor, axis);
    if (a == nullptr) continue;
    out += std::string(axis == 0 ? " " : "; ") + kAxisName[axis] + " tau " +
           Format("%.3g", a->adev.tau_s[a->fit.first]) + " .. " +
           Format("%.3g", a->adev.tau_s[a->fit.last]) + " s, " +
           std::to_string(a->fit.points()) + " points, chi2/point " +
           Format("%.2g", a->fit.chi2 / static_cast<double>(a->fit.points())) +
           (a->fit.misfit ? " (MISFIT)" : "");
  }
  out += "\n";
  for (int axis = 0; axis < 3; ++axis) {
    const signal::AxisNoise* a = noise.Find(sensor, axis);
    if (a == nullptr || !a->fit.misfit) continue;
    out += std::string("  warning: ") + kAxisName[axis] + ": " + MisfitWords(*a, noise) + "\n";
  }
  return out;
}

}  // namespace

std::string MisfitWords(const signal::AxisNoise& a, const signal::StillNoise& noise) {
  return "the noise terms do not describe this Allan deviation (chi2/point " +
         Format("%.3g", a.fit.chi2 / static_cast<double>(a.fit.points())) + ", above " +
         Format("%.3g", noise.options.terms.misfit_chi2_per_point) +
         "): the still data holds motion, vibration, a filter's correlation at the short taus "
         "(raise the shortest tau fitted: plumb allan --tau-min) or steps; only the upper bounds "
         "stand";
}

namespace {

json TermJson(const signal::NoiseTerm& t, const NoiseTermLabel& label) {
  json j = {{"name", label.name},
            {"value", Number(t.value())},
            {"unit", label.unit},
            {"resolved", t.resolved},
            {"in_model", t.in_model},
            {"fitted", Number(t.fitted)},
            {"chi2_rise", Number(t.chi2_rise)},
            {"upper_bound", Number(t.upper_bound)},
            {"bound_tau_s", Number(t.bound_tau_s)},
            {"tau_min_s", Number(t.tau_min_s)},
            {"tau_max_s", Number(t.tau_max_s)}};
  if (!label.datasheet_unit.empty()) {
    j["datasheet"] = {{"value", Number(t.value() * label.datasheet_scale)},
                      {"unit", label.datasheet_unit}};
  }
  return j;
}

json AxisJson(const signal::AxisNoise& a, const std::string& unit) {
  json points = json::array();
  const signal::AllanDeviation& d = a.adev;
  for (std::size_t j = 0; j < d.tau_s.size(); ++j) {
    points.push_back({{"tau_s", Number(d.tau_s[j])},
                      {"m", d.cluster_size[j]},
                      {"adev", Number(d.adev[j])},
                      {"lower", Number(d.adev_lower[j])},
                      {"upper", Number(d.adev_upper[j])},
                      {"edf", Number(d.edf[j])},
                      {"noise", signal::PowerLawNoiseName(d.noise[j])},
                      {"terms", d.terms[j]}});
  }
  json terms = json::object();
  for (int k = 0; k < signal::kNoiseTermCount; ++k) {
    const auto kind = static_cast<NoiseTermKind>(k);
    terms[signal::NoiseTermSymbol(kind)] =
        TermJson(a.fit.term(kind), LabelNoiseTerm(a.sensor, kind, unit));
  }
  return {{"adev", points},
          {"fit",
           {{"tau_min_s", Number(d.tau_s[a.fit.first])},
            {"tau_max_s", Number(d.tau_s[a.fit.last])},
            {"points", a.fit.points()},
            {"chi2", Number(a.fit.chi2)},
            {"dof", a.fit.dof},
            {"iterations", a.fit.iterations},
            {"misfit", a.fit.misfit}}},
          {"terms", terms}};
}

}  // namespace

NoiseTermLabel LabelNoiseTerm(Sensor sensor, NoiseTermKind kind, const std::string& u) {
  const bool accel = sensor == Sensor::kAccel;
  const bool si = accel ? u == "m/s^2" : u == "rad/s";
  const double ug = 1.0 / units::kMicroG;
  const double deg_h = units::kDegPerHourPerRadPerS;
  NoiseTermLabel l;
  switch (kind) {
    case NoiseTermKind::kQuantisation:
      l = {accel ? "velocity quantisation" : "angle quantisation", u + " s", "", 0.0};
      if (si) {
        l.unit = accel ? "m/s" : "rad";
        l.datasheet_unit = accel ? "" : "deg";
        l.datasheet_scale = accel ? 0.0 : units::kDegPerRad;
      }
      break;
    case NoiseTermKind::kWhite:
      l = {accel ? "velocity random walk" : "angle random walk", u + "/sqrt(Hz)", "", 0.0};
      if (si) {
        l.datasheet_unit = accel ? "ug/sqrt(Hz)" : "deg/sqrt(h)";
        l.datasheet_scale = accel ? ug : units::kDegPerRad * units::kSqrtSecondsPerSqrtHour;
      }
      break;
    case NoiseTermKind::kBiasInstability:
      l = {"bias instability", u, "", 0.0};
      if (si) {
        l.datasheet_unit = accel ? "ug" : "deg/h";
        l.datasheet_scale = accel ? ug : deg_h;
      }
      break;
    case NoiseTermKind::kRandomWalk:
      l = {accel ? "acceleration random walk" : "rate random walk", u + "/s/sqrt(Hz)", "", 0.0};
      if (si) {
        l.unit = accel ? "m/s^3/sqrt(Hz)" : "rad/s^2/sqrt(Hz)";
        l.datasheet_unit = accel ? "ug/sqrt(s)" : "deg/h/sqrt(h)";
        l.datasheet_scale = accel ? ug : deg_h * units::kSqrtSecondsPerSqrtHour;
      }
      break;
    case NoiseTermKind::kRamp:
      l = {accel ? "acceleration ramp" : "rate ramp", u + "/s", "", 0.0};
      if (si) {
        l.unit = accel ? "m/s^3" : "rad/s^2";
        l.datasheet_unit = accel ? "ug/s" : "deg/h/h";
        l.datasheet_scale = accel ? ug : deg_h * units::kSecondsPerHour;
      }
      break;
  }
  return l;
}

std::string StillNoiseText(const signal::StillNoise& noise) {
  std::ostringstream os;
  os << "still data: " << noise.segments.size() << " segment"
     << (noise.segments.size() == 1 ? "" : "s") << ", " << noise.samples << " samples, "
     << Format("%.6g", noise.still_s) << " s (longest " << Format("%.6g", noise.longest_s)
     << " s), sample interval " << Format("%.6g", noise.dt_s) << " s\n";
  for (const std::string& note : noise.notes) os << "  note: " << note << "\n";
  if (!noise.axes.empty()) {
    const signal::AxisNoise& a = noise.axes.front();
    os << "Allan deviation: overlapping, pooled over the segments; "
       << Format("%.3g", 100.0 * a.adev.confidence)
       << " % intervals from the exact chi-square quantile with the EDF of NIST SP 1065 "
          "Table 5 for the fitted noise type\n"
       << "terms: weighted least squares of AVAR = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + "
          "K^2 tau/3 [+ R^2 tau^2/2], coefficients >= 0 (IEEE Std 952 annex C); '<' marks an "
          "upper bound at "
       << Format("%.3g", 100.0 * noise.options.terms.term_confidence)
       << " %, a term the data does not resolve\n";
  }
  for (Sensor sensor : {Sensor::kAccel, Sensor::kGyro}) {
    if (noise.Find(sensor, 0) != nullptr) os << "\n" << SensorTable(noise, sensor);
  }
  return os.str();
}

json StillNoiseJson(const signal::StillNoise& noise, const ImuSeries& series) {
  json segments = json::array();
  for (const StillSegment& s : noise.segments) {
    segments.push_back({{"label", s.label},
                        {"begin", s.begin},
                        {"end", s.end},
                        {"t_start_s", Number(series.t_s[s.begin])},
                        {"t_end_s", Number(series.t_s[s.end - 1])}});
  }
  json doc = {
      {"schema_version", 1},
      {"method",
       {{"adev", "overlapping Allan deviation (IEEE Std 952 annex C), still segments pooled: "
                 "each gives the clusters that fit inside it"},
        {"intervals", "chi-square interval with the exact quantile (NIST SP 1065 section 5.3)"},
        {"edf", "Howe, Allan and Barnes (NIST SP 1065 Table 5) for the noise type the fit "
                "finds at each tau; Satterthwaite over segments"},
        {"terms", "weighted least squares of AVAR = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + "
                  "K^2 tau/3 [+ R^2 tau^2/2] with non-negative coefficients, weights "
                  "edf / (2 AVAR_model^2), reweighted"},
        {"resolved", "the term dominates the model at enough consecutive points and the data "
                     "lies above the best fit without it there (Bonferroni over the points); "
                     "otherwise value is the smallest per-point upper bound"}}},
      {"sample_interval_s", Number(noise.dt_s)},
      {"still",
       {{"segments", segments},
        {"samples", noise.samples},
        {"duration_s", Number(noise.still_s)},
        {"longest_s", Number(noise.longest_s)},
        {"notes", noise.notes}}}};
  doc["confidence"] = Number(noise.options.allan.confidence);
  doc["term_confidence"] = Number(noise.options.terms.term_confidence);
  for (Sensor sensor : {Sensor::kAccel, Sensor::kGyro}) {
    if (noise.Find(sensor, 0) == nullptr) continue;
    const std::string unit = sensor == Sensor::kAccel ? noise.acc_unit : noise.gyr_unit;
    json axes = json::object();
    for (int axis = 0; axis < 3; ++axis) {
      const signal::AxisNoise* a = noise.Find(sensor, axis);
      if (a != nullptr) axes[kAxisName[axis]] = AxisJson(*a, unit);
    }
    doc[SensorKey(sensor)] = {{"unit", unit}, {"axes", axes}};
  }
  return doc;
}

}  // namespace plumb::report

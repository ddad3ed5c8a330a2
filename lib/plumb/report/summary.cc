#include "plumb/report/summary.h"

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <sstream>

#include "plumb/estimation/uncertainty.h"
#include "plumb/report/version.h"

namespace plumb::report {
namespace {

template <typename... Args>
std::string Format(const char* fmt, Args... args) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

std::string Vec(const Vec3& v) {
  return "(" + Format("%.3g", v.x()) + ", " + Format("%.3g", v.y()) + ", " + Format("%.3g", v.z()) +
         ")";
}

std::string DetectedLines(const segmentation::SegmentationResult& s) {
  const auto& rep = s.report;
  const auto& n = s.noise;
  const auto& d = s.detail;
  std::ostringstream os;
  os << "still segments: " << s.segments.size() << " detected (window "
     << Format("%.3g", rep.window_s) << " s, shortest kept " << Format("%.3g", rep.min_still_s)
     << " s";
  if (rep.rejected_short > 0) os << ", " << rep.rejected_short << " shorter runs dropped";
  os << ")\n";
  os << "  noise from " << n.samples << " samples in " << n.periods.size() << " still period"
     << (n.periods.size() == 1 ? "" : "s") << " (" << n.source << "): accel sigma "
     << Vec(n.acc_sigma) << " " << n.acc_unit;
  if (n.has_gyro) os << ", gyro sigma " << Vec(n.gyr_sigma) << " " << n.gyr_unit;
  os << " per sample\n";
  os << "  thresholds: accel variance ratio " << Format("%.3g", d.acc_threshold);
  if (d.gyr_threshold > 0) os << ", gyro variance ratio " << Format("%.3g", d.gyr_threshold);
  if (d.rate_threshold > 0) os << ", rate chi2(3) " << Format("%.3g", d.rate_threshold);
  os << "; windows failing: accel " << d.failed_acc;
  if (d.gyr_threshold > 0) os << ", gyro " << d.failed_gyr;
  if (d.rate_threshold > 0) os << ", rate " << d.failed_rate;
  os << ", gap " << d.failed_gap << " of " << d.windows << "\n";
  if (d.rejected_by_gyro > 0) {
    os << "  " << d.rejected_by_gyro << " still runs of the accelerometer rejected by the "
       << "gyroscope tests (slow turns?)\n";
  }
  return os.str();
}

}  // namespace

std::string SegmentationSummary(const segmentation::SegmentationResult& s,
                                const std::string& source, bool with_notes) {
  std::ostringstream os;
  if (s.report.method == "given") {
    os << "still segments: " << s.segments.size() << " given"
       << (source.empty() ? "" : " in " + source) << "\n";
  } else {
    os << DetectedLines(s);
  }
  if (with_notes) {
    for (const auto& note : s.report.notes) os << "  note: " << note << "\n";
  }
  return os.str();
}

std::string FailedGatesText(const estimation::FitReport& fit) {
  if (fit.gates.empty()) return "";
  std::string names;
  for (const auto& g : fit.gates) names += (names.empty() ? "" : ", ") + g.name;
  const std::size_t n = fit.gates.size();
  return "failed " + (n == 1 ? std::string("a gate") : std::to_string(n) + " gates") + " (" +
         names + ")";
}

std::string FitVerdict(const estimation::FitReport& fit) {
  if (!fit.gates.empty()) {
    // Whatever chi^2/dof says, a failed gate means the fit is not to be trusted as it stands.
    const std::string value =
        fit.dof > 0 ? "chi2/dof " + Format("%.3g", fit.chi2_dof()) : std::string("no dof left");
    return value + ", but the fit " + FailedGatesText(fit) + ": not to be trusted as it stands";
  }
  if (fit.dof <= 0) {
    return "no degrees of freedom left: the fit cannot be judged (record more still poses)";
  }
  const double ratio = fit.chi2_dof();
  const double spread = std::sqrt(2.0 / fit.dof);
  const std::string value =
      "chi2/dof " + Format("%.3g", ratio) + " (expected 1 +- " + Format("%.2g", spread) + ")";
  if (estimation::Chi2AboveBand(fit)) {
    return value + ": residuals exceed the noise; the model or the segments miss something";
  }
  if (ratio < estimation::Chi2Band(fit.dof).first) {
    return value + ": residuals below the noise; the noise level is overestimated";
  }
  return value + ": consistent with the noise";
}

std::string GateLines(const estimation::FitReport& fit, const std::string& source) {
  std::string out;
  for (const auto& g : fit.gates) {
    out += "gate failed: " + g.name + ": " + (source.empty() ? "" : source + ": ") + g.message + "\n";
  }
  return out;
}

std::string CalibrationSummary(const estimation::CalibrationResult& r, const std::string& source) {
  std::ostringstream os;
  os << "plumb " << Version() << " calibrate: method " << r.calibration.method << ", model " << r.calibration.model.spec()
     << "\n";
  os << FitVerdict(r.fit);
  const std::size_t lost = r.calibration.observability.unobservable.size();
  if (lost > 0) os << "; " << lost << " unobservable direction" << (lost > 1 ? "s" : "");
  const std::size_t weak = r.calibration.observability.weakly_determined.size();
  if (weak > 0) os << "; " << weak << " weakly determined combination" << (weak > 1 ? "s" : "") << " held";
  os << "\n" << GateLines(r.fit, source) << "\n" << FullReport(r);
  return os.str();
}

std::string BeforeAfterSummary(const estimation::CalibrationResult& before,
                               const estimation::CalibrationResult& after) {
  std::ostringstream os;
  auto row = [&](const std::string& what, const std::string& b, const std::string& a) {
    os << "  " << Format("%-28s", what.c_str()) << Format("%-34s", b.c_str()) << a << "\n";
  };
  auto vec = [](const Vec3& v) { return Format("%.4g %.4g %.4g", v.x(), v.y(), v.z()); };
  os << "before and after (same segments):\n";
  row("model", before.calibration.model.spec(), after.calibration.model.spec());
  row("chi2 / dof", Format("%.1f / %d", before.fit.chi2, before.fit.dof),
      Format("%.1f / %d", after.fit.chi2, after.fit.dof));
  row("chi2/dof", Format("%.3f", before.fit.chi2_dof()), Format("%.3f", after.fit.chi2_dof()));
  row("accel RMS (" + before.calibration.acc_unit + ")", vec(before.fit.rms_acc), vec(after.fit.rms_acc));
  if (before.calibration.has_gyro && after.calibration.has_gyro) {
    row("gyro RMS (" + before.calibration.gyr_unit + ")", vec(before.fit.rms_gyr), vec(after.fit.rms_gyr));
    if (before.fit.motion_segments > 0) {
      row("motion RMS (rad)", vec(before.fit.rms_motion), vec(after.fit.rms_motion));
    }
    if (before.fit.velocity_segments > 0 || after.fit.velocity_segments > 0) {
      row("velocity RMS (m/s)",
          before.fit.velocity_segments > 0 ? vec(before.fit.rms_velocity) : std::string("-"),
          after.fit.velocity_segments > 0 ? vec(after.fit.rms_velocity) : std::string("-"));
    }
  }
  const bool same_residuals = before.fit.velocity_segments == after.fit.velocity_segments;
  const bool worse = after.fit.chi2_dof() >= before.fit.chi2_dof();
  if (same_residuals) {
    os << "  chi2 fell by " << Format("%.1f", before.fit.chi2 - after.fit.chi2) << "\n";
  } else {
    os << "  the refit also fits the velocity residuals of the turns (the accelerometer while "
          "it turns), which the fit before does not: chi2 sums other residuals, compare "
          "chi2/dof\n";
  }
  if (worse) {
    os << "  chi2/dof rose from " << Format("%.3f", before.fit.chi2_dof()) << " to "
       << Format("%.3f", after.fit.chi2_dof()) << ": not advised, the fit before is the better "
       << "one\n";
  }
  // Still above the band after the best effect: say how much of the misfit is left.
  const double upper = estimation::Chi2BandUpper(after.fit.dof);
  if (!worse && same_residuals && after.fit.dof > 0 && after.fit.chi2_dof() > upper) {
    const double excess_before = std::max(before.fit.chi2 - before.fit.dof, 0.0);
    const double excess_after = std::max(after.fit.chi2 - after.fit.dof, 0.0);
    os << "  still above its band after the refit: chi2/dof " << Format("%.3g", after.fit.chi2_dof())
       << " (band up to " << Format("%.3g", upper) << "); the misfit beyond the noise (chi2 - dof) went "
       << Format("%.1f", excess_before) << " -> " << Format("%.1f", excess_after) << ", "
       << Format("%.0f", excess_before > 0 ? 100.0 * excess_after / excess_before : 100.0)
       << "% of it not explained by this effect: add the next candidate and diagnose again; what "
          "no catalogue effect explains is outside plumb's model (segments that are not still, "
          "an effect not in the catalogue), and the sigmas are not to be trusted until it is "
          "explained\n";
  }
  bool header = false;
  for (const auto& p : after.calibration.parameters) {
    const bool known = std::any_of(before.calibration.parameters.begin(), before.calibration.parameters.end(),
                                   [&](const estimation::ParameterEstimate& q) { return q.name == p.name; });
    if (known || p.fixed) continue;
    if (!header) os << "parameters added:\n";
    header = true;
    const std::string sigma = p.observable ? Format("%.3g", p.sigma) : std::string("unobservable");
    os << "  " << Format("%-36s", p.name.c_str()) << Format("%14.6g", p.value) << " +- "
       << sigma << "  " << p.unit << "\n";
  }
  return os.str();
}

}  // namespace plumb::report

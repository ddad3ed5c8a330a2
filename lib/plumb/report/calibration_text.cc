#include "plumb/report/calibration_text.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "plumb/core/number_text.h"
#include "plumb/core/units.h"
#include "plumb/estimation/observability.h"
#include "plumb/estimation/uncertainty.h"
#include "plumb/model/board_mount.h"

namespace plumb::report {
namespace {

std::string Vec(const Vec3& v, const char* fmt = "%.4g") {
  return "(" + FormattedText(fmt, v.x()) + ", " + FormattedText(fmt, v.y()) + ", " + FormattedText(fmt, v.z()) + ")";
}

/// `text` right-aligned in 12 columns.
std::string Pad(const std::string& text) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%12s", text.c_str());
  return buf;
}

/// The table of `parameters`: value, sigma (and sigma * `scale` when scale > 1), unit.
std::string ParameterTable(const std::vector<estimation::ParameterEstimate>& parameters,
                           double scale) {
  const bool scaled = scale > 1.0;
  std::string out;
  char line[192];
  std::snprintf(line, sizeof line, "%-34s %15s %12s%s  %s\n", "parameter", "value", "sigma",
                scaled ? "       scaled" : "", "unit");
  out += line;
  for (const auto& p : parameters) {
    const bool none = p.fixed || !p.observable;
    std::string sigma = p.fixed ? "fixed" : !p.observable ? "unobservable" : FormattedText("%.3g", p.sigma);
    const std::string extra = !scaled ? "" : " " + Pad(none ? "" : FormattedText("%.3g", scale * p.sigma));
    std::snprintf(line, sizeof line, "%-34s %15.8g %12s%s  %s\n", p.name.c_str(), p.value,
                  sigma.c_str(), extra.c_str(), p.unit.c_str());
    out += line;
  }
  return out;
}

/// The rotation parameters (rotation.x..z, rad) of board IMU `b`, in axis order.
std::vector<const estimation::ParameterEstimate*> RotationParameters(
    const estimation::BoardImuCalibration& b) {
  std::vector<const estimation::ParameterEstimate*> out;
  for (int i = 0; i < 3; ++i) out.push_back(&b.MountParameter(model::board_mount::kRotation + i));
  return out;
}

/// The rotation (index into `rotation`) that leads combination `d`: its coefficient the
/// combination's largest (g per rad against a bias's 1 per m/s^2; a tie with the accelerometer
/// matrix's term, which tilts alike), not a trace of one in a gyroscope's combination;
/// rotation.size() when none does.
std::size_t LeadingRotation(const estimation::Combination& d,
                            const std::vector<const estimation::ParameterEstimate*>& rotation) {
  constexpr double kLeadShare = 0.999;  // its own largest, to rounding
  std::size_t lead = rotation.size();
  double lead_coefficient = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < d.names.size(); ++i) {
    largest = std::max(largest, std::abs(d.coefficients[i]));
    for (std::size_t r = 0; r < rotation.size(); ++r) {
      if (d.names[i] == rotation[r]->name &&
          std::abs(d.coefficients[i]) > std::abs(lead_coefficient)) {
        lead = r;
        lead_coefficient = d.coefficients[i];
      }
    }
  }
  return std::abs(lead_coefficient) < kLeadShare * largest ? rotation.size() : lead;
}

/// Combination `d` divided by the coefficient of `name`: that parameter's value (rad) once the
/// others are known, with its sigma, and `remark` after it.
std::string LedCombinationText(const estimation::Combination& d, const std::string& name,
                               const std::string& remark) {
  double lead_coefficient = 1.0;
  for (std::size_t i = 0; i < d.names.size(); ++i) {
    if (d.names[i] == name) lead_coefficient = d.coefficients[i];
  }
  Eigen::VectorXd coefficients(static_cast<Eigen::Index>(d.names.size()));
  for (std::size_t i = 0; i < d.names.size(); ++i) {
    coefficients(static_cast<Eigen::Index>(i)) = d.coefficients[i] / lead_coefficient;
  }
  const double value = d.value / lead_coefficient;
  const double sigma = d.sigma / std::abs(lead_coefficient);
  return "  " + estimation::FormatCombination(coefficients, d.names, false) + " = " +
         FormattedText("%.4g", value) + " +- " + FormattedText("%.2g", sigma) + " rad (" +
         FormattedText("%.4g", value * units::kDegPerRad) + " +- " +
         FormattedText("%.2g", sigma * units::kDegPerRad) + " deg)" + remark + "\n";
}

/// Where the data determine `rotation` only together with other parameters (one still pose:
/// a tilt of the IMU trades with the accelerometers' bias difference, g * tilt, and a turn
/// about gravity is not seen): each component alone where determined, else the determined (or
/// weakly determined) combination it leads, divided by its coefficient: the component's value
/// once the others are known; and the components nothing determines.
std::string UndeterminedMountText(const estimation::Calibration& c,
                                  const std::vector<const estimation::ParameterEstimate*>& rotation,
                                  bool one_orientation) {
  std::string out;
  std::vector<bool> said(rotation.size(), false);
  for (std::size_t r = 0; r < rotation.size(); ++r) {
    const estimation::ParameterEstimate& p = *rotation[r];
    if (!p.observable || !std::isfinite(p.sigma)) continue;
    said[r] = true;
    out += LedCombinationText({p.name, p.value, p.sigma, 0.0, {p.name}, {1.0}}, p.name, "");
  }
  const std::pair<const std::vector<estimation::Combination>*, const char*> lists[] = {
      {&c.observability.determined, ""},
      {&c.observability.weakly_determined,
       ": weakly determined, held where it starts (see the weakly determined combinations)"}};
  for (const auto& [list, remark] : lists) {
    for (const estimation::Combination& d : *list) {
      const std::size_t lead = LeadingRotation(d, rotation);
      if (lead == rotation.size() || said[lead]) continue;
      said[lead] = true;
      out += LedCombinationText(d, rotation[lead]->name, remark);
    }
  }
  std::string unsaid;
  for (std::size_t r = 0; r < rotation.size(); ++r) {
    if (!said[r]) unsaid += (unsaid.empty() ? "" : ", ") + rotation[r]->name;
  }
  if (!unsaid.empty()) {
    out += "  " + unsaid +
           (one_orientation
                ? ": not seen at all (a turn about gravity, which still poses in one orientation "
                  "cannot show)\n"
                : ": leads no combination these data determine (see the unobservable directions)\n");
  }
  return out;
}

/// Board IMU `b`'s rotation into the body: determined (angle, axis, sigmas) or what of it is.
std::string MountText(const estimation::Calibration& c, const estimation::FitReport& fit,
                      const estimation::BoardImuCalibration& b) {
  const std::vector<const estimation::ParameterEstimate*> rotation = RotationParameters(b);
  const Eigen::AngleAxisd aa(b.R_b_i());
  const std::string held = FormattedText("%.4g", aa.angle() * units::kDegPerRad) + " deg about " +
                           Vec(aa.axis(), "%.3f");
  if (b.RotationDetermined()) {
    return "rotation into the body " + held + ", sigma about x, y, z " +
           Vec(Vec3(rotation[0]->sigma, rotation[1]->sigma, rotation[2]->sigma) *
                   units::kDegPerRad, "%.2g") +
           " deg\n";
  }
  return "rotation into the body not determined by these data (held at " + held +
         "); what they determine of it:\n" +
         UndeterminedMountText(c, rotation, fit.distinct_poses <= 1);
}

/// Board IMU `b`'s place and clock on the board: its lever arm (cm) and time offset (ms) with
/// sigma (`scale`d) where the turns determine them, or why they are not.
std::string PlaceText(const estimation::BoardImuCalibration& b, double scale) {
  using model::board_mount::kLeverArm;
  using model::board_mount::kTimeOffset;
  if (b.MountParameter(kTimeOffset).fixed) {
    return "lever arm and time offset held at 0 (no turn, sampled finely enough by both, compares "
           "its accelerometer with IMU 0's); ";
  }
  auto value = [&](int i, double unit) {
    const estimation::ParameterEstimate& p = b.MountParameter(i);
    if (!p.observable || !std::isfinite(p.sigma)) return std::string("not determined");
    return FormattedText("%.3g", p.value * unit) + " +- " +
           FormattedText("%.2g", scale * p.sigma * unit);
  };
  const double cm = units::kCmPerM;
  return "lever arm x, y, z " + value(kLeverArm, cm) + ", " + value(kLeverArm + 1, cm) + ", " +
         value(kLeverArm + 2, cm) + " cm and time offset " + value(kTimeOffset, units::kMsPerS) +
         " ms, from the turns (their comparison with IMU 0's: chi2 " +
         FormattedText("%.4g", b.turn_chi2) + " on " + std::to_string(b.turn_residuals) +
         " values); ";
}

/// The board's other IMUs (SPEC 6): each one's rotation into the body and its parameters.
std::string BoardText(const estimation::Calibration& c, const estimation::FitReport& fit,
                      double scale) {
  std::string out;
  for (const auto& b : c.board) {
    out += "\nimu" + std::to_string(b.instance) + ", fitted with IMU 0 (the attitudes shared); " +
           PlaceText(b, scale) + MountText(c, fit, b);
    out += ParameterTable(b.parameters, scale);
  }
  return out;
}

}  // namespace

std::string OverDispersionNote(const estimation::FitReport& fit) {
  if (!estimation::Chi2AboveBand(fit)) return "";
  const double scale = estimation::SigmaScale(fit);
  const double upper = estimation::Chi2BandUpper(fit.dof);
  return "chi2/dof " + FormattedText("%.4g", fit.chi2_dof()) + " is above its band (up to " +
         FormattedText("%.3g", upper) +
         "): the residuals exceed the noise the fit was whitened with, so the formal sigma "
         "(from that noise) is too small; 'scaled' is sigma * sqrt(chi2/dof) = sigma * " +
         FormattedText("%.4g", scale) +
         ". The JSON's sigma and covariance are the scaled ones (sigma_formal beside); the "
         "exported files carry values only\n" +
         (estimation::MisfitBeyondNoise(fit)
              ? "chi2/dof is more than " + FormattedText("%.0f", estimation::kMisfitFactor) +
                    " times its band: the misfit is a missing effect or bad segments, not "
                    "noise, and even the scaled sigma assumes it is random: do not trust these "
                    "parameters to their sigma (another session of the same sensor can differ "
                    "by more) until 'plumb diagnose' explains the misfit\n"
              : std::string());
}

std::string BriefReport(const estimation::CalibrationResult& result) {
  const estimation::Calibration& c = result.calibration;
  const estimation::FitReport& fit = result.fit;
  std::ostringstream os;
  os << "method " << c.method << ", model " << c.model.spec() << ": " << fit.still_segments
     << " still segments, " << fit.motion_segments << " motion intervals\n";
  os << "chi2 " << FormattedText("%.6g", fit.chi2) << " on " << fit.dof << " dof, chi2/dof "
     << FormattedText("%.4g", fit.chi2_dof()) << "; rank " << c.observability.rank << " of "
     << c.observability.num_unknowns << " unknowns"
     << (c.observability.wander_states > 0
             ? " (and " + std::to_string(c.observability.wander_states) + " bias-wander states)"
             : std::string())
     << "; "
     << (fit.converged ? "converged" : "NOT converged") << " in " << fit.iterations
     << " iterations\n";
  return os.str();
}

std::string FullReport(const estimation::CalibrationResult& result) {
  const estimation::Calibration& c = result.calibration;
  const estimation::FitReport& fit = result.fit;
  std::ostringstream os;
  os << BriefReport(result);
  os << "site: " << (c.site.known ? FormattedText("%.6f", c.site.lat_deg) + " deg, " +
                                      FormattedText("%.6f", c.site.lon_deg) + " deg, " +
                                      FormattedText("%.1f", c.site.height_m) + " m (" + c.site.source + ")"
                                : std::string("none"))
     << ", gravity " << FormattedText("%.6f", c.site.gravity()) << " m/s^2\n";
  os << "residual RMS per axis: accel " << Vec(fit.rms_acc) << " " << c.acc_unit;
  if (c.has_gyro) os << ", gyro " << Vec(fit.rms_gyr) << " " << c.gyr_unit;
  if (fit.motion_segments > 0) os << ", motion " << Vec(fit.rms_motion) << " rad";
  os << "\nnoise per sample: accel " << Vec(c.noise.acc) << " " << c.acc_unit << " (tau "
     << FormattedText("%.2f", c.noise.tau_acc) << " samples)";
  if (c.has_gyro) {
    os << ", gyro " << Vec(c.noise.gyr) << " " << c.gyr_unit << " (tau "
       << FormattedText("%.2f", c.noise.tau_gyr) << " samples)";
  }
  os << "\n";
  const bool acc_walk = c.noise.walk_acc.minCoeff() > 0, gyr_walk = c.noise.walk_gyr.minCoeff() > 0;
  if (acc_walk || gyr_walk) {
    os << "bias random walk in the fit (per segment, tied by random-walk factors):";
    if (acc_walk) os << " accel " << Vec(c.noise.walk_acc) << " " << c.acc_unit << "/s/sqrt(Hz)";
    if (gyr_walk) {
      os << (acc_walk ? "," : "") << " gyro " << Vec(c.noise.walk_gyr) << " " << c.gyr_unit
         << "/s/sqrt(Hz)";
    }
    os << "\n";
  }
  const bool acc_bi = c.noise.instability_acc.minCoeff() > 0;
  const bool gyr_bi = c.noise.instability_gyr.minCoeff() > 0;
  if (acc_bi || gyr_bi) {
    os << "bias instability in the fit (Gauss-Markov, tau " << FormattedText("%.3g", c.noise.instability_time_s)
       << " s):";
    if (acc_bi) os << " accel " << Vec(c.noise.instability_acc) << " " << c.acc_unit;
    if (gyr_bi) os << (acc_bi ? "," : "") << " gyro " << Vec(c.noise.instability_gyr) << " " << c.gyr_unit;
    os << "\n";
  }
  if (acc_walk || gyr_walk || acc_bi || gyr_bi) {
    os << "the bias wanders over the session; the biases below are at its start\n";
  } else {
    os << "bias held constant over the session (--constant-bias): the sigma is honest only if "
          "the noise is white\n";
  }
  os << "\n";
  const double scale = estimation::SigmaScale(fit);
  const bool scaled = scale > 1.0;
  if (scaled) os << OverDispersionNote(fit);
  os << ParameterTable(c.parameters, scale);
  os << BoardText(c, fit, scale);
  if (!c.observability.unobservable.empty()) {
    os << "\nunobservable directions (moving along them changes no prediction):\n";
    for (const auto& u : c.observability.unobservable) os << "  " << u << "\n";
  }
  if (!c.observability.weakly_determined.empty()) {
    os << "\nweakly determined combinations (the data place them no better than three times a MEMS "
          "IMU's typical size: each held where the fit starts; a parameter it moves keeps the "
          "data's sigma, which covers the hold, or is unobservable where that sigma exceeds three "
          "typical sizes):\n";
    for (const auto& w : c.observability.weakly_determined) {
      os << "  " << w.text << ": held at " << FormattedText("%.4g", w.value) << "; the data's sigma "
         << FormattedText("%.3g", w.sigma) << " (formal), typical size " << FormattedText("%.3g", w.typical)
         << "\n";
    }
  }
  if (!c.observability.determined.empty()) {
    os << "determined combinations:\n";
    for (const auto& d : c.observability.determined) {
      os << "  " << d.text << " = " << FormattedText("%.8g", d.value) << " +- "
         << FormattedText("%.3g", d.sigma);
      if (scaled) os << " (scaled " << FormattedText("%.3g", scale * d.sigma) << ")";
      os << "\n";
    }
  }
  for (const Notice& n : fit.notes) os << "note: " << n.message << "\n";
  return os.str();
}

}  // namespace plumb::report

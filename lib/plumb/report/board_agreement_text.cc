// See board_agreement_text.h.
#include "plumb/report/board_agreement_text.h"

#include <cmath>

#include "plumb/core/number_text.h"
#include "plumb/core/units.h"
#include "plumb/report/json_report.h"

namespace plumb::report {
namespace {

bool Within(const estimation::ImuAgreement& a, bool after) {
  const double accel = after ? a.accel_after : a.accel_before;
  const double gyro = after ? a.gyro_after : a.gyro_before;
  return accel <= a.accel_limit &&
         (!a.has_gyro || gyro <= estimation::kArduPilotGyroThreshold_rad_s);
}

std::string Verdict(const estimation::ImuAgreement& a) {
  const bool before = Within(a, false), after = Within(a, true);
  std::string verdict;
  if (before && after) {
    verdict = "within ArduPilot's check before and after";
  } else if (after) {
    verdict = "outside ArduPilot's check before, within it after";
  } else if (before) {
    verdict = "within ArduPilot's check before, outside it after";
  } else {
    verdict = "outside ArduPilot's check before and after";
  }
  if (a.matched_by_construction) {
    verdict += ", at the poses recorded, which do not determine the accelerometers' models: "
               "the calibration matches the IMUs there by construction, and says nothing of "
               "other orientations";
  }
  return verdict;
}

/// `value` to `digits` significant digits, 0 below a billionth of `scale` (a difference the
/// fit made vanish).
std::string Shown(double value, double scale, int digits) {
  return SignificantText(std::abs(value) < 1e-9 * scale ? 0.0 : value, digits);
}

}  // namespace

std::string BoardAgreementText(const std::vector<estimation::ImuAgreement>& agreement) {
  using estimation::kArduPilotAccelThreshold_m_s2;
  std::string out =
      "the board's IMUs against IMU 0 at rest (the largest over the poses; ArduPilot arms within " +
      FixedText(kArduPilotAccelThreshold_m_s2, 2) + " m/s^2, z halved, " +
      FixedText(kArduPilotAccelThreshold_m_s2 * estimation::kArduPilotThirdImuFactor, 2) +
      " from IMU3 on, and " +
      FixedText(estimation::kArduPilotGyroThreshold_rad_s * units::kDegPerRad, 0) +
      " deg/s; before -> after calibration, then once the IMUs' turn is taken out):\n";
  for (const estimation::ImuAgreement& a : agreement) {
    const double g = units::kStandardGravity;
    const double w = estimation::kArduPilotGyroThreshold_rad_s * units::kDegPerRad;
    out += "  imu" + std::to_string(a.instance) + " (" + std::to_string(a.poses) +
           (a.poses == 1 ? " pose" : " poses") + "): accel " + Shown(a.accel_before, g, 3) +
           " -> " + Shown(a.accel_after, g, 3) + " m/s^2 (" + Shown(a.accel_in_body, g, 2) +
           " turned)";
    if (a.has_gyro) {
      out += ", gyro " + Shown(a.gyro_before * units::kDegPerRad, w, 3) + " -> " +
             Shown(a.gyro_after * units::kDegPerRad, w, 3) + " deg/s (" +
             Shown(a.gyro_in_body * units::kDegPerRad, w, 2) + " turned)";
    }
    out += ": " + Verdict(a) + "\n";
  }
  return out;
}

nlohmann::json BoardAgreementJson(const std::vector<estimation::ImuAgreement>& agreement) {
  nlohmann::json out = nlohmann::json::array();
  for (const estimation::ImuAgreement& a : agreement) {
    nlohmann::json gyro = nullptr;
    if (a.has_gyro) {
      gyro = {{"before", Number(a.gyro_before)}, {"after", Number(a.gyro_after)},
              {"in_body", Number(a.gyro_in_body)},
              {"limit", Number(estimation::kArduPilotGyroThreshold_rad_s)}};
    }
    out.push_back({{"instance", a.instance},
                   {"poses", a.poses},
                   {"accel",
                    {{"before", Number(a.accel_before)}, {"after", Number(a.accel_after)},
                     {"in_body", Number(a.accel_in_body)}, {"limit", Number(a.accel_limit)}}},
                   {"gyro", gyro},
                   {"within_before", Within(a, false)},
                   {"within_after", Within(a, true)},
                   {"matched_by_construction", a.matched_by_construction}});
  }
  return out;
}

}  // namespace plumb::report

#include "plumb/estimation/advice.h"

#include <cmath>
#include <optional>
#include <string>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/estimation/gates.h"
#include "plumb/estimation/uncertainty.h"

namespace plumb::estimation {
namespace {

/// "the data cannot determine ...; <what to record>", or "" when every parameter is determined.
std::string Undetermined(const Calibration& calibration,
                         const FitReport& fit) {
  bool accel_short = false, gyro_short = false;
  std::vector<std::string> lost;
  const int accel_base = calibration.model.BaseTerm(model::Sensor::kAccel);
  const int gyro_base = calibration.model.BaseTerm(model::Sensor::kGyro);
  for (const auto& p : calibration.parameters) {
    if (p.fixed || p.observable) continue;
    lost.push_back(p.name);
    accel_short = accel_short || p.place.term == accel_base;
    gyro_short = gyro_short || (gyro_base >= 0 && p.place.term == gyro_base);
  }
  if (lost.empty()) return "";
  std::vector<std::string> advice;
  if (accel_short) {
    // The fit's count (gates.h CountDistinctPoses), as its JSON and the one_pose gate say it.
    advice.push_back("the base accelerometer model needs still poses in at least 9 distinct "
                     "orientations (fewer when attitudes are known); found " +
                     std::to_string(fit.distinct_poses));
  }
  if (gyro_short) {
    advice.push_back("the gyroscope matrix needs turns about three independent axes between still "
                     "poses; found " + std::to_string(fit.motion_segments) + " motion intervals" +
                     (calibration.has_gyro && !calibration.site.known
                          ? " (and no site: Earth rate unused)"
                          : ""));
  }
  std::string list;
  for (const auto& name : lost) list += (list.empty() ? "" : ", ") + name;
  std::string message = "the data cannot determine " + list;
  for (const auto& a : advice) message += "; " + a;
  return message;
}

/// To two decimals, as a chi^2 per residual is read.
double Rounded(double x) { return std::round(x * 100.0) / 100.0; }

/// When the velocity residuals of the turns sit above their band: what rests on them.
std::optional<std::string> TurnsNotAtTheirNoise(const Calibration& calibration,
                                                const CalibrationOptions& options,
                                                const FitReport& fit) {
  const TurnVelocityFit turns = VelocityFit(fit);
  if (!turns.above_band()) return std::nullopt;
  std::string needing;
  for (const auto& term : calibration.model.terms()) {
    const auto& info = term.effect->info();
    if (!info.excitation.angular_acceleration) continue;
    needing += (needing.empty() ? "" : ", ") + info.name;
  }
  return "the velocity residuals of the " + std::to_string(turns.residuals / 3) +
         " turns sit at chi2 " + Number(Rounded(turns.per_residual())) +
         " per residual, above their band (" + Number(Rounded(Chi2BandUpper(turns.residuals))) +
         (options.turn_vibration ? ") even weighted by the vibration measured in each turn"
                                 : ") weighted by the white noise alone") +
         ": the accelerometer during the turns carries what the model lacks, so what only they "
         "determine (" +
         (needing.empty() ? std::string("the effects that need the accelerometer in motion")
                          : needing) +
         ") is not to be trusted as it stands";
}

}  // namespace

void AddAdvice(const Calibration& calibration, const StillSet& still,
               const CalibrationOptions& options, FitReport& fit) {
  const geo::Site& site = calibration.site;
  const std::string undetermined = Undetermined(calibration, fit);
  if (!undetermined.empty()) {
    if (options.on_insufficient == InsufficientData::kError) {
      throw InsufficientDataError(undetermined);
    }
    fit.warnings.push_back(Notice{"undetermined", undetermined, {}});
  }
  for (const NotATurn& m : fit.not_turns) AddNotice(fit.notes, "not_a_turn", NotATurnText(fit, m));
  if (const std::optional<std::string> turns = TurnsNotAtTheirNoise(calibration, options, fit)) {
    fit.warnings.push_back(Notice{"turns_above_noise", *turns, {}});
  }
  if (!site.known) {
    fit.warnings.push_back(Notice{
        "site_unknown",
        "no site given: gravity fixed at " + std::to_string(site.gravity()) + " m/s^2" +
        (calibration.has_gyro ? " and Earth rate left out; the accelerometer scale and the "
                                "gyroscope bias depend on it"
                              : "; the accelerometer scale depends on it") +
        " (give " + OptionText(Option::kSite) + ")",
        {Option::kSite}});
  }
  if (site.known && calibration.has_gyro && !still.AnyAttitudeKnown() &&
      !options.first_heading_deg) {
    fit.warnings.push_back(Notice{
        "heading_assumed",
        "the heading of the first still pose is held at 0 (x north) as the gauge; with a site, "
        "Earth rate (" + Number(site.omega_ie_n.head<2>().norm()) +
        " rad/s horizontal) is predicted for that heading: state it (" +
        OptionText(Option::kHeading, "DEG") + " or " + OptionText(Option::kLevelNorth) +
        ") or the gyroscope biases absorb up to that much",
        {Option::kHeading, Option::kLevelNorth}});
  }
}

}  // namespace plumb::estimation

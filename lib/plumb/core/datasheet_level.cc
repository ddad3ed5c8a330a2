// See datasheet_level.h.
#include "plumb/core/datasheet_level.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb {

const std::vector<std::pair<std::string, double>>& DatasheetUnits(WanderLevel level) {
  static const double kDegPerHour = 1.0 / units::kDegPerHourPerRadPerS;
  static const std::vector<std::pair<std::string, double>> kAccelWalk{
      {"m/s^3/sqrt(Hz)", 1.0}, {"m/s^2/sqrt(s)", 1.0}, {"ug/sqrt(s)", units::kMicroG},
      {"ug/sqrt(h)", units::kMicroG / units::kSqrtSecondsPerSqrtHour}};
  static const std::vector<std::pair<std::string, double>> kGyroWalk{
      {"rad/s^2/sqrt(Hz)", 1.0}, {"rad/s/sqrt(s)", 1.0}, {"deg/s/sqrt(s)", units::kRadPerDeg},
      {"deg/h/sqrt(h)", kDegPerHour / units::kSqrtSecondsPerSqrtHour}};
  static const std::vector<std::pair<std::string, double>> kAccelInstability{
      {"m/s^2", 1.0}, {"ug", units::kMicroG}, {"mg", units::kMilliG}};
  static const std::vector<std::pair<std::string, double>> kGyroInstability{
      {"rad/s", 1.0}, {"deg/s", units::kRadPerDeg}, {"deg/h", kDegPerHour}};
  switch (level) {
    case WanderLevel::kAccelWalk:
      return kAccelWalk;
    case WanderLevel::kGyroWalk:
      return kGyroWalk;
    case WanderLevel::kAccelInstability:
      return kAccelInstability;
    case WanderLevel::kGyroInstability:
      break;
  }
  return kGyroInstability;
}

double ParseDatasheetLevel(const std::string& text, WanderLevel level) {
  const auto& units = DatasheetUnits(level);
  std::string names;
  for (const auto& u : units) names += (names.empty() ? "" : ", ") + u.first;
  std::size_t end = 0;
  double v = 0;
  try {
    v = std::stod(text, &end);
  } catch (const std::exception&) {
    throw Error("must be a number >= 0 with an optional unit (" + names + "), got '" + text + "'");
  }
  std::string unit = text.substr(end);
  unit.erase(std::remove(unit.begin(), unit.end(), ' '), unit.end());
  double scale = 1.0;
  if (!unit.empty()) {
    const auto it = std::find_if(units.begin(), units.end(),
                                 [&](const auto& u) { return u.first == unit; });
    if (it == units.end()) {
      throw Error("unit '" + unit + "' not known here; use one of " + names + " (got '" + text +
                  "')");
    }
    scale = it->second;
  }
  if (!std::isfinite(v) || v < 0) throw Error("must be a finite number >= 0 (got '" + text + "')");
  return v * scale;
}

}  // namespace plumb

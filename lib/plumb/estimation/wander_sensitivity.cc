#include "plumb/estimation/wander_sensitivity.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "plumb/core/option_name.h"

namespace plumb::estimation {
namespace {

/// The level to give for one process: the largest finite bound over the axes whose level is
/// the typical one, when it is above that level; else nothing.
std::optional<double> AtBound(const Vec3& level, const std::array<LevelSource, 3>& from,
                              const Vec3& bound) {
  double out = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (from[static_cast<std::size_t>(i)] != LevelSource::kTypical) continue;
    if (std::isfinite(bound[i]) && bound[i] > level[i]) out = std::max(out, bound[i]);
  }
  if (out <= 0.0) return std::nullopt;
  return out;
}

}  // namespace

std::optional<CalibrationOptions> OptionsAtTheWanderBound(const NoiseModel& noise,
                                                          const WanderBounds& bounds,
                                                          int still_poses,
                                                          const CalibrationOptions& options) {
  if (!options.ModelsWander()) return std::nullopt;
  // Holds enough to estimate the levels: the note of wander_levels.h names that instead.
  if (still_poses >= options.walk_min_poses) return std::nullopt;
  CalibrationOptions out = options;
  bool any = false;
  auto set = [&](std::optional<double>& option, const Vec3& level,
                 const std::array<LevelSource, 3>& from, const Vec3& bound) {
    if (option.has_value()) return;
    if (const std::optional<double> b = AtBound(level, from, bound)) {
      option = *b;
      any = true;
    }
  };
  set(out.accel_walk_density, noise.walk_acc, noise.from.walk_acc, bounds.walk_acc);
  set(out.accel_instability, noise.instability_acc, noise.from.instability_acc,
      bounds.instability_acc);
  set(out.gyro_walk_density, noise.walk_gyr, noise.from.walk_gyr, bounds.walk_gyr);
  set(out.gyro_instability, noise.instability_gyr, noise.from.instability_gyr,
      bounds.instability_gyr);
  if (!any) return std::nullopt;
  out.estimate_walk = false;
  out.check_linearity = false;  // only the sigmas are read
  return out;
}

std::optional<std::string> SigmaRestsOnTheTypicalWander(const CalibrationResult& fit,
                                                        const CalibrationResult& at_bound) {
  double worst = 0.0, from = 0.0, to = 0.0;
  std::string what;
  auto consider = [&](const std::string& name, double s, double s_bound) {
    if (!(s > 0.0) || !std::isfinite(s) || !std::isfinite(s_bound)) return;
    if (s_bound / s > worst) {
      worst = s_bound / s;
      what = name;
      from = s;
      to = s_bound;
    }
  };
  const auto& p = fit.calibration.parameters;
  const auto& q = at_bound.calibration.parameters;
  for (std::size_t i = 0; i < p.size() && i < q.size(); ++i) {
    if (p[i].fixed || !p[i].observable || !q[i].observable) continue;
    consider(p[i].name, p[i].sigma, q[i].sigma);
  }
  const auto& c = fit.calibration.observability.determined;
  const auto& d = at_bound.calibration.observability.determined;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const auto same = std::find_if(d.begin(), d.end(), [&](const Combination& k) {
      return k.text == c[i].text;
    });
    if (same != d.end()) consider(c[i].text, c[i].sigma, same->sigma);
  }
  if (worst < kWorthSaying) return std::nullopt;
  char text[768];
  std::snprintf(text, sizeof text,
                "the sigmas rest on the typical MEMS bias wander, which this session cannot "
                "measure (its still data do not resolve it and its holds are too few to "
                "estimate it): were the wander at the largest level the still data allow (their "
                "95 %% bound), the sigmas would be up to %.3g times larger (%s: %.3g -> %.3g). "
                "Give the sensor's levels (a datasheet's, or %s a long still recording) for "
                "sigmas you can promise",
                worst, what.c_str(), from, to, OptionText(Option::kNoiseFrom).c_str());
  return std::string(text);
}

}  // namespace plumb::estimation

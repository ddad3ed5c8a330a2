// plumb/estimation/wander_sensitivity.h — stage 9 of the backend: how far the sigmas rest on
// bias-wander levels that the session could not measure.
//
// Where the still data neither resolve a wander level nor bound it below the typical MEMS
// sensor's (wander_levels.h), and the session has too few holds to estimate it
// (walk_estimate.h), the typical level stands and the sigmas are only as right as that guess.
// On the seed paper's one-minute hold the biases' sigma is mostly the instability's: a sensor
// wandering five times as much as typical gets NEES/dof 19.9 (sigmas 4.5 times too small), one
// five times quieter 0.20. The minute cannot tell them apart, so it cannot promise either
// sigma; what it can say is how far the sigmas would grow were the wander at the still data's
// 95 % bound (the largest wander they allow). The fit is made again with every such level at
// its bound (the largest over the axes, a level given as a datasheet's would be), and the
// sigmas compared: the largest ratio, with the quantity it belongs to, is the warning.
#pragma once

#include <optional>
#include <string>

#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/result.h"
#include "plumb/estimation/wander_levels.h"

namespace plumb::estimation {

/// `options` with every wander level that `noise` took from the typical sensor set to the
/// still data's bound in `bounds` (where that bound is finite and above it), when the session
/// has fewer than options.walk_min_poses still segments (`still_poses`: too few holds to
/// estimate the levels); nullopt otherwise or when no level qualifies (a constant bias,
/// levels given, measured or bounded below typical).
std::optional<CalibrationOptions> OptionsAtTheWanderBound(const NoiseModel& noise,
                                                          const WanderBounds& bounds,
                                                          int still_poses,
                                                          const CalibrationOptions& options);

/// The largest ratio of `at_bound`'s sigma to `fit`'s over the parameters both determine and
/// the determined combinations, said as a warning when it exceeds kWorthSaying; nullopt
/// otherwise.
std::optional<std::string> SigmaRestsOnTheTypicalWander(const CalibrationResult& fit,
                                                        const CalibrationResult& at_bound);

/// Sigmas that grow by less than this at the bound rest little on the wander: said nothing.
inline constexpr double kWorthSaying = 1.5;

}  // namespace plumb::estimation

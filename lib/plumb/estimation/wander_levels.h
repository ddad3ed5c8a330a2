// plumb/estimation/wander_levels.h — stage 2a of the backend: the levels of the bias wander
// (noise_model.h: a random walk and a Gauss-Markov instability per sensor) that the options do
// not give, per sensor, process and axis, from what still data say about them.
//
// The still data's overlapping Allan deviation is fitted with the processes the estimator
// has: white noise, quantisation, the random walk K and, for the instability, a first-order
// Gauss-Markov process of the assumed correlation time (signal::NoiseTermsOptions::
// gauss_markov_time_s), whose level is the sigma the estimator uses. (IEEE's flicker floor B
// is not that sigma, and where a walk rises over the Gauss-Markov bump the floor is not seen
// at all: 30 minutes still of a sensor with 3 times the typical walk and instability gave,
// with the flicker floor, the typical instability and 1.3-1.7 times the walk; with the
// Gauss-Markov term, 0.7-1.4 times each, tests/estimation/calibrate_sim_test.cc.)
// In the order they are used:
//   covering  a record whose fitted Allan deviation reaches the session's length: its fitted
//             levels, resolved or not (the sum of the terms, which is what the estimator
//             needs, is measured over every interval of the session even where the split
//             between walk and instability is not);
//   measured  otherwise, the fit resolves the term (signal/noise_terms.h's test): its level,
//             but no more than its bound;
//   bounded   the term is not resolved but the Allan deviation bounds it (95 %, the bound of
//             noise_terms.h, which holds whatever else the curve is made of) below the typical
//             MEMS level: the bound;
//   typical   otherwise the typical MEMS level (core/typical_mems.h), in the sensor's units.
// Why not the typical level always: a sensor quieter than typical would get sigmas too large
// and a noisier one sigmas too small (the sigma is a promise only if the noise it rests on is
// the sensor's). Why not the bound always: a multi-pose session's holds last seconds; their
// bound on a walk is tens of times the typical level and would throw away what the session
// can determine. The levels never fall below 1e-3 of the typical ones (the factors stay finite).
//
// Quantisation (IEEE Q) is the resolved Q of the longest still data, per axis, else 0.
//
// The still data: the session's own segments at rest (MeasureStillNoise) and any other still
// recording of the same sensor analysed the same way (CalibrationOptions::other_still_noise). A term
// resolved by several is taken from the longest still data; the bound is the smallest.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/still_set.h"
#include "plumb/signal/noise_terms.h"

namespace plumb::estimation {

/// The still data's 95 % upper bound on each wander level, per axis, in the level's units
/// (+inf where no still data bound it): what the session's own estimate of a level
/// (walk_estimate.h) may not exceed.
struct WanderBounds {
  static constexpr double kNone = std::numeric_limits<double>::infinity();
  Vec3 walk_acc = Vec3::Constant(kNone), walk_gyr = Vec3::Constant(kNone);
  Vec3 instability_acc = Vec3::Constant(kNone), instability_gyr = Vec3::Constant(kNone);
};

struct WanderLevels {
  NoiseModel noise;                ///< with every wander level set
  WanderBounds bounds;             ///< the still data's bounds on them
  std::vector<Notice> notes;  ///< the levels and where they came from (code wander_levels)
};

/// Sets the wander levels that `noise` (stage 2) leaves unset because the options do not give
/// them (file comment). `measured`: the still data analysed (may be empty: the typical levels).
/// `still_poses`: the session's still segments (with enough of them, the note names the
/// estimate from the session, walk_estimate.h, for the levels left typical).
WanderLevels AssignWanderLevels(const NoiseModel& noise,
                                const std::vector<const signal::StillNoise*>& measured,
                                const StartingValues& start, bool has_gyro, double span_s,
                                const CalibrationOptions& options, int still_poses = 0);

/// The options of AnalyseStillNoise that fit the instability as the estimator's Gauss-Markov
/// process of `instability_time_s` (so that AssignWanderLevels need not fit again).
signal::StillNoiseOptions WanderNoiseOptions(double instability_time_s);

/// The noise terms of the session's segments at rest (signal::AnalyseStillNoise with
/// WanderNoiseOptions), or nullopt when they are too short for an Allan deviation (the reason
/// appended to `notes`, code allan_too_short). The axes are analysed at once through `run_jobs` when it is given.
std::optional<signal::StillNoise> MeasureStillNoise(const ImuSeries& series, const StillSet& set,
                                                    double instability_time_s,
                                                    std::vector<Notice>& notes,
                                                    const JobRunner& run_jobs = {});

}  // namespace plumb::estimation

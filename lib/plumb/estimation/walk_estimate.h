// plumb/estimation/walk_estimate.h — the level of the bias wander estimated over the fit
// (stage 2b of the backend, opt-in: CalibrationOptions::estimate_walk), for the levels the
// options do not give.
//
// Why: stage 2a (wander_levels.h) measures a level where the still data resolve it and bounds
// it where they bound it below the typical MEMS sensor's; a multi-pose session's holds last
// seconds and do neither, so the typical level stands. On 12 holds of 30 s a sensor five
// times quieter than typical then gets sigmas larger than the truth needs (NEES/dof 0.44) and
// one five times noisier sigmas far too small (13.5; its chi2/dof 13.9 says so). The session
// shows how far the biases wander between its holds, but only through the fit: the still
// means differ by the wander *and* by the poses. Helmert's variance-component estimate
// (Förstner 1979; Koch, Parameter Estimation and Hypothesis Testing, 3.6) separates them.
// With the wander factors of one sensor (its walk and instability factors,
// residuals/bias_walk_residual.h) as a group g of whitened residuals r_g, their redundancy is
//
//   red_g = sum_{i in g} (1 - h_ii),     h_ii = J_i C J_i^T,
//
// J the whitened Jacobian over every free unknown (model, attitudes, wander states) and C its
// (pseudo-)inverse normal matrix: the part of the group's residuals the fit cannot absorb. At
// the right level E[r_g^T r_g] = red_g, so each iteration scales the sensor's wander variance
// by r_g^T r_g / red_g and fits again, until the level changes by less than kTolerance. One
// scale per sensor: a dozen holds show how far the wander moves, not how it splits between
// walk and instability or among the axes, so that shape is stage 2a's. A sensor whose own
// factors the fit absorbs (red_g <= 2: on 12 holds of 5 s the accelerometer's, whose
// redundancy is about that of its 36 still means against 9 parameters and 24 tilts) takes
// the scale of the whole IMU's factors.
//
// Marginalised over its own scatter: an estimate from red_g redundant factors scatters like
// chi^2_red / red, and a sigma resting on it is optimistic on average by E[s^2 / s_hat^2] =
// red / (red - 2) (Student's t); the variance used is the estimate times red / (red - 2),
// never lifting an estimate below stage 2a's level above it. With red_g below kMinRedundancy
// at the end a level the iteration lowered stays (so small a wander leaves factors the fit
// absorbs, and every higher level was read too high); any other goes back to stage 2a's. The
// level never exceeds the still data's 95 % bound (wander_levels.h: it holds whatever else
// the data are made of) and never falls below 1e-3 of the typical level. Monte Carlo
// (tests/estimation/calibrate_sim_test.cc, CovarianceIsHonestFromQuietToWanderingSensors):
// NEES/dof in its band from 0.2 to 5 times the typical wander.
//
// Why opt-in: the differences between holds that the estimate reads as wander also carry any
// effect the model misses. On imu_tk's Xsens (a gyroscope g-sensitivity the base model
// lacks) the estimate reads a gyroscope wander 278 times the typical level and chi2/dof falls
// from 24 to 1.8: a misfit hidden. An estimated walk far above any MEMS sensor's is the gate
// implausible_walk. At least `walk_min_poses` still segments are needed, else stage 2a's
// levels are kept and a warning says so. Levels given in the options (0 included: no such
// process) are kept.
#pragma once

#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/still_set.h"
#include "plumb/estimation/wander_levels.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"

namespace plumb::estimation {

struct WalkEstimate {
  NoiseModel noise;        ///< the noise model with the wander levels the session resolves
  int iterations = 0;      ///< fits made
  std::vector<Notice> notes;     ///< what was done (code walk_estimated)
  std::vector<Notice> warnings;  ///< what was assumed for lack of data
  /// Non-empty when an estimated walk is implausibly large (the gate implausible_walk).
  std::string implausible;
};

/// Resolves the levels stage 2a could not (file comment): iterates fits of the problem
/// (stages 4-5) from `theta` and the poses of `still`, scaling each chosen sensor's wander.
/// `levels` holds the white noise, the levels of stage 2a with their sources, and the still
/// data's bounds on them.
WalkEstimate ResolveWander(const ImuSeries& series, const model::Model& model,
                           const geo::Site& site, const StillSet& still,
                           const model::ParameterBlocks& theta, const WanderLevels& levels,
                           const StartingValues& start, const CalibrationOptions& options);

}  // namespace plumb::estimation

// plumb/estimation/walk_estimate.h — the bias random walk estimated over the fit (stage 2b
// of the backend, opt-in: CalibrationOptions::estimate_walk), for the walks not given.
//
// A multi-pose session shows how far the biases wander between its holds, but only through the
// fit: the still means differ by the walk *and* by the poses. Helmert's variance-component
// estimate (Förstner 1979; Koch, Parameter Estimation and Hypothesis Testing, 3.6) separates
// them. With the walk factors of one sensor as a group g of whitened residuals r_g, their
// redundancy is
//
//   red_g = sum_{i in g} (1 - h_ii),     h_ii = J_i C J_i^T,
//
// J the whitened Jacobian over every free unknown (model, attitudes, walk states) and C its
// (pseudo-)inverse normal matrix: the part of the group's residuals that the fit cannot absorb.
// At the right density, E[r_g^T r_g] = red_g, so each iteration scales K^2 by
// r_g^T r_g / red_g and fits again, until K changes by less than `tolerance`. The start is
// the level of stage 2a (wander_levels.h; the largest axis's); the result is floored at 1e-3
// of the typical MEMS walk (a walk too small to see leaves the factors stiff but finite).
//
// The estimate needs holds to compare: at least `walk_min_poses` still segments, else the
// level of stage 2a is kept and a warning says so. Densities given in the options (0
// included: no walk) are kept.
#pragma once

#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/still_set.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"

namespace plumb::estimation {

struct WalkEstimate {
  NoiseModel noise;        ///< the noise model with every wander level resolved
  int iterations = 0;      ///< fits made
  double redundancy_acc = 0, redundancy_gyr = 0;  ///< red_g of each sensor's walk factors
  std::vector<std::string> notes;     ///< what was done, in words
  std::vector<std::string> warnings;  ///< what was assumed for lack of data
  /// Non-empty when an estimated walk is implausibly large (the gate implausible_walk).
  std::string implausible;
};

/// Resolves the levels the options leave unset: iterates fits of the problem (stages 4-5)
/// from `theta` and the poses of `still`, scaling each free walk density (file comment).
/// `noise` gives the white noise and the levels given.
WalkEstimate ResolveWander(const ImuSeries& series, const model::Model& model,
                          const geo::Site& site, const StillSet& still,
                          const model::ParameterBlocks& theta, const NoiseModel& noise,
                          const StartingValues& start, const CalibrationOptions& options);

}  // namespace plumb::estimation

// plumb/estimation/fitted_problem.h — the backend (calibrator.cc) in two halves: stages 1-5,
// the problem at its solution, and stages 6-8 on it; sensitivity.h works on the same solution.
// INTERNAL to plumb::estimation (not installed): it holds Ceres's problem (calibration_problem.h,
// solve.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/core/session.h"
#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/result.h"
#include "plumb/estimation/solve.h"
#include "plumb/estimation/wander_levels.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"

namespace plumb::estimation {

struct FittedProblem {
  /// On the heap: the Ceres problems of `solution` point into its values.
  std::unique_ptr<CalibrationProblem> problem;
  Solution solution;
  NoiseModel noise;        ///< the noise the residuals are whitened with (stage 2)
  StartingValues start;    ///< stage 3
  std::string implausible_walk;  ///< the walk estimate's gate message, or ""
  WanderBounds wander_bounds;    ///< the still data's bounds on the wander levels (stage 2a)
};

/// Stages 1-5 of Calibrate (the still set, the noise model and the wander's levels, starting
/// values, the problem, the solve with its gauge); fills `result`'s method, site, model,
/// units, noise, notes and warnings. `board`: the board's other IMUs fitted with IMU 0
/// (`series`; board.h), which must outlive the problem; none: IMU 0 alone. `board_models`:
/// their models as CalibrateBoard takes them.
FittedProblem FitProblem(const ImuSeries& series, const std::vector<StillSegment>& segments,
                         const model::Model& model, const geo::Site& site,
                         const CalibrationOptions& options, CalibrationResult& result,
                         const std::vector<BoardImu>& board = {},
                         const std::vector<model::Model>& board_models = {});

/// Stages 6-8 of Calibrate on a fitted problem (FitProblem's, same arguments): the analysis,
/// parameters and covariance, the fit's residuals, advice and gates, into `result`.
void FinishCalibration(const ImuSeries& series, const std::vector<StillSegment>& segments,
                       const CalibrationOptions& options, FittedProblem& fitted,
                       CalibrationResult& result);

}  // namespace plumb::estimation

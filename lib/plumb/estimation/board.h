// plumb/estimation/board.h — stages 1-3 of the backend for the board's other IMUs (SPEC 6,
// "Several IMUs of one board"), before the problem (stage 4) takes them with IMU 0.
//
// For each IMU: its samples of IMU 0's poses and motion intervals (StillSetOnBoardImu), its
// noise model (EstimateNoise) with its wander's levels from its own still data
// (AssignWanderLevels), its model's starting values (Initialize, on its own samples), and
// where it starts in the body: R_b_i = R_n_b^T R_n_i, IMU 0's starting attitude of each pose
// against its own, averaged over the poses (the chordal mean: the rotation nearest the mean
// of their matrices). Its model is its own (calibrator.h, CalibrateBoard), or IMU 0's spec,
// without the gyroscope's terms when it has no gyroscope. After the fit (stage 6), ReportBoard
// gives their parameters and the one covariance over every IMU's.
#pragma once

#include <vector>

#include "plumb/core/session.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/fit_report.h"
#include "plumb/estimation/observability.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/problem_imu.h"
#include "plumb/estimation/still_set.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"

namespace plumb::estimation {

/// The board's other IMUs as the problem takes them, each with its model of `models` (one per
/// IMU, checked against its samples); notes on their wander levels go to `fit.notes`, prefixed
/// with the IMU. `board` must outlive the problem (its series).
std::vector<BoardImuInput> PrepareBoard(const std::vector<BoardImu>& board,
                                        const std::vector<model::Model>& models,
                                        const ImuSeries& series0, const StillSet& still0,
                                        const geo::Site& site, const CalibrationOptions& options,
                                        FitReport& fit);

/// Stage 6 for the board's other IMUs: each one's parameters with their sigmas (from
/// `analysis`, the fit with every unknown free, over `columns`) into calibration.board, and
/// the covariance over IMU 0's parameters (calibration.parameters, whose block is
/// calibration.covariance) and theirs into calibration.board_covariance; each one's turn
/// comparison's chi2 from `built` (the problem at the fit). Nothing without a board.
void ReportBoard(const CalibrationProblem& problem, const BuiltProblem& built,
                 const UnknownColumns& columns,
                 const ObservabilityAnalysis& analysis,
                 const std::vector<Eigen::Index>& column_of, Calibration& calibration);

}  // namespace plumb::estimation

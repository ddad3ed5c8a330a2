// plumb/estimation/board_turns.h — the turns as another IMU of the board and IMU 0 both sampled
// them: the windows of residuals/board_force_residual.h, and their weights.
//
// INTERNAL to plumb::estimation (not installed).
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/estimation/still_set.h"
#include "plumb/model/model.h"
#include "plumb/residuals/board_force_residual.h"

namespace plumb::estimation {

/// The length of a window, s. A hand's turn takes a second or more (a quarter turn in one or
/// two), and the edge values come from four windows' means exactly for a cubic motion, so a
/// window of a tenth of a second keeps the turn's centripetal and Euler accelerations while it
/// averages 10 to 100 samples at 100-1000 Hz; half that length doubles the residuals (and the
/// fit's cost) for the same information (NEES/dof of the three-IMU boards 1.03 either way,
/// tests/estimation/board_test.cc).
inline constexpr double kBoardWindow_s = 0.1;

/// The slowest rate at which a turn's windows are formed, Hz: two samples per window at least,
/// so that the windows' means resolve the turn (at telemetry's few hertz a hand's turn of a
/// second or two is a handful of samples, and the turn's rate between them is not known).
inline constexpr double kMinTurnRate_hz = 2.0 / kBoardWindow_s;

/// The windows of a turn: IMU 0's samples `turn0` of `series0` (its model `model0`) cut into
/// windows of the same number of samples, about kBoardWindow_s (the last few samples, short of
/// a window, left out), which tile the turn: their edges halfway between samples, the first
/// and last half a sample period out. Each has IMU 0's means and those of IMU i's samples of
/// the same turn (`turn` of `series`, `model`) stamped within its edges (none: count 0).
/// None where either IMU samples the turn slower than kMinTurnRate_hz. Weights: the identity
/// (WeighTurnWindows).
std::vector<residuals::BoardWindow> TurnWindows(const ImuSeries& series0,
                                                const MotionInterval& turn0,
                                                const model::Model& model0,
                                                const ImuSeries& series,
                                                const MotionInterval& turn,
                                                const model::Model& model);

/// The accelerometer's broadband scatter over samples [first, last] of each range, per sample
/// and axis, output units^2: the mean of its second differences squared over 6
/// (estimation/turn_noise.h says why); zero without a second difference.
Vec3 Scatter(const ImuSeries& series,
             const std::vector<std::pair<std::size_t, std::size_t>>& ranges);

/// One IMU's accelerometer noise in a turn, as its window means carry it.
struct TurnAccelNoise {
  Mat3 F_inv = Mat3::Identity();  ///< its model's linear stage, outputs to m/s^2
  /// Per sample and axis, output units^2: the white noise's sigma^2 tau, times the turn's
  /// scatter over the still poses' (Scatter): the vibration's share, measured where it happens.
  /// The ratio is unbiased where nothing shakes the turn, and cancels what a filter in the
  /// sensor does to both.
  Vec3 var_sample = Vec3::Zero();
  /// Per accelerometer wander process, per axis: the short-time walk K^2 (WanderProcess::
  /// ShortTimeWalk2), output units^2 / s.
  std::vector<Vec3> walk2;
  double duration_s = 0.0;  ///< the turn's, first to last sample
};

/// Sets each window's sqrt_info to L_w^-1, L_w L_w^T the covariance of its bracket
/// (residuals/board_force_residual.h): per IMU, the mean's white noise or scatter over its count
/// plus each wander process's bridge about its line at the window (K^2 T s (1 - s), s its
/// place along the turn), through F^-1, IMU i's then turned by R_b_i into the body.
void WeighTurnWindows(std::vector<residuals::BoardWindow>& windows, const TurnAccelNoise& imu0,
                      const TurnAccelNoise& imu, const Mat3& R_b_i);

}  // namespace plumb::estimation

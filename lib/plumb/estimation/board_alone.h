// plumb/estimation/board_alone.h — one IMU of a board fit (SPEC 6, "Several IMUs of one board")
// seen alone, in its own frame, for what takes one IMU at a time (the exports: each instance's
// firmware parameters, and the error they leave on that IMU's own still samples).
//
// IMU k's model maps its own samples: y_k = F_k R_b_k^T f_b + b_k (its frame, not the body's),
// so its firmware offsets and scales are its model's, as when it is calibrated alone; where it
// sits in the body (R_b_k, lever arm, time offset) is the board's, not the firmware's.
#pragma once

#include <cstddef>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"

namespace plumb::estimation {

/// Board IMU `k` (`calibration.board[k]`) as a calibration of its own: its model, blocks,
/// parameters (named as the board names them, "imu1.accel.bias.x") with their block of
/// board_covariance, its noise and units; IMU 0's method, site and observability (which name
/// every IMU's parameters); no board. Throws std::out_of_range for k beyond the board.
Calibration BoardImuAlone(const Calibration& calibration, std::size_t k);

/// IMU 0's still segments of the fit (`still`, over `series0`) as board IMU `series` samples
/// them (SegmentOnBoardImu), with that IMU's means and its attitude R_n_b R_b_i (`R_b_i`, the
/// IMU's frame into the body); segments it holds no sample of are left out.
std::vector<StillSegmentFit> StillFitsOnBoardImu(const std::vector<StillSegmentFit>& still,
                                                 const ImuSeries& series0,
                                                 const ImuSeries& series, const Quat& R_b_i);

}  // namespace plumb::estimation

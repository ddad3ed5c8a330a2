// plumb/peers/imu_tk.h — imu_tk's calibration files, its model in plumb's forward form, and
// its accelerometer cost for any forward calibration.
//
// imu_tk (Tedaldi, Pretto and Menegatti, ICRA 2014; github.com/Kyle-ak/imu_tk) writes one
// CalibratedTriad per sensor (include/imu_tk/calibration.h): a misalignment matrix T, a
// diagonal scale matrix K and a bias B, applied in the INVERSE direction,
//
//   calibrated = T K (raw - B),
//
// so plumb's forward form is raw = (T K)^-1 calibrated + B: F = (T K)^-1, b_a = B (and E, b_g
// the same way for the gyroscope). imu_tk's accelerometer T is upper triangular ("body frame
// = accelerometer frame"), so (T K)^-1 is upper triangular like plumb's F, in the same frame;
// its gyroscope T is full, relative to that frame, like plumb's E. imu_tk's calibrated
// accelerometer is in m/s^2 (its gravity magnitude) and its gyroscope in rad/s (it integrates
// it over time stamps in seconds); raw is what imu_tk was given (counts for its demo data).
//
// imu_tk's accelerometer cost (src/calibration.cpp, MultiPosAccResidual): one residual
//   r_i = g - |T K (x_i - B)|
// per sample x_i; the samples are the first 100 of every still interval longer than 100
// samples (interval_n_samples_ = 100, acc_use_means_ false in its demo), and Ceres' cost is
// 0.5 sum r_i^2. It tries threshold multipliers 2..10 for its still detector and keeps the
// lowest cost: on its demo data 0.120131 with multiplier 6 and 38 intervals, i.e. over 3800
// residuals that include the sensor noise of every sample.
#pragma once

#include <string>
#include <vector>

#include "plumb/core/types.h"
#include "plumb/peers/forward_calibration.h"

namespace plumb::peers {

/// imu_tk's demo settings and its printed answer on its own data (../shared/data/multipose/
/// imu_tk/test_imu_calib_stdout.txt).
inline constexpr double kImuTkDemoGravity = 9.81744;  ///< m/s^2, setGravityMagnitude
inline constexpr int kImuTkSamplesPerInterval = 100;  ///< samples per still interval in its cost
inline constexpr double kImuTkDemoCost = 0.120131;    ///< (m/s^2)^2, its lowest accel cost
inline constexpr int kImuTkDemoIntervals = 38;        ///< still intervals behind that cost

/// One imu_tk CalibratedTriad: calibrated = T K (raw - B).
struct ImuTkTriad {
  Mat3 T = Mat3::Identity();  ///< misalignment, ones on the diagonal, dimensionless
  Mat3 K = Mat3::Identity();  ///< diagonal scale, calibrated units per raw unit
  Vec3 B = Vec3::Zero();      ///< bias, raw units
};

/// Both of imu_tk's triads.
struct ImuTkCalibration {
  ImuTkTriad acc;
  ImuTkTriad gyro;
};

/// Reads an imu_tk `.calib` file (CalibratedTriad::save): T (3 rows of 3), a blank line, K
/// (3 rows of 3), a blank line, B (3 rows of 1) — 21 numbers separated by white space, as
/// imu_tk's load() reads them. Throws plumb::InputError naming the file and the line when a
/// token is not a number, the count is not 21, T has no unit diagonal or K is not diagonal
/// with positive entries.
ImuTkTriad ReadImuTkCalib(const std::string& path);

/// Reads full_precision_params.txt (the full-precision print of both triads): sections `ACC`
/// and `GYRO`, each with `T=` (9 numbers), `K=` (9), `B=` (3) and an optional `1/K=` (3,
/// checked against K). Same checks and errors as ReadImuTkCalib.
ImuTkCalibration ReadImuTkFullPrecision(const std::string& path);

/// imu_tk's answer in plumb's forward form: F = (T_a K_a)^-1, b_a = B_a, E = (T_g K_g)^-1,
/// b_g = B_g; `sources` names the files. Throws plumb::Error when T K is singular.
ForwardCalibration ImuTkToForward(const ImuTkCalibration& calibration,
                                  const std::vector<std::string>& sources);

/// imu_tk's accelerometer cost over a set of accelerometer outputs.
struct ImuTkCost {
  double cost = 0.0;      ///< 0.5 sum_k w_k r_k^2, (m/s^2)^2
  double rms_m_s2 = 0.0;  ///< sqrt(sum w_k r_k^2 / sum w_k), m/s^2
  double max_abs_m_s2 = 0.0;  ///< largest |r_k|, m/s^2
  int terms = 0;          ///< number of outputs y_k used
  double weight = 0.0;    ///< sum of the weights (= terms when unweighted)
};

/// imu_tk's cost of the forward calibration (F, b_a): r_k = g - |F^-1 (y_k - b_a)|,
/// cost = 0.5 sum_k w_k r_k^2. `y_a` are accelerometer outputs (samples, or still-segment
/// means) in output units; `weights` empty (all 1) or one >= 0 per output; `gravity_m_s2` > 0.
/// Throws plumb::Error when F is singular or the sizes differ.
ImuTkCost ImuTkAccelCost(const Mat3& accel_matrix, const Vec3& accel_bias,
                         const std::vector<Vec3>& y_a, double gravity_m_s2,
                         const std::vector<double>& weights = {});

/// One still segment as plumb's result gives it.
struct StillMean {
  Vec3 y_a = Vec3::Zero();  ///< mean accelerometer output, output units
  double count = 0.0;       ///< samples averaged, >= 0
};

/// The cost imu_tk would print on these segments, estimated from their means: each segment of
/// more than `samples_per_interval` samples contributes `samples_per_interval` residuals, whose
/// expected sum of squares is n (r_k^2 + s_k^2), r_k the residual of the mean and
/// s_k^2 = u_k^T F^-1 diag(noise^2) F^-T u_k the variance of one sample's calibrated norm
/// (u_k the unit calibrated vector). `noise_per_sample`: per-axis standard deviation of one
/// accelerometer sample, output units (plumb's noise.accel). In the result, `terms` is the
/// number of segments used, `weight` the number of residuals, `rms_m_s2` includes the noise
/// and `max_abs_m_s2` is the largest |r_k| of the means. Same errors as ImuTkAccelCost.
ImuTkCost ImuTkSampleCostEstimate(const Mat3& accel_matrix, const Vec3& accel_bias,
                                  const std::vector<StillMean>& segments,
                                  const Vec3& noise_per_sample, double gravity_m_s2,
                                  int samples_per_interval = kImuTkSamplesPerInterval);

}  // namespace plumb::peers

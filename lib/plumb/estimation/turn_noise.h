// plumb/estimation/turn_noise.h — what the velocity residual of a turn carries besides the
// sensors' white noise: the vibration of the turn, measured from its own samples.
//
// The velocity residual (residuals/velocity_residual.h) sums h dR_i f_i over a turn. A turn made
// by hand shakes the IMU: knocks, grip changes, the board set down. Sampled at a hundred hertz
// or so, that vibration's content above the Nyquist frequency folds into the samples as a
// broadband scatter whose sum is not the integral of the true specific force. It is measured
// where it happens, from the accelerometer's second differences
//
//   d_i = y_i+1 - 2 y_i + y_i-1,     E[d_i d_i^T] = 6 Sigma_i   for a broadband scatter Sigma_i,
//
// which a hand's motion, smooth over three samples, leaves near zero (h^2 y'' is ~1e-3 of the
// sample at 100 Hz). Per axis a of the body frame at the turn's start (dR_i rotates sample i
// into it):
//
//   var_a = max( white:    sigma_f,a^2 tau_a h^2 n,
//                measured: h^2 sum_i (dR_i F^-1 d_i)_a^2 / 6 )
//         + across_a g^2 sigma_w^2 tau_g h^4 n^3 / 3,         across_a = 1 - down_a^2,
//
// the last the gyroscope's white noise integrated into an attitude random walk that tilts
// gravity (only across it). The white noise is inside the measured scatter too, so a quiet turn
// keeps the white-noise variance.
//
// Evidence, on the real hand-held sessions (base+time_offset; velocity chi^2 per residual with
// the white noise alone -> with the measured scatter): mikoff imu0 35 -> 0.73, imu1 46 -> 0.84,
// imu2 36 -> 1.8; ChanghyeonKim93 (uniform clock) 29 -> 0.63 and 33 -> 0.85; imu_tk 6.4 -> 1.2.
// The fourth differences (70 Sigma_i, blind to motion cubic over five samples) give the same
// scatter as the second to within 5 % on mikoff imu0: it is broadband, not the motion.
// The gyroscope's second differences are left out: they carry the turn's own smooth rate
// (its fourth differences give half the variance), and the rotation residuals of the same
// turns sit at their white noise (chi^2 per residual 0.4-0.7), so the attitude the turns
// integrate is good to that noise.
#pragma once

#include <vector>

#include "plumb/core/types.h"
#include "plumb/residuals/measurements.h"

namespace plumb::estimation {

/// The sensors' white noise per sample, in the corrected frame (what CalibrationProblem weights
/// the turns with when nothing shakes them), and whether the turn's vibration counts.
struct TurnNoise {
  Mat3 cov_f = Mat3::Zero();  ///< specific force per sample, (m/s^2)^2, F^-1 Sigma_a F^-T
  Vec3 tau_acc = Vec3::Ones();  ///< correlation factor of the accelerometer's white noise
  double var_rate = 0.0;        ///< angular rate per sample per axis (mean), (rad/s)^2, x tau_g
  /// Whether the turn's measured vibration counts (CalibrationOptions::turn_vibration).
  bool measure_vibration = true;
};

/// The velocity residual's variance per axis of the body frame at the turn's start, m^2/s^2:
/// the white noise's or the measured vibration's, whichever is larger, for the accelerometer
/// and for the attitude through gravity (the wander and quantisation terms are added by the
/// caller). `down_b` is gravity's direction in that frame (unit), `g` its size, m/s^2; E_inv and
/// F_inv map sensor outputs to rad/s and m/s^2 (the model's linear stage).
Vec3 TurnVelocityVariance(const residuals::MotionSamples& samples, const Mat3& E_inv,
                          const Mat3& F_inv, const TurnNoise& noise, const Vec3& down_b,
                          double g);

}  // namespace plumb::estimation

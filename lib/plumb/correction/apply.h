// plumb/correction/apply.h — a calibration applied to samples: the true specific force and
// angular rate that produced each measured output, through the inverse of every effect of the
// model (model::Model::Correct: Newton iterations on the forward model from its linear
// inverse), with the uncertainty the calibration's covariance puts on them.
//
//   f_b, omega_b = Correct(theta; y_a, y_g, t - t_ref, T - T_ref, alpha_b)
//
// Frames and units: body FRD; f_b m/s^2, omega_b rad/s (SI whatever units the samples were in:
// the calibration maps SI to them). alpha_b, the angular acceleration lever-arm effects need,
// is E^-1 d y_g / dt by central differences of the outputs (one-sided at the ends), as the
// backend takes it. The Earth-rate term is physics, not a sensor error: its attitude is unknown
// for arbitrary samples, so it is left in omega_b (the rate with respect to inertial space).
//
// Uncertainty (optional): per sample, per axis, sqrt(diag(J C J^T)) with C the calibration's
// covariance and J = d(f_b, omega_b) / d(parameters) by central differences of Correct, each
// parameter stepped by 1e-3 of its sigma. It is the calibration's share only; the sensor's own
// noise in each sample is not in it.
#pragma once

#include <vector>

#include "plumb/core/error.h"
#include "plumb/core/imu_series.h"
#include "plumb/core/types.h"
#include "plumb/correction/calibration_file.h"

namespace plumb::correction {

struct ApplyOptions {
  /// Propagate the covariance to every sample (costs two corrections per parameter and sample).
  bool uncertainty = false;
  /// Newton steps of the inverse after the linear inverse (>= 0; 2 reach double precision for
  /// the catalogue's effects at their typical sizes).
  int newton_steps = 2;
};

struct CorrectedSeries {
  std::vector<Vec3> f_b;      ///< per sample, m/s^2
  std::vector<Vec3> omega_b;  ///< per sample, rad/s (empty without a gyroscope)
  /// With ApplyOptions::uncertainty: per sample and axis, the calibration's standard deviation.
  std::vector<Vec3> f_sigma, omega_sigma;
};

/// The correction of a sample is not finite (ApplyCalibration): its message names the sample
/// by index and time, not the file the samples came from (the caller's to add).
class NonFiniteCorrection : public Error {
 public:
  using Error::Error;
};

/// Applies `calibration` to every sample of `series`. Throws plumb::Error naming the file when
/// the series does not fit the calibration: a gyroscope model without gyroscope samples, a
/// temperature effect without temperatures, samples in other units than the calibration's;
/// and throws NonFiniteCorrection for the first sample (index and time) whose correction is
/// not finite (a value no sensor gives, 1e308): never a NaN or an infinity in the result.
CorrectedSeries ApplyCalibration(const CalibrationFile& calibration, const ImuSeries& series,
                                 const ApplyOptions& options = {});

}  // namespace plumb::correction

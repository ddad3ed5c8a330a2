// plumb/diagnostics/residual_analysis.h — compare the fitted model with the measurements
// (SPEC section 5, first bullet): predicted against measured per segment and per sample, the
// worst segments and time ranges, the residual against the regressors of the catalogue's
// signatures, and the residual's Allan deviation against the white-noise line.
//
// Predictions use the fit's model and parameters (model::Model::Predict) with the inputs the
// backend uses on a still segment (plumb/residuals/still_residuals.cc):
//   f_b = R_b_n (-g_n),  omega_b = R_b_n omega_ie_n + known rate,  alpha_b = 0,
//   dt_s = t - t_ref,  dtemp_c = T - T_ref (0 without temperature),  R_b_n = R_n_b^T,
// per segment at the mean time and mean temperature, per sample at the sample's own.
// Residuals are measured minus predicted. A segment turning at a known rate has no
// accelerometer residual (its specific force turns), as in the fit.
//
// Example:
//   CalibrationResult fit = estimation::Calibrate(series, segments, model, site);
//   ResidualAnalysis a = AnalyseResiduals(series, fit);
//   for (const auto& s : a.signatures) if (s.significant) ...;  // what the model is missing
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/types.h"
#include "plumb/estimation/result.h"

namespace plumb::diagnostics {

struct ResidualAnalysisOptions {
  /// Keep every stride-th still sample in ResidualAnalysis::samples (plots, CSV), >= 1. The
  /// worst stretches and the Allan deviation always use every sample.
  std::size_t sample_stride = 1;
  /// Family-wise level of the signature tests, in (0, 0.5): a signature is significant when
  /// its two-sided p-value is below significance / (number of tests) (Bonferroni).
  double significance = 0.01;
  /// Fewest segments or intervals for a signature test, >= 4 (the Fisher z needs n - 3 > 0).
  int min_points = 6;
  /// How many worst time ranges to name, >= 1.
  std::size_t worst_count = 5;
  /// Length of the stretches that still segments of at least twice this are cut into for
  /// the worst stretches, s, > 0.
  double stretch_s = 10.0;
  /// Allan deviation: the still segments pooled are those with at least this fraction of
  /// the longest one's samples, in (0, 1].
  double allan_length_fraction = 0.5;
  /// Allan deviation: the largest cluster leaves at least this many clusters in the shortest
  /// pooled segment (m <= n / allan_min_clusters), >= 2.
  int allan_min_clusters = 8;
  /// Allan deviation: cluster sizes per decade of tau, [1, 100].
  int allan_points_per_decade = 5;
};

/// Predicted against measured on one still segment (entries of fit.still, same order).
struct SegmentComparison {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::size_t index = 0;    ///< index in fit.still
  std::string label;        ///< the segment's label
  double t_begin_s = kNaN;  ///< time of the first sample, s (series time)
  double t_end_s = kNaN;    ///< time of the last sample, s
  double t_mid_s = kNaN;    ///< mean sample time, s
  double temp_c = kNaN;     ///< mean temperature, degC; NaN without temperature
  bool has_acc = false;     ///< accelerometer residual exists (not turning at a known rate)
  bool has_gyr = false;     ///< still gyroscope residual exists (gyroscope fitted on stills)
  Vec3 f_b = Vec3::Zero();      ///< specific force of the fitted attitude, body, m/s^2
  Vec3 omega_b = Vec3::Zero();  ///< true rate of the fit (Earth rate + known rate), rad/s
  /// Measured mean, predicted mean, residual (measured - predicted), all in the series'
  /// accelerometer unit; whitened residual from the fit, dimensionless (~N(0, 1) per axis
  /// when the model is complete). Zero when !has_acc.
  Vec3 acc_measured = Vec3::Zero(), acc_predicted = Vec3::Zero();
  Vec3 acc_residual = Vec3::Zero(), acc_whitened = Vec3::Zero();
  /// The same for the gyroscope, series' gyroscope unit. Zero when !has_gyr.
  Vec3 gyr_measured = Vec3::Zero(), gyr_predicted = Vec3::Zero();
  Vec3 gyr_residual = Vec3::Zero(), gyr_whitened = Vec3::Zero();
  /// |(acc_whitened, gyr_whitened)| over the residuals that exist, >= 0.
  double whitened_norm = 0.0;
};

/// One motion interval of the fit (entries of fit.motion, same order), rotations as rotation
/// vectors in the body frame of the segment before, rad. With R_k the fitted attitudes and dR
/// the integrated corrected gyroscope, the fit's residual is r = Log(dR^T R_k^T R_k+1).
struct MotionComparison {
  std::size_t index = 0;          ///< index in fit.motion
  std::size_t from = 0, to = 0;   ///< still segments (indices in fit.still)
  double t_begin_s = 0.0;         ///< last sample of segment `from`, s
  double t_end_s = 0.0;           ///< first sample of segment `to`, s
  Vec3 rotation_attitudes = Vec3::Zero();  ///< Log(R_k^T R_k+1), rad
  Vec3 rotation_gyro = Vec3::Zero();       ///< Log(dR) = Log(R_k^T R_k+1 Exp(-r)), rad
  Vec3 residual = Vec3::Zero();            ///< r, rad
  Vec3 whitened = Vec3::Zero();            ///< r whitened by the fit, dimensionless
  double whitened_norm = 0.0;              ///< |whitened|, >= 0
  /// Regressors, from the raw gyroscope corrected by the fit's linear part E^-1 (y_g - b_g):
  double mean_rate = 0.0;        ///< mean |omega_b| over the interval, rad/s
  double mean_rate2 = 0.0;       ///< mean |omega_b|^2, rad^2/s^2
  double max_angular_acc = 0.0;  ///< max |d omega_b / dt| (central differences), rad/s^2
};

/// Per-sample residuals on the still samples (every options.sample_stride-th of each
/// segment), as a structure of arrays: entry i of every vector is one sample. Measured values
/// are series.acc / series.gyr at `sample`.
struct SampleResiduals {
  std::vector<std::size_t> sample;   ///< index in the series
  std::vector<std::size_t> segment;  ///< index in fit.still
  std::vector<double> t_s;           ///< sample time, s
  /// Predicted output and residual (measured - predicted), series' units; NaN where the
  /// residual does not exist (see SegmentComparison::has_acc, has_gyr).
  std::vector<Vec3> acc_predicted, acc_residual;
  std::vector<Vec3> gyr_predicted, gyr_residual;
  /// Residual divided by the fit's per-sample noise (fit.noise_acc, fit.noise_gyr), per axis.
  std::vector<Vec3> acc_normalised, gyr_normalised;
  std::size_t size() const { return sample.size(); }
};

/// Which residual: still accelerometer, still gyroscope, or motion (rotation).
enum class ResidualKind { kStillAccel, kStillGyro, kMotion };
/// "accel", "gyro" or "motion".
const char* ResidualKindName(ResidualKind kind);

/// A time range with a large residual: a still segment, a motion interval, or a stretch of a
/// long still segment. Its score is its largest whitened component (~N(0, 1) when the model
/// is complete); for a stretch of n samples, z = sum(residual) / (sqrt(n) sigma_white) with
/// the residual's white level from ResidualAllan (the fit's noise sqrt(tau) where there is
/// none): a slow effect that inflates the fit's correlation time still shows.
struct WorstRange {
  enum class Kind { kStill, kMotion, kStretch };
  Kind kind = Kind::kStill;
  std::size_t index = 0;      ///< fit.still index (kStill, kStretch) or fit.motion (kMotion)
  double t_begin_s = 0.0, t_end_s = 0.0;  ///< the range, s (series time)
  std::string name;           ///< e.g. "still 'x up' 12.0-17.0 s", "motion 3->4 17.0-19.0 s"
  ResidualKind residual = ResidualKind::kStillAccel;  ///< the largest component's residual
  int axis = 0;               ///< and its axis, 0..2
  double score = 0.0;         ///< |largest whitened component|, >= 0
};

/// The residual against one regressor over the still segments or the motion intervals. Test:
/// Pearson correlation r of the whitened residual with the regressor over n points, Fisher
/// z = atanh(r) sqrt(n - 3) ~ N(0, 1) under "no relation", two-sided p-value; significant when
/// p < options.significance / num_tests (Bonferroni over all tests of the analysis).
struct Signature {
  ResidualKind residual = ResidualKind::kStillAccel;
  int axis = 0;              ///< residual axis, 0..2
  /// "time" (mid-segment, since the first sample), "temperature" (segment mean), "f_b.x",
  /// "f_b.x^2" (fitted attitude), "|omega|", "|omega|^2" (still: the fit's true rate; motion:
  /// MotionComparison's means), "max |alpha|" (motion)
  std::string regressor;
  std::string unit;          ///< the regressor's unit: "s", "degC", "m/s^2", ...
  int points = 0;            ///< n, segments or intervals used
  double correlation = 0.0;  ///< r, [-1, 1]
  double slope = 0.0;        ///< least-squares slope of the whitened residual, per regressor unit
  double slope_sigma = 0.0;  ///< its standard error, same unit
  /// Least-squares slope of the unwhitened residual (series' unit, or rad for motion) per
  /// regressor unit, and its standard error: the size of the effect.
  double slope_residual = 0.0, slope_residual_sigma = 0.0;
  double p_value = 1.0;      ///< two-sided, [0, 1]
  bool significant = false;
};

/// Allan deviation of one axis of the per-sample still residual, beside the white-noise line.
struct ResidualAllan {
  ResidualKind residual = ResidualKind::kStillAccel;  ///< kStillAccel or kStillGyro
  int axis = 0;
  std::vector<double> tau_s;  ///< cluster times, s
  std::vector<double> adev;   ///< Allan deviation of the residual (AVAR pooled over the
                              ///< segments, weighted by their terms), series' unit
  /// The white-noise line sigma_white / sqrt(m), series' unit. It is anchored on the residual
  /// itself, sigma_white = adev sqrt(m) at the reference cluster (the middle of the
  /// log-spaced sizes, about sqrt(m_max)): beyond the sensor's filter, below where slow
  /// effects build up. Not on the fit's noise, whose correlation time a slow effect inflates.
  std::vector<double> white;
  double sigma_white = 0.0;      ///< series' unit (per sample), >= 0
  double reference_tau_s = 0.0;  ///< cluster time of the anchor, s
  /// The fit's per-sample noise times sqrt(its correlation time), series' unit: the white
  /// level its whitening assumes. Far above sigma_white: the fit's noise has absorbed a slow
  /// effect (and its chi^2 understates the misfit).
  double fit_sigma = 0.0;
  /// adev / white at the largest cluster: ~1 when only white noise is left, well above 1
  /// when a slow effect (drift, random walk, temperature) is left in the residual.
  double ratio = 0.0;
};

struct ResidualAnalysis {
  std::vector<SegmentComparison> still;  ///< per fit.still entry, time order
  std::vector<std::size_t> still_rank;   ///< indices into `still`, worst whitened_norm first
  std::vector<MotionComparison> motion;  ///< per fit.motion entry
  std::vector<std::size_t> motion_rank;  ///< indices into `motion`, worst first
  SampleResiduals samples;
  /// The options.worst_count largest ranges over segments, intervals and stretches, worst first.
  std::vector<WorstRange> worst;
  /// Every test performed (a regressor that does not vary is skipped), and their number.
  std::vector<Signature> signatures;
  int num_tests = 0;
  double p_threshold = 0.0;  ///< significance / num_tests
  /// Allan deviation per sensor and axis (empty when no segment is long enough), over the
  /// still segments in allan_segments (indices in fit.still).
  std::vector<ResidualAllan> allan;
  std::vector<std::size_t> allan_segments;
};

/// Compares `fit` (a result of estimation::Calibrate on `series`) with the measurements.
/// Throws plumb::Error if an option is out of range, a segment of the fit lies outside the
/// series, or the fit has a gyroscope and the series none.
ResidualAnalysis AnalyseResiduals(const ImuSeries& series, const estimation::CalibrationResult& fit,
                                  const ResidualAnalysisOptions& options = {});

}  // namespace plumb::diagnostics

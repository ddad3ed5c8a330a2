// plumb/estimation/calibration.h — what a calibration *is* (SPEC sections 1-3 and 6): the
// model, its named parameters with values, sigmas and full covariance, what the data could
// not determine, the site and the sensor noise. How the fit that produced it went (segments,
// residuals, chi^2, warnings) is in fit_report.h; CalibrationResult (result.h) holds both.
//
// Exporters, peers and the Python module depend on this type only.
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "plumb/core/types.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"

namespace plumb::estimation {

/// One scalar model parameter as reported.
struct ParameterEstimate {
  std::string name;   ///< e.g. "accel.bias.x", "gyro_g_sensitivity.G.xy" (for display)
  /// Where it lives in the model (Calibration::model): what it is is asked of the model
  /// (model::Model::Role, SensorOf), not read from `name`.
  model::ParameterPlace place;
  std::string unit;   ///< e.g. "m/s^2"
  double value = 0;   ///< reported value (nominal + block value), SI
  /// One standard deviation; NaN when not observable or held fixed.
  double sigma = std::numeric_limits<double>::quiet_NaN();
  bool observable = true;  ///< false: the data cannot determine it (see Observability)
  bool fixed = false;      ///< held at its value by the model or method
};

/// A linear combination of parameters, as text, with its value and sigma.
struct Combination {
  std::string text;  ///< e.g. "accel.bias.z - 9.78 accel.matrix.zz"
  double value = 0;
  double sigma = 0;
  /// For a weakly determined combination: its typical spread among MEMS IMUs (sigma exceeds
  /// it; estimation/observability.h kWeakSpread); 0 otherwise.
  double typical = 0;
  /// The combination as numbers: sum_i coefficients[i] * value of parameter names[i].
  std::vector<std::string> names;
  std::vector<double> coefficients;
};

struct Observability {
  /// Numerical rank of the column-scaled whitened Jacobian, less the weakly determined
  /// combinations held (observability.h kWeakSpread).
  int rank = 0;
  int num_unknowns = 0;    ///< free tangent-space unknowns (model parameters and attitudes)
  /// Bias-wander states besides them (always determined: each has its Markov factor), which
  /// the degrees of freedom also subtract.
  int wander_states = 0;
  /// Null-space directions, each "a p1 + b p2 ...": moving the parameters along it changes
  /// no prediction.
  std::vector<std::string> unobservable;
  /// The same directions as numbers: one row per entry of `unobservable` (reduced row-echelon
  /// form, original units), one column per unknown named in `null_space_names` (the model's
  /// free parameters, the attitudes, the eliminated unknowns); 0 rows when all is observable.
  Eigen::MatrixXd null_space;
  std::vector<std::string> null_space_names;
  /// Combinations the data determine no better than their typical spread among MEMS IMUs,
  /// held at their start values in the fit (value: there; sigma: the data's; typical: the
  /// spread). Their parameters are not reported as determined.
  std::vector<Combination> weakly_determined;
  /// Combinations of unobservable parameters that the data does determine.
  std::vector<Combination> determined;
  /// Their covariance, c_i^T C c_j, in `determined` order (its diagonal: their sigma squared).
  Eigen::MatrixXd determined_covariance;
  /// Smallest kept and largest dropped relative singular values (diagnostics).
  double smallest_kept = 0, largest_dropped = 0;
};

/// Where a level of the bias wander came from (estimation/wander_levels.h), per sensor,
/// process and axis.
enum class LevelSource {
  kNone,       ///< no such process in the fit (a constant bias, or a level given as 0)
  kGiven,      ///< given in the options (CalibrationOptions::accel_walk_density, ...)
  kMeasured,   ///< resolved by the Allan deviation of still data
  kBounded,    ///< not resolved; the Allan deviation's upper bound, below the typical level
  kTypical,    ///< the typical MEMS level (core/typical_mems.h), within the data's bound
  kEstimated,  ///< estimated over the fit by variance components (walk_estimate.h)
};
/// "none", "given", "allan", "allan_bound", "typical", "estimated" (the JSON's words).
const char* LevelSourceName(LevelSource source);

/// The sources of the four wander processes' levels, per axis.
struct WanderSources {
  std::array<LevelSource, 3> walk_acc{}, walk_gyr{}, instability_acc{}, instability_gyr{};
};

/// The sensor noise the fit was whitened with, measured on the session's still segments.
struct NoiseLevels {
  Vec3 acc = Vec3::Zero();  ///< accelerometer noise per sample, sensor units
  Vec3 gyr = Vec3::Zero();  ///< gyroscope noise per sample, sensor units
  /// Integrated autocorrelation times used (the largest over the axes), samples (>= 1).
  double tau_acc = 1, tau_gyr = 1;
  /// Bias random-walk densities the fit assumed per axis, sensor units / s / sqrt(Hz);
  /// zero: the bias was held constant over the session.
  Vec3 walk_acc = Vec3::Zero();
  Vec3 walk_gyr = Vec3::Zero();
  /// Bias instability the fit assumed (Gauss-Markov sigma per axis, sensor units; zero:
  /// none) and its correlation time, s.
  Vec3 instability_acc = Vec3::Zero();
  Vec3 instability_gyr = Vec3::Zero();
  double instability_time_s = 0;
  WanderSources from;  ///< where each wander level came from
  /// Quantisation (IEEE Q) per axis the fit assumed, sensor units x s (0: none).
  Vec3 quantisation_acc = Vec3::Zero();
  Vec3 quantisation_gyr = Vec3::Zero();
};

/// Another IMU of the board as calibrated with IMU 0 (SPEC 6, "Several IMUs of one board"):
/// its model and parameters, and where it sits in the body (model/board_mount.h).
struct BoardImuCalibration {
  int instance = 1;  ///< its number on the board
  model::Model model;
  /// Its model's blocks, then its board_mount block (7 values): one per term of `model`, and
  /// one more.
  model::ParameterBlocks theta;
  /// Its model's parameters in model order, then its mount's seven (rotation.x..z, lever_arm.x..z,
  /// time_offset); named as the fit names them ("imu1.accel.bias.x", "imu1.rotation.x"), each
  /// with `place` in `theta` (the mount's term: model.num_terms()).
  std::vector<ParameterEstimate> parameters;
  NoiseLevels noise;
  bool has_gyro = false;
  std::string acc_unit = "m/s^2";
  std::string gyr_unit = "rad/s";
  /// Its turns' comparison with IMU 0 at the fit (residuals/board_force_residual.h): chi2, the
  /// sum of the squared whitened residuals, over `turn_residuals` values (0: no turn compared,
  /// and its lever arm and time offset held).
  double turn_chi2 = 0.0;
  int turn_residuals = 0;

  /// R_b_i, its frame into the body frame (IMU 0's accelerometer's).
  Quat R_b_i() const;
  /// Its mount's parameter `index` (model/board_mount.h's layout: rotation.x..z, lever_arm.x..z,
  /// time_offset), among `parameters` (their last seven).
  const ParameterEstimate& MountParameter(int index) const;
  /// Whether the fit determined its rotation into the body: each rotation parameter observable,
  /// with a finite sigma.
  bool RotationDetermined() const;
  /// Its lever arm from IMU 0, m, body frame, and its time offset, s (held at zero: no residual
  /// of the fit sees them yet).
  Vec3 LeverArm() const;
  double TimeOffset() const;
  /// F, b_a, E, b_g of its own base effects, as Calibration's.
  Mat3 AccelMatrix() const;
  Vec3 AccelBias() const;
  Mat3 GyroMatrix() const;
  Vec3 GyroBias() const;
};

struct Calibration {
  /// Label of the method ("generalized", or a paper method run on the backend).
  std::string method = "generalized";
  model::Model model;
  model::ParameterBlocks theta;  ///< solved parameter blocks, one per model term
  /// Every parameter of the model, in model order (model::Model::ParameterNames()).
  std::vector<ParameterEstimate> parameters;
  /// Covariance of the reported parameters, in `parameters` order (SI units squared). Rows
  /// and columns of fixed parameters are zero; for unobservable ones it is the pseudo-inverse
  /// (minimum-norm) value and is meaningless on its own: use `observability.determined`.
  Eigen::MatrixXd covariance;
  /// Where the covariance came from: "ceres::Covariance (DENSE_SVD)" or "pseudo-inverse".
  std::string sigma_source;
  Observability observability;
  geo::Site site;
  NoiseLevels noise;
  bool has_gyro = false;
  std::string acc_unit = "m/s^2";  ///< units of the accelerometer samples (see ImuSeries)
  std::string gyr_unit = "rad/s";
  /// The board's other IMUs fitted with this one (empty: IMU 0 alone).
  std::vector<BoardImuCalibration> board;
  /// With a board: one covariance over `parameters` then every board IMU's, in that order (SI
  /// units squared; zero rows for fixed parameters and for unobservable ones, whose
  /// pseudo-inverse values mean nothing: `observability.determined` says what the data fix
  /// of them); empty without one.
  Eigen::MatrixXd board_covariance;

  /// The forward quantities of SPEC section 1, from the base effects' blocks: F (sensor units
  /// per m/s^2), b_a (sensor units), E (sensor units per rad/s), b_g (sensor units). Without a
  /// gyroscope E = I and b_g = 0.
  Mat3 AccelMatrix() const;
  Vec3 AccelBias() const;
  Mat3 GyroMatrix() const;
  Vec3 GyroBias() const;
};

}  // namespace plumb::estimation

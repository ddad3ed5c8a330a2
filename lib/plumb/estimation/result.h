// plumb/estimation/result.h — what one solve of the backend reports (SPEC sections 3 and 6).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/segment.h"
#include "plumb/core/types.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"

namespace plumb::estimation {

/// One scalar model parameter as reported.
struct ParameterEstimate {
  std::string name;   ///< e.g. "accel.bias.x", "gyro_g_sensitivity.G.xy"
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
};

struct Observability {
  int rank = 0;            ///< numerical rank of the column-scaled whitened Jacobian
  int num_unknowns = 0;    ///< free tangent-space unknowns (model parameters and attitudes)
  /// Null-space directions, each "a p1 + b p2 ...": moving the parameters along it changes
  /// no prediction.
  std::vector<std::string> unobservable;
  /// Combinations of unobservable parameters that the data does determine.
  std::vector<Combination> determined;
  /// Smallest kept and largest dropped relative singular values (diagnostics).
  double smallest_kept = 0, largest_dropped = 0;
};

/// Residuals of one still segment, unwhitened (sensor units) and whitened.
struct StillSegmentFit {
  StillSegment segment;
  double t_mid_s = 0;
  std::size_t count = 0;             ///< samples in the segment
  Vec3 acc_mean = Vec3::Zero();      ///< measured mean output, sensor units
  Vec3 gyr_mean = Vec3::Zero();
  Vec3 acc_residual = Vec3::Zero();  ///< measured minus predicted mean, sensor units
  Vec3 gyr_residual = Vec3::Zero();
  Vec3 acc_whitened = Vec3::Zero();
  Vec3 gyr_whitened = Vec3::Zero();
  Quat R_n_b = Quat::Identity();     ///< estimated (or known) attitude
  bool attitude_known = false;
};

/// Residual of one motion interval, rad (unwhitened) and whitened.
struct MotionFit {
  std::size_t from = 0, to = 0;  ///< still segment indices
  double duration_s = 0;
  Vec3 rotation_residual = Vec3::Zero();
  Vec3 whitened = Vec3::Zero();
  bool has_velocity = false;              ///< a velocity residual was fitted
  Vec3 velocity_residual = Vec3::Zero();  ///< velocity change over the interval, m/s
  Vec3 velocity_whitened = Vec3::Zero();
};

struct FitSummary {
  double chi2 = 0;   ///< sum of squared whitened residuals
  int num_residuals = 0;
  int dof = 0;       ///< residuals minus rank
  double chi2_dof() const { return dof > 0 ? chi2 / dof : std::numeric_limits<double>::quiet_NaN(); }
  Vec3 rms_acc = Vec3::Zero();  ///< RMS of still accelerometer residuals per axis, sensor units
  Vec3 rms_gyr = Vec3::Zero();  ///< RMS of still gyroscope residuals per axis, sensor units
  Vec3 rms_motion = Vec3::Zero();  ///< RMS of motion rotation residuals per axis, rad
  Vec3 rms_velocity = Vec3::Zero();  ///< RMS of motion velocity residuals per axis, m/s
  int still_segments = 0;
  int motion_segments = 0;
  int velocity_segments = 0;  ///< motion intervals with a velocity residual (accel in motion)
  int iterations = 0;
  bool converged = false;
  std::string solver_report;  ///< ceres::Solver::Summary::BriefReport()
};

/// The whitened problem at the optimum with the columns of the model's probe terms
/// (model::Model::AddProbe), for the score test of plumb/diagnostics. Rows are the whitened
/// residuals in the order still segment 0 (accelerometer, gyroscope), segment 1, ..., then the
/// motion intervals; each row is labelled.
struct ProbeJacobian {
  Eigen::VectorXd r;  ///< whitened residuals (measured minus predicted), dimensionless
  Eigen::MatrixXd J;  ///< d r / d(free unknowns: model parameters, then attitude tangents)
  Eigen::MatrixXd Z;  ///< d r / d(probe parameters) at zero
  std::vector<std::string> unknown_names;  ///< J's columns
  std::vector<bool> unknown_is_model;      ///< J's columns: model parameter (else attitude)
  std::vector<std::string> probe_names;    ///< Z's columns, e.g. "gyro_g_sensitivity.G.xy"
  std::vector<int> probe_term;             ///< Z's columns: index of the term in the model
  enum class RowKind { kStillAccel, kStillGyro, kMotion, kVelocity };
  std::vector<RowKind> row_kind;  ///< per row
  std::vector<int> row_index;     ///< per row: still segment or motion interval index
  std::vector<int> row_axis;      ///< per row: 0, 1, 2
};

struct CalibrationResult {
  std::string method = "generalized";
  model::Model model;
  model::ParameterBlocks theta;          ///< solved parameter blocks
  std::vector<ParameterEstimate> parameters;
  /// Covariance of the reported parameters, in `parameters` order (SI units squared). Rows
  /// and columns of fixed parameters are zero; for unobservable ones it is the pseudo-inverse
  /// (minimum-norm) value and is meaningless on its own: use `determined` combinations.
  Eigen::MatrixXd covariance;
  /// Where the covariance came from: "ceres::Covariance (DENSE_SVD)" or "pseudo-inverse".
  std::string sigma_source;
  /// The forward quantities of SPEC section 1, SI.
  Mat3 accel_matrix = Mat3::Identity();
  Vec3 accel_bias = Vec3::Zero();
  Mat3 gyro_matrix = Mat3::Identity();
  Vec3 gyro_bias = Vec3::Zero();
  bool has_gyro = false;
  std::string acc_unit = "m/s^2";  ///< units of the accelerometer samples (see ImuSeries)
  std::string gyr_unit = "rad/s";
  FitSummary fit;
  Observability observability;
  geo::Site site;
  std::vector<StillSegmentFit> still;
  std::vector<MotionFit> motion;
  Vec3 noise_acc = Vec3::Zero();  ///< per-sample noise used for whitening, sensor units
  Vec3 noise_gyr = Vec3::Zero();
  double tau_acc = 1, tau_gyr = 1;  ///< integrated autocorrelation times used, samples
  std::vector<std::string> warnings;
  /// Present when the model has probe terms.
  std::optional<ProbeJacobian> probes;

  /// A few lines: model, chi^2/dof, rank, convergence.
  std::string BriefReport() const;
  /// The parameter table with sigmas and the observability section, for a terminal.
  std::string FullReport() const;
};

}  // namespace plumb::estimation

// plumb/estimation/fit_report.h — how a fit went (SPEC sections 3 and 6): chi^2 and degrees of
// freedom, convergence, the residuals of every still segment and motion interval, warnings,
// and (for diagnose) the probe columns. What the calibration is lives in calibration.h.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/log_motion.h"
#include "plumb/core/notice.h"
#include "plumb/core/option_name.h"
#include "plumb/core/segment.h"
#include "plumb/core/types.h"

namespace plumb::estimation {

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
  /// With a bias random walk: the walk's mean over the segment, (s_k + e_k) / 2, sensor
  /// units (the bias over the segment is the model's plus this); zero without.
  Vec3 acc_walk = Vec3::Zero();
  Vec3 gyr_walk = Vec3::Zero();
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

/// Motion between two still segments that the fit leaves out, not a turn: longer than
/// CalibrationOptions::max_motion_s (estimation/still_set.h).
/// A stretch of time with no sample: from t_s (the last sample before it), length_s long.
struct SampleGap {
  double t_s = 0.0;
  double length_s = 0.0;
};

struct NotATurn {
  std::size_t from = 0, to = 0;  ///< still segment indices
  double t_begin_s = 0.0, t_end_s = 0.0;
  double limit_s = 0.0;          ///< the longest motion the fit integrates
  /// What the log says the vehicle did in it, when that is why it is left out (else its
  /// length, beyond limit_s).
  std::optional<LogMotion> flown;
  /// The longest gap in its samples, when that is why it is left out (longer than
  /// gap_limit_s, CalibrationOptions::max_turn_gap_s).
  std::optional<SampleGap> gap;
  double gap_limit_s = 0.0;
};

/// The whitened problem at the optimum with the columns of the model's probe terms
/// (model::Model::AddProbe), for the score test of plumb/diagnostics. Rows are the whitened
/// residuals in the order still segment 0 (accelerometer, gyroscope), segment 1, ..., then the
/// motion intervals; each row is labelled.
struct ProbeJacobian {
  Eigen::VectorXd r;  ///< whitened residuals (measured minus predicted), dimensionless
  /// d r / d(free unknowns: model parameters, then attitude tangents, then from first_wander
  /// the bias-wander states); sparse (elimination.h's JacobianRange factorises it)
  Eigen::SparseMatrix<double> J;
  std::size_t first_wander = 0;
  Eigen::MatrixXd Z;  ///< d r / d(probe parameters) at zero
  std::vector<std::string> unknown_names;  ///< J's columns
  std::vector<bool> unknown_is_model;      ///< J's columns: model parameter (else attitude)
  std::vector<std::string> probe_names;    ///< Z's columns, e.g. "gyro_g_sensitivity.G.xy"
  std::vector<int> probe_term;             ///< Z's columns: index of the term in the model
  enum class RowKind { kStillAccel, kStillGyro, kMotion, kVelocity, kBiasWalk };
  std::vector<RowKind> row_kind;  ///< per row
  std::vector<int> row_index;     ///< per row: still segment or motion interval index
  std::vector<int> row_axis;      ///< per row: 0, 1, 2
};

/// A check the fit failed (estimation/gates.h, SPEC section 3 "Gates"): a fit that did not
/// converge, a rank from segments of one pose, samples outside the sensor's range, a rate or
/// unit the data contradict, a saturated axis. `name` is one of kGateNames (gates.h).
struct Gate {
  std::string name;     ///< its stable code (gates.h lists them), e.g. "not_converged"
  std::string message;  ///< what failed, in numbers, and what to do
  /// The options the message points the user to (through OptionText), in its order: data for
  /// a front end that acts on them instead of reading the message (not in the JSON).
  std::vector<Option> options = {};
};

/// Whether chi^2 is as quadratic in the unknowns as the covariance assumes, a few sigma out
/// from the solution (estimation/linearity.h).
struct LinearityReport {
  bool checked = false;      ///< false: not run (options.check_linearity) or nothing to check
  double step_sigmas = 0;    ///< the step c, in sigma of the direction
  /// Per direction checked (the loosest of the parameters' correlation matrix, linearity.h,
  /// in the order of its eigenvalues, increasing): the larger of chi^2(+c d) - chi^2 and
  /// chi^2(-c d) - chi^2, over c^2 (1 for a linear model).
  std::vector<double> ratio;
  double worst_ratio = 0;       ///< the largest of `ratio`
  std::string worst_direction;  ///< its direction: the largest terms, in sigma of each parameter
};

struct FitReport {
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
  /// Solver iterations (steps) over every solve of the fit (a rough and a refined one, a
  /// second with null directions held); each solve is limited to
  /// CalibrationOptions::max_iterations.
  int iterations = 0;
  int solves = 0;                 ///< solves made
  int last_solve_iterations = 0;  ///< iterations of the last solve (solver_report's count)
  bool converged = false;
  std::string solver_report;  ///< ceres::Solver::Summary::BriefReport() of the last solve

  std::vector<StillSegmentFit> still;  ///< per still segment used, in time order
  std::vector<MotionFit> motion;       ///< per motion interval integrated
  std::vector<NotATurn> not_turns;     ///< motion between poses left out of the fit
  std::vector<Notice> warnings;        ///< what the user must know (codes: core/notice.h)
  std::vector<Notice> notes;           ///< how the fit was made (e.g. the noise; codes: notice.h)
  /// Checks the fit failed (empty: all passed); a failed gate means the numbers above are
  /// not to be trusted as they stand (estimation/gates.h).
  std::vector<Gate> gates;
  /// Distinct poses among the still segments at rest: consecutive segments with the same
  /// gravity direction and no turn between them count once (estimation/gates.h).
  int distinct_poses = 0;
  /// How quadratic chi^2 is around the solution (the nonlinear gate).
  LinearityReport linearity;
  /// Present when the model has probe terms.
  std::optional<ProbeJacobian> probes;
};

}  // namespace plumb::estimation

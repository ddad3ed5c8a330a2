// plumb/estimation/options.h — how the one backend (SPEC section 3) is configured.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "plumb/core/jobs.h"
#include "plumb/core/log_motion.h"
#include "plumb/core/typical_mems.h"
#include "plumb/signal/noise_terms.h"

namespace plumb::estimation {

/// What to do when the data cannot determine every parameter of the requested model.
enum class InsufficientData {
  kReport,  ///< fit anyway; report the unobservable directions and what to record (default)
  kError,   ///< throw plumb::InsufficientDataError saying what to record
};

struct CalibrationOptions {
  /// Label of the method in outputs ("generalized", or a paper method run on the backend).
  std::string method = "generalized";
  /// Runs independent jobs at once (core/jobs.h): here the motion residuals of each of
  /// Ceres's evaluation passes (parallel_evaluation.h). Empty: one after another. The fit is
  /// the same bit for bit either way.
  JobRunner run_jobs;
  /// Integrate the gyroscope between consecutive still segments (motion residuals).
  bool use_motion = true;
  /// Motion intervals longer than this are not integrated, s (> 0): the attitude before and
  /// after are then treated as unrelated and each chain gets its own heading gauge.
  double max_motion_s = 120.0;
  /// Motion intervals whose samples stop for longer than this, s (> 0), are not integrated
  /// either: the integration holds the last rate across a gap, and a hand's turn changes its
  /// rate within tenths of a second, so over a longer gap the turn the samples miss (a dropout
  /// of the link or the logger) would enter the fit as a misfit of degrees.
  double max_turn_gap_s = 0.5;
  /// Where the log says the vehicle flew or moved (Session::log_motion, core/log_motion.h), on
  /// the samples' clock: a motion interval one covers (LogMotion::Covers: more than its edges)
  /// is no turn and is left out like one longer than max_motion_s; a still segment one covers
  /// fails the not_still gate. Empty: the input says nothing of it.
  std::vector<LogMotion> log_motion;
  /// Heading of the first still segment's x axis from north, degrees, if the user states it
  /// (e.g. 0 for "x points north"); otherwise the heading gauge is held at its initial value.
  std::optional<double> first_heading_deg;
  /// Still residuals of the gyroscope (the Earth-rate constraint) are used when true.
  bool use_still_gyro = true;
  /// Velocity residuals over the motion intervals (residuals/velocity_residual.h: the
  /// accelerometer while the IMU turns, at rest at both ends). Unset: used when the model has
  /// an effect that needs them (lever arms, time offset: EffectInfo::excitation.
  /// angular_acceleration); set, forced on or off (e.g. to compare two models on the same
  /// residuals).
  std::optional<bool> accel_in_motion;
  /// The velocity residuals weighted by the vibration measured in each turn where it exceeds
  /// the white noise (estimation/turn_noise.h; true), or by the white noise alone (false: to
  /// see what the vibration does; on turns made by hand it understates their sigma).
  bool turn_vibration = true;
  /// Relative singular-value threshold of the column-scaled whitened Jacobian below which a
  /// direction counts as unobservable (0 < value < 1).
  double rank_tolerance = 1e-9;
  /// Minimum samples for a still segment to be used (>= 1).
  int min_segment_samples = 10;
  /// Bias random-walk densities K (IEEE Std 952 rate / acceleration random walk) of the
  /// accelerometer and the gyroscope, sensor units / s / sqrt(Hz) (m/s^3/sqrt(Hz) and
  /// rad/s^2/sqrt(Hz) for SI samples), >= 0 and finite. Set and > 0: the bias is not one
  /// constant over the session but walks, and the backend gives every still segment bias-walk
  /// states tied by random-walk factors (residuals/bias_walk_residual.h); the model's bias is
  /// then the bias at the model's reference time. 0: no walk. Unset: wander_levels.h.
  /// A wandering bias (walk and instability states per segment) is the default; it costs
  /// about 6 unknowns per segment and sensor, eliminated before the analysis (solve.h).
  std::optional<double> accel_walk_density;
  std::optional<double> gyro_walk_density;
  /// Bias instability as a first-order Gauss-Markov process per axis: steady-state sigma
  /// (accelerometer m/s^2, gyroscope rad/s, sensor units for unscaled samples; finite >= 0;
  /// 0: none; unset: wander_levels.h)
  /// and correlation time (s, finite > 0). Every still segment then also has instability
  /// states at both ends, tied by Gauss-Markov factors (residuals/bias_walk_residual.h).
  std::optional<double> accel_instability;
  std::optional<double> gyro_instability;
  double instability_time_s = typical_mems::kInstabilityTime_s;
  /// Estimate the wander levels (walk and instability) that are not given from the session
  /// itself, by variance-component estimation over the wander factors, marginalised over the
  /// estimate's scatter (estimation/walk_estimate.h), when it has walk_min_poses still poses
  /// (else the levels of wander_levels.h, said in the warnings). Off by default: the
  /// differences between holds that the estimate reads as wander also carry whatever effect
  /// the model misses (a session with a hidden g-sensitivity read as "consistent with the
  /// noise" with it on), so the default is the level from still data alone (wander_levels.h)
  /// and a misfit stays visible.
  bool estimate_walk = false;
  /// One constant bias over the session: no walk, no instability, whatever the fields above
  /// say. Honest only for white noise (the report says so); for comparisons and peers' methods.
  bool constant_bias = false;
  /// Whether the bias wanders in the fit: always, unless constant_bias. Levels not given come
  /// from the still data's Allan deviation or the typical sensor (wander_levels.h), or the
  /// walk estimate, said in the notes.
  bool ModelsWander() const { return !constant_bias; }
  /// Other still recordings of the same sensor, analysed (signal::AnalyseStillNoise), whose
  /// Allan deviation informs the wander levels not given, beside the session's own still
  /// segments (wander_levels.h); e.g. a long still recording that resolves the walk.
  std::vector<signal::StillNoise> other_still_noise;
  /// Fewest still segments for the walk estimate (>= 2); with fewer the typical walk is used.
  int walk_min_poses = 6;
  /// Lower bound on the noise standard deviation per sample, in sensor units, guarding
  /// against quantised data whose scatter reads zero (finite, > 0).
  double min_sigma_acc = 1e-6;
  double min_sigma_gyr = 1e-8;
  /// Solver limits: iterations per solve (>= 1) and Ceres's relative tolerances of the final
  /// solves, each in (0, 1).
  int max_iterations = 200;
  double function_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
  InsufficientData on_insufficient = InsufficientData::kReport;
  /// Covariance by ceres::Covariance (DENSE_SVD) on the problem with the null directions'
  /// pivots held (default), or by the pseudo-inverse of the column-scaled Jacobian. Both give
  /// the same sigma for every observable parameter and determined combination (tested).
  bool use_ceres_covariance = true;
  /// Check that chi^2 is as quadratic as the covariance assumes, 2 sigma out along the
  /// loosest directions of the parameters' correlation (estimation/linearity.h; the nonlinear
  /// gate).
  /// Costs two evaluations of the residuals per direction checked; off for fits whose
  /// covariance nobody reads (diagnose's candidate scores).
  bool check_linearity = true;

  /// Throws plumb::Error naming the first field out of its documented range (the calibration
  /// runs it first).
  void Validate() const;
};

}  // namespace plumb::estimation

// The options of a generalized fit that `calibrate` and `report` share (--model, --strict,
// --heading, --level-north, --temp-ref, --max-iterations), the steps both take from a session
// to the calibration's inputs (segments, site, model and options) and to the calibration, and
// what a failed gate (estimation/gates.h) does under --strict.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/segment.h"
#include "plumb/core/session.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/result.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"
#include "plumb/pipeline/fit_setup.h"
#include "plumb/segmentation/still_detector.h"
#include "input_options.h"
#include "site_options.h"

namespace plumb::cli {

struct FitArgs {
  std::string model = "base";      ///< --model SPEC
  /// --imu-model K=SPEC (repeatable): board IMU K's own model (K as its parameters are named,
  /// imuK.), the others --model's.
  std::vector<std::string> imu_models;
  bool strict = false;             ///< --strict: fail when the data cannot determine the model
                                   ///< (exit 1) or the fit fails a gate (exit 3)
  double heading_deg = 0.0;        ///< --heading: first still pose's x axis from north, degrees
  CLI::Option* heading = nullptr;  ///< set when --heading was given
  bool level_north = false;        ///< --level-north: first still pose level, x north (known)
  double temp_ref_c = 25.0;        ///< --temp-ref: reference of the temperature terms, degC
  /// The options the flags set directly, as the fit takes them: --max-iterations
  /// (max_iterations, >= 1) and the bias wander: --accel-rw / --gyro-rw (accel_walk_density,
  /// gyro_walk_density: bias random-walk densities, sensor units / s / sqrt(Hz), >= 0),
  /// --estimate-rw (estimate_walk), --constant-bias (constant_bias), --accel-bi / --gyro-bi
  /// (accel_instability, gyro_instability: Gauss-Markov sigma, sensor units, >= 0) and
  /// --bi-time (instability_time_s, s).
  estimation::CalibrationOptions options;
  /// --noise-from FILE: a still recording of the same sensor whose Allan deviation informs
  /// the wander levels not given (estimation/wander_levels.h).
  std::string noise_from;
};

/// The exit code of a failed gate under --strict (SPEC section 8).
inline constexpr int kExitGateFailed = 3;

/// Registers --model on `app`, and --imu-model for commands that fit the board (`board`).
void AddModelOption(CLI::App* app, FitArgs& args, bool board = false);

/// Registers --imu-model on `app`.
void AddImuModelOption(CLI::App* app, FitArgs& args);

/// The model `spec` given to `option` (--model, --baseline); a spec that names no model (an
/// unknown effect, a repeated one, no base) is a usage error naming the option (exit 2).
model::Model ParseModelOption(const std::string& option, const std::string& spec);

/// Registers --strict, --heading, --level-north, --temp-ref, --max-iterations, the bias
/// wander (--accel-rw, --gyro-rw, --estimate-rw, --accel-bi, --gyro-bi, --bi-time,
/// --noise-from, --constant-bias) on `app`.
void AddFitOptions(CLI::App* app, FitArgs& args);

/// Everything Calibrate() takes besides the samples (plumb/pipeline/fit_setup.h).
using pipeline::FitSetup;

/// The flags as a pipeline::FitRequest, and the fit's inputs for `session` and its
/// segmentation (pipeline::PrepareFit); adds to session.warnings when --gravity overrides
/// WGS84 gravity at a known site. With --noise-from, reads that still
/// recording with `input`'s options and analyses its noise (signal::AnalyseStillNoise);
/// throws plumb::Error naming the file when it has no still stretch long enough.
FitSetup PrepareFit(Session& session, const segmentation::SegmentationResult& segmentation,
                    const SiteArgs& site_args, const FitArgs& fit, const InputArgs& input);

/// "<source>: N samples, T s[, no gyroscope][, with temperature]" and the session's warnings.
void PrintSession(const Session& session);

/// Each of `warnings` as "warning: ..." on standard error (SPEC 6: warnings go to stderr).
void PrintWarnings(const std::vector<Notice>& warnings);

/// The files a fit reads besides its calibration: INPUT..., --acc/--gyr, --segments and
/// --noise-from, into `roles`' inputs (file_roles.h).
void AddFitInputFiles(const InputArgs& input, const std::string& segments_path,
                      const FitArgs& fit, FileRoles& roles);

/// pipeline::CalibrateSession (its error also lists the samples' gates), after saying the
/// stage on the progress line.
estimation::CalibrationResult CalibrateWithProgress(const Session& session, const FitSetup& fit);

/// "the fit of SOURCE failed N gates (names)": for errors and refusals.
using pipeline::GateFailure;

/// With --strict and a failed gate: prints "plumb: error: ..." on stderr and returns
/// kExitGateFailed (the caller returns it before writing anything); otherwise 0.
int StrictGateExit(const estimation::FitReport& fit, const std::string& source, bool strict);

}  // namespace plumb::cli

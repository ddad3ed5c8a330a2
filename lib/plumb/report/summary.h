// plumb/report/summary.h — what `plumb calibrate` prints on a terminal (the library formats,
// only the command prints).
//
// SegmentationSummary: how many still segments, how they were found, the thresholds and the
// noise they came from. CalibrationSummary: a two-line header (version, method, model, and a
// verdict on chi^2/dof against its spread) followed by FullReport() (calibration_text.h).
#pragma once

#include <string>

#include "plumb/estimation/result.h"
#include "plumb/report/calibration_text.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb::report {

/// A few lines on the still segments; `source` names the segments file for given segments
/// (may be empty). `with_notes` appends the detector's own notes (long: every rejected run).
std::string SegmentationSummary(const segmentation::SegmentationResult& segmentation,
                                const std::string& source = "", bool with_notes = false);

/// One line judging chi^2/dof: consistent with the noise when within 3 standard deviations of
/// 1 (the standard deviation of chi^2/dof is sqrt(2 / dof)), otherwise what it suggests. When
/// the fit failed a gate (FitReport::gates) it says so instead, naming them: never "consistent
/// with the noise" then.
std::string FitVerdict(const estimation::FitReport& fit);

/// "failed a gate (nonlinear)" or "failed 2 gates (one_pose, nonlinear)": the gates `fit`
/// failed, as every verdict names them; "" when it failed none.
std::string FailedGatesText(const estimation::FitReport& fit);

/// One line per failed gate: "gate failed: NAME: [SOURCE: ]MESSAGE" (empty when all passed).
std::string GateLines(const estimation::FitReport& fit, const std::string& source = "");

/// Header (with the verdict and the failed gates, naming `source`, the input, when given)
/// plus the full report of the result and its notes; its warnings (result.fit.warnings) are
/// not in it: a command prints them on standard error.
std::string CalibrationSummary(const estimation::CalibrationResult& result,
                               const std::string& source = "");

/// Two fits of the same data side by side, `before` (the user's fit, e.g. base) and `after`
/// (e.g. base+gyro_g_sensitivity): chi^2, dof, chi^2/dof, per-axis RMS of the still
/// accelerometer, still gyroscope, motion and velocity residuals, and the parameters that
/// `after` adds, with sigma. When `after` holds velocity residuals that `before` does not, its
/// chi^2 is not a fall but over other residuals, and it says so; when chi^2/dof rose, it says
/// the refit is not advised.
std::string BeforeAfterSummary(const estimation::CalibrationResult& before,
                               const estimation::CalibrationResult& after);

}  // namespace plumb::report

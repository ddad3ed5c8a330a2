// plumb/pipeline/fit_setup.h — the steps every front end (the plumb command, the Python module)
// takes from a session to a calibration: the still segments (a segments file, or the still
// detector), the fit's inputs (segments, site, model and options) and the fit itself, whose
// failure names the samples' gates. The front ends turn their flags or keywords into the
// requests below; everything after that is here, once.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/core/segment.h"
#include "plumb/core/session.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/result.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb::pipeline {

/// How the still segments of a session are found.
struct SegmentRequest {
  /// A segments file (io/text/segments_file.h: CSV of times or sample indices, or imucal's
  /// JSON) whose segments are used instead of detecting them; "" = detect.
  std::string segments_path;
  /// Detect from the accelerometer alone (the detector's use_gyro off).
  bool still_accel_only = false;
  /// The detector's options; its use_gyro and units are set from still_accel_only and the
  /// series.
  segmentation::StillDetectorOptions detector;
};

/// The still segments of `series`: read from request.segments_path, or detected.
segmentation::SegmentationResult FindSegments(const ImuSeries& series,
                                              const SegmentRequest& request);

/// What a generalized fit takes besides the samples and their segments, as a front end was
/// given it.
struct FitRequest {
  /// The model, parsed by the front end (which names its option in a parse error); PrepareFit
  /// sets its time reference to the first sample and its temperature reference to temp_ref_c.
  model::Model model;
  /// Models of the board's other IMUs of their own (SPEC 6), by the instance their parameters
  /// are named for ("imu2.accel.bias.x": 2); the others take `model`.
  std::map<int, model::Model> imu_models;
  /// Reference temperature of the temperature terms, degC.
  double temp_ref_c = 25.0;
  /// The first still pose is level with x north, its attitude known and held.
  bool level_north = false;
  /// The user's site (source "flags"); when absent, the log's GPS, else no site.
  std::optional<SiteInput> site;
  /// A fixed gravity magnitude instead of WGS84 normal gravity, m/s^2.
  std::optional<double> gravity_m_s2;
  /// The fit's options as given (heading, strictness, iteration limit, bias wander, other
  /// still recordings' noise); passed on unchanged.
  estimation::CalibrationOptions options;
};

/// Everything estimation::Calibrate takes besides the samples.
struct FitSetup {
  std::vector<StillSegment> segments;  ///< the segments, the first known level x north with
                                       ///< FitRequest::level_north
  geo::Site site;                      ///< the request's, else the log's GPS, else none
  model::Model model;                  ///< the request's, time and temperature references set
  /// One per Session::other_imus: FitRequest::imu_models's, else `model`; empty when the
  /// request gave none (estimation::CalibrateBoard's board_models).
  std::vector<model::Model> board_models;
  estimation::CalibrationOptions options;  ///< the request's
  /// The session's warnings, and the note that a fixed gravity overrides WGS84 gravity at a
  /// known site (a calibration document's input warnings).
  std::vector<Notice> input_warnings;
};

/// The fit's inputs for `session` and its segmentation, from `request`. Throws plumb::Error
/// when request.imu_models names an instance the session's board has not.
FitSetup PrepareFit(const Session& session, const segmentation::SegmentationResult& segmentation,
                    FitRequest request);

/// estimation::CalibrateBoard on the session (IMU 0 with Session::other_imus, the board's IMUs
/// the input was asked for; none: estimation::Calibrate) with `fit`. When it throws
/// plumb::Error, the error also lists the samples' gates (estimation::CheckSamples: samples out
/// of range, a saturated axis), often the reason, as "gate failed: NAME: SOURCE: MESSAGE" lines.
estimation::CalibrationResult CalibrateSession(const Session& session, const FitSetup& fit);

/// "the fit of SOURCE failed a gate (name)" / "... failed N gates (names)": for errors and
/// refusals when a fit fails its gates (estimation/gates.h).
std::string GateFailure(const estimation::FitReport& fit, const std::string& source);

}  // namespace plumb::pipeline

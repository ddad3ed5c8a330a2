// plumb/estimation/calibrator.h — the one least-squares backend (SPEC section 3).
//
// Unknowns: the model's parameter blocks and one attitude R_k per still segment (on SO(3),
// held constant where known). Residuals: still accelerometer and gyroscope on segment
// statistics, motion residuals integrating the gyroscope between consecutive segments.
// Gauge: the heading of the first segment of every motion-joined chain is held (TiltManifold),
// at the stated heading if the options give one. Noise levels come from the data: the pooled
// within-segment scatter per axis and its integrated autocorrelation time.
//
// Example:
//   auto site = geo::Site::At(51.64, -1.2, 100, "flags");
//   auto model = model::Model::Parse("base");
//   CalibrationResult r = Calibrate(session.series, segments, model, site, {});
//   std::cout << report::FullReport(r);   // plumb/report/calibration_text.h
#pragma once

#include <vector>

#include "plumb/core/session.h"

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/result.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"

namespace plumb::estimation {

/// Fits `model` to the still segments of `series` (and the motion between them). Throws
/// plumb::InsufficientDataError when there is nothing to fit (no usable still segment, an
/// effect whose data is absent) or, with InsufficientData::kError, when the data cannot
/// determine every parameter; the message says what to record.
CalibrationResult Calibrate(const ImuSeries& series, const std::vector<StillSegment>& segments,
                            const model::Model& model, const geo::Site& site,
                            const CalibrationOptions& options = {});

/// The same with the board's other IMUs in the one fit (SPEC 6, "Several IMUs of one board";
/// Session::other_imus): their still attitudes shared with `series` (IMU 0, whose segments
/// these are), each IMU with its error model and its rotation into the body; they are reported
/// in Calibration::board with one covariance over every IMU (Calibration::board_covariance).
/// Each IMU's model is its own of `board_models` (one per IMU of `board`, in order), or, with
/// none given, `model`; without the gyroscope's terms when it has none. Throws plumb::Error
/// when `board_models` is neither empty nor one per IMU.
CalibrationResult CalibrateBoard(const ImuSeries& series, const std::vector<BoardImu>& board,
                                 const std::vector<StillSegment>& segments,
                                 const model::Model& model, const geo::Site& site,
                                 const CalibrationOptions& options = {},
                                 const std::vector<model::Model>& board_models = {});

}  // namespace plumb::estimation

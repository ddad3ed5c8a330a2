// apps/plumb/segment_options.h — how a command finds the still segments: --segments FILE, or
// the still detector with its options (shared by calibrate and diagnose).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "plumb/core/imu_series.h"
#include "plumb/pipeline/fit_setup.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb::cli {

/// --segments FILE (given segments instead of detection), --still-accel-only and the
/// detector's options (--init-still, --window, --min-still, --false-alarm) as the library's
/// request, and -v.
struct SegmentArgs : pipeline::SegmentRequest {
  bool verbose = false;  ///< print the still detector's notes
};

/// Registers --segments, the "Still detection" option group and -v/--verbose.
void AddSegmentOptions(CLI::App* app, SegmentArgs& args);

/// The still segments of `series`: read from --segments, or detected (pipeline::FindSegments,
/// the stage said on the progress line).
segmentation::SegmentationResult FindSegments(const ImuSeries& series, const SegmentArgs& args);

}  // namespace plumb::cli

// apps/plumb/segment_options.h — how a command finds the still segments: --segments FILE, or
// the still detector with its options (shared by calibrate and diagnose).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "plumb/core/imu_series.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb::cli {

struct SegmentArgs {
  std::string segments_path;      ///< --segments FILE: given segments instead of detection
  bool still_accel_only = false;  ///< detect still segments from the accelerometer alone
  bool verbose = false;           ///< print the still detector's notes
  segmentation::StillDetectorOptions detector;
};

/// Registers --segments, the "Still detection" option group and -v/--verbose.
void AddSegmentOptions(CLI::App* app, SegmentArgs& args);

/// The still segments of `series`: read from --segments, or detected.
segmentation::SegmentationResult FindSegments(const ImuSeries& series, const SegmentArgs& args);

}  // namespace plumb::cli

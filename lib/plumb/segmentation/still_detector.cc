// plumb/segmentation/still_detector.cc — DetectStillSegments (see still_detector.h): checks
// the options and the series, then runs the steps in order: the noise (still_noise.cc), the
// window tests (still_runs.cc), the join of runs of one pose (join_same_pose.cc), the trim and
// length filter, and the notes (still_notes.cc).
#include "plumb/segmentation/still_detector.h"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/segmentation/block_moments.h"
#include "plumb/segmentation/still_detector_internal.h"

namespace plumb::segmentation {
namespace {

void CheckOptions(const StillDetectorOptions& o) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw Error("still detector option " + what);
  };
  require(std::isfinite(o.init_still_s) && o.init_still_s >= 0.0,
          "init_still_s = " + Number(o.init_still_s) + " s must be >= 0 (0 = auto)");
  require(std::isfinite(o.window_s) && o.window_s > 0.0,
          "window_s = " + Number(o.window_s) + " s must be > 0");
  require(o.false_alarm > 0.0 && o.false_alarm < 0.5,
          "false_alarm = " + std::to_string(o.false_alarm) + " must be in (0, 0.5)");
  require(std::isfinite(o.min_still_s) && o.min_still_s >= 0.0,
          "min_still_s = " + Number(o.min_still_s) + " s must be >= 0");
  require(std::isfinite(o.edge_s) && o.edge_s >= 0.0,
          "edge_s = " + Number(o.edge_s) + " s must be >= 0");
  require(!std::isnan(o.rate_allowance),
          "rate_allowance must be a number (negative = automatic)");
}

void CheckSeries(const ImuSeries& series) {
  const std::size_t n = series.size();
  if (n == 0) {
    throw InsufficientDataError("still detection: the series is empty; record the IMU still in "
                                "several orientations");
  }
  if (series.acc.size() != n || (series.has_gyro() && series.gyr.size() != n)) {
    throw Error("still detection: inconsistent series: " + std::to_string(n) + " times, " +
                std::to_string(series.acc.size()) + " accelerometer and " +
                std::to_string(series.gyr.size()) + " gyroscope samples");
  }
}

}  // namespace

SegmentationResult DetectStillSegments(const ImuSeries& series,
                                       const StillDetectorOptions& options) {
  using namespace detail;  // the steps, still_detector_internal.h
  CheckOptions(options);
  CheckSeries(series);
  const double dt_s = series.median_dt_s();
  if (!(dt_s > 0.0)) {
    throw InsufficientDataError("still detection: the series has " +
                                std::to_string(series.size()) +
                                " samples without a positive sample interval");
  }
  const Geometry geometry = MakeGeometry(options.window_s, dt_s);
  if (series.size() < geometry.window()) {
    throw InsufficientDataError(
        "still detection: the series has " + std::to_string(series.size()) + " samples (" +
        FormattedText("%.3g", series.duration_s()) + " s), fewer than one " +
        std::to_string(geometry.window()) + "-sample window of " +
        FormattedText("%.3g", options.window_s) + " s; record longer still periods");
  }
  const bool use_gyro = options.use_gyro && series.has_gyro();
  const BlockMoments blocks(series, geometry.block, use_gyro);

  SegmentationResult result;
  SegmentationReport& report = result.report;
  report.method = "detected";
  report.window_s = static_cast<double>(geometry.window()) * dt_s;
  report.min_still_s = options.min_still_s;

  // 1. Noise of a still period.
  result.noise = options.init_still_s > 0.0
                     ? InitialNoise(series, blocks, options, geometry, report)
                     : AutomaticNoise(series, blocks, options, geometry, dt_s, report);
  const NoiseEstimate& noise = result.noise;
  report.init_still_s = static_cast<double>(noise.samples) * dt_s;
  report.notes.push_back(NoiseNote(noise, options));
  if (!use_gyro) {
    report.notes.push_back(series.has_gyro()
                               ? "gyroscope not tested (use_gyro off)"
                               : "no gyroscope: accelerometer test only; a slow turn about the "
                                 "vertical cannot be seen");
  }

  // 2. The window tests over the whole series.
  DetectionDetail& detail = result.detail;
  const WindowTests tests = MakeTests(noise, blocks, options, geometry, detail);
  const Classification found = Classify(series, blocks, tests);
  report.threshold = detail.acc_threshold;
  detail.windows = found.windows;
  detail.failed_acc = found.failed_acc;
  detail.failed_gyr = found.failed_gyr;
  detail.failed_rate = found.failed_rate;
  detail.failed_gap = found.failed_gap;
  detail.failed_nonfinite = found.failed_nonfinite;
  detail.still_runs = found.runs.size();
  report.notes.push_back(ThresholdNote(detail, options, dt_s));
  report.notes.push_back(FailureNote(found, tests));
  if (blocks.nonfinite_samples() > 0) {
    report.notes.push_back(std::to_string(blocks.nonfinite_samples()) +
                           " samples hold NaN or infinite values; no window over them is "
                           "called still");
  }

  // 3. Still runs: runs showing the same pose joined, trimmed, then kept when long enough.
  std::size_t joined = 0;
  const std::vector<Run> runs = JoinSamePose(series, blocks, found.runs, noise, options, dt_s,
                                             0.5 * options.window_s, joined);
  if (joined > 0) {
    report.notes.push_back(
        "joined " + std::to_string(joined) + " pairs of still runs: the samples between them "
        "vibrate but hold the same pose (accelerometer means agree, no rotation)");
  }
  double still_s = 0.0;
  for (const Run& run : runs) {
    const Run trimmed = Trim(series, run, options.edge_s);
    const double length_s = static_cast<double>(trimmed.size()) * dt_s;
    if (trimmed.size() == 0 || length_s < options.min_still_s) {
      ++report.rejected_short;
      continue;
    }
    StillSegment segment;
    segment.begin = trimmed.begin;
    segment.end = trimmed.end;
    segment.label = "still #" + std::to_string(result.segments.size() + 1);
    result.segments.push_back(std::move(segment));
    still_s += length_s;
  }
  report.notes.push_back(
      "found " + std::to_string(result.segments.size()) + " still segments totalling " +
      FormattedText("%.1f", still_s) + " s of " + FormattedText("%.1f", series.duration_s() + dt_s) + " s; " +
      std::to_string(report.rejected_short) + " still runs shorter than " +
      FormattedText("%.3g", options.min_still_s) + " s after trimming " + FormattedText("%.3g", options.edge_s) +
      " s at each end dropped");
  if (use_gyro) NoteGyroRejections(series, found, options, dt_s, result);
  if (options.init_still_s > 0.0) NoteInitialCoverage(found, noise, report);
  return result;
}

}  // namespace plumb::segmentation

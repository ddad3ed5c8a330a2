// plumb/segmentation/still_notes.cc — the report of the still detector (still_detector.h):
// the notes on the noise, the thresholds, the windows that failed each test, the runs only the
// gyroscope rejected and the initial period's coverage, and the number formatting they share.
#include <algorithm>
#include <cstdio>
#include <string>

#include "plumb/segmentation/still_detector_internal.h"

namespace plumb::segmentation::detail {
namespace {

/// How many gyro-rejected runs the notes list by time.
constexpr std::size_t kListedRuns = 12;

/// Whether any segment overlaps the run.
bool Overlaps(const std::vector<StillSegment>& segments, Run run) {
  for (const StillSegment& segment : segments) {
    if (segment.begin < run.end && run.begin < segment.end) return true;
  }
  return false;
}

}  // namespace

std::string FormatVec(const Vec3& v, const char* format) {
  return "(" + FormattedText(format, v.x()) + ", " + FormattedText(format, v.y()) + ", " + FormattedText(format, v.z()) +
         ")";
}

std::string TimeRange(const ImuSeries& series, Run run) {
  // Log times, as `plumb info` shows them, so a stretch named here can be found in the log.
  return FormattedText("%.2f", series.t_s[run.begin]) + "-" + FormattedText("%.2f", series.t_s[run.end - 1]) +
         " s";
}

std::string NoiseNote(const NoiseEstimate& noise, const StillDetectorOptions& options) {
  std::string note = "accel noise sigma " + FormatVec(noise.acc_sigma) + " " + options.acc_unit +
                     ", tau_int " + FormatVec(noise.acc_tau_int, "%.2f") + " samples";
  if (noise.has_gyro) {
    note += "; gyro noise sigma " + FormatVec(noise.gyr_sigma) + " " + options.gyr_unit +
            ", tau_int " + FormatVec(noise.gyr_tau_int, "%.2f") + " samples, still rate " +
            FormatVec(noise.gyr_still_rate, "%.6g") + " " + options.gyr_unit;
  }
  return note;
}

std::string ThresholdNote(const DetectionDetail& d, const StillDetectorOptions& options,
                          double dt_s) {
  std::string note =
      "window " + FormattedText("%.3g", static_cast<double>(d.window_samples) * dt_s) + " s (" +
      std::to_string(d.window_samples) + " samples at dt " + FormattedText("%.4g", dt_s) +
      " s, tested every " + std::to_string(d.block_samples) + " samples); false alarm " +
      FormattedText("%.3g", options.false_alarm) +
      " per window length; thresholds: accel variance ratio " + FormattedText("%.3f", d.acc_threshold) +
      " (chi^2 dof " + FormattedText("%.0f", d.acc_dof) + ")";
  if (d.gyr_threshold > 0.0) {
    note += ", gyro variance ratio " + FormattedText("%.3f", d.gyr_threshold) + " (chi^2 dof " +
            FormattedText("%.0f", d.gyr_dof) + ")";
  }
  if (d.rate_threshold > 0.0) {
    note += ", gyro mean rate chi^2(3) " + FormattedText("%.2f", d.rate_threshold) +
            " with allowance " + FormatVec(d.rate_allowance) + " " + options.gyr_unit;
  }
  return note;
}

std::string FailureNote(const Classification& found, const WindowTests& tests) {
  std::string note = "of " + std::to_string(found.windows) + " window positions, " +
                     std::to_string(found.failed_acc) + " fail the accel variance test";
  if (tests.gyro_variance) {
    note += ", " + std::to_string(found.failed_gyr) + " the gyro variance test";
  }
  if (tests.rate) note += ", " + std::to_string(found.failed_rate) + " the gyro mean-rate test";
  note += ", " + std::to_string(found.failed_gap) + " span a time gap";
  if (found.failed_nonfinite > 0) {
    note += ", " + std::to_string(found.failed_nonfinite) + " hold a NaN or infinite sample";
  }
  return note;
}

/// Lists the accelerometer-still runs, long enough, that no kept segment overlaps.
void NoteGyroRejections(const ImuSeries& series, const Classification& found,
                        const StillDetectorOptions& options, double dt_s,
                        SegmentationResult& result) {
  std::string listed;
  std::size_t& count = result.detail.rejected_by_gyro;
  for (const Run& run : found.acc_runs) {
    const Run trimmed = Trim(series, run, options.edge_s);
    const double length_s = static_cast<double>(trimmed.size()) * dt_s;
    if (trimmed.size() == 0 || length_s < options.min_still_s ||
        Overlaps(result.segments, run)) {
      continue;
    }
    if (++count <= kListedRuns) listed += (listed.empty() ? "" : ", ") + TimeRange(series, trimmed);
  }
  if (count > 0) {
    result.report.notes.push_back(
        std::to_string(count) +
        " accelerometer-still runs rejected only by the gyroscope tests (rotation jitter or a "
        "drifting rate; gyro_variance_test = false or use_gyro = false would keep them): " +
        listed + (count > kListedRuns ? ", ..." : ""));
  }
}

/// Warns when the stated initial still period is not still throughout.
void NoteInitialCoverage(const Classification& found, const NoiseEstimate& noise,
                         SegmentationReport& report) {
  std::size_t covered = 0;
  for (const Run& run : found.runs) {
    const std::size_t hi = std::min(run.end, noise.samples);
    if (hi > run.begin) covered += hi - run.begin;
  }
  if (covered < noise.samples) {
    report.notes.push_back("warning: the initial still period is not still throughout: " +
                           std::to_string(noise.samples - covered) + " of its " +
                           std::to_string(noise.samples) +
                           " samples fail a test; check init_still_s");
  }
}

}  // namespace plumb::segmentation::detail

// plumb/segmentation/still_detector_internal.h — INTERNAL to plumb::segmentation: the pieces
// of the still detector (still_detector.h) and the types they pass between them. Not part of
// the public interface. The detector is split by step:
//   still_noise.cc       the noise of a still period (initial, or pooled over a first pass
//                        seeded by the quietest stretch) and the window tests' thresholds;
//   still_runs.cc        the window layout, the moving-window classification into still runs,
//                        and the trimming of a run's ends;
//   join_same_pose.cc    the join of consecutive runs that hold the same pose;
//   still_notes.cc       the report's notes and the number formatting they share;
//   still_detector.cc    DetectStillSegments, which runs the steps in order.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/number_text.h"
#include "plumb/core/segment.h"
#include "plumb/core/types.h"
#include "plumb/segmentation/block_moments.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb::segmentation::detail {

/// The sliding window sums are recomputed from the blocks every this many positions, so that
/// rounding in the running updates cannot accumulate over long series.
constexpr std::size_t kResyncInterval = 4096;

/// A half-open run of samples [begin, end).
struct Run {
  std::size_t begin = 0;
  std::size_t end = 0;

  std::size_t size() const { return end - begin; }
};

/// Window layout: `blocks` (odd) blocks of `block` samples, centred on a block.
struct Geometry {
  std::size_t block = 1;
  std::size_t blocks = 5;

  std::size_t window() const { return block * blocks; }
};

/// Everything a window test needs, derived from the noise estimate and the options.
struct WindowTests {
  Geometry geometry;
  /// Longest interval between two consecutive samples a still window may hold, s: half a
  /// window. Motion could hide in a longer gap; shorter ones (a host dropping samples one by
  /// one or in short bursts) cannot hide a change of pose, which the window's variance and
  /// mean-rate tests would see before and after it.
  double max_gap_s = 0.0;
  double inverse_n = 0.0;          ///< 1 / samples per window
  Vec3 acc_weight = Vec3::Zero();  ///< 1 / (3 sigma^2 (n - 1)), on the scatter sums
  double acc_threshold = 0.0;
  bool gyro_variance = false;         ///< gyroscope variance test on
  Vec3 gyr_weight = Vec3::Zero();     ///< 1 / (3 sigma^2 (n - 1)), on the scatter sums
  double gyr_threshold = 0.0;
  bool rate = false;                  ///< mean-rate test on
  Vec3 rate_offset = Vec3::Zero();    ///< n (still rate - gyro reference of the block sums)
  Vec3 rate_weight = Vec3::Zero();    ///< 1 / (V n^2), on the squared offset sums
  double rate_threshold = 0.0;
};

/// What one classification pass found.
struct Classification {
  std::vector<Run> runs;      ///< maximal runs of still samples
  std::vector<Run> acc_runs;  ///< the same by the accelerometer and time-gap tests alone
  std::size_t windows = 0;
  std::size_t failed_acc = 0;
  std::size_t failed_gyr = 0;
  std::size_t failed_rate = 0;
  std::size_t failed_gap = 0;
  std::size_t failed_nonfinite = 0;
};

// still_runs.cc

/// The window layout for a window of about `window_s` at sample interval `dt_s`.
Geometry MakeGeometry(double window_s, double dt_s);

/// One pass over the block sums: a window of `blocks` blocks is tested at every block; its
/// verdict applies to the centre block's samples (the first and last half windows, and a short
/// last block, take the verdict of the nearest window). Returns the maximal still runs.
Classification Classify(const ImuSeries& series, const BlockMoments& blocks,
                        const WindowTests& tests);

/// Trims edge_s from both ends of a run; returns an empty run when nothing is left.
Run Trim(const ImuSeries& series, Run run, double edge_s);

// still_noise.cc

/// Per-axis allowance for the still rate changing between poses.
Vec3 RateAllowance(const NoiseEstimate& noise, const StillDetectorOptions& options);

/// The window tests; `with_rate_test` false leaves out the mean-rate test (first pass).
WindowTests MakeTests(const NoiseEstimate& noise, const BlockMoments& blocks,
                      const StillDetectorOptions& options, Geometry geometry,
                      DetectionDetail& detail, bool with_rate_test = true);

/// Noise from the first init_still_s seconds, rounded down to whole blocks.
NoiseEstimate InitialNoise(const ImuSeries& series, const BlockMoments& blocks,
                           const StillDetectorOptions& options, Geometry geometry,
                           SegmentationReport& report);

/// Noise pooled over the still runs of a first pass seeded by the quietest stretch.
NoiseEstimate AutomaticNoise(const ImuSeries& series, const BlockMoments& blocks,
                             const StillDetectorOptions& options, Geometry geometry,
                             double dt_s, SegmentationReport& report);

// join_same_pose.cc

/// Joins consecutive still runs whose samples in between show the same pose (see the
/// comment at its definition); `joined` counts the joins.
std::vector<Run> JoinSamePose(const ImuSeries& series, const BlockMoments& blocks,
                              const std::vector<Run>& runs,
                              const NoiseEstimate& noise, const StillDetectorOptions& options,
                              double dt_s, double max_gap_s, std::size_t& joined);

// still_notes.cc

/// "(x, y, z)", each printed with `format`.
std::string FormatVec(const Vec3& v, const char* format = "%.4g");
/// "t0-t1 s": the run's first and last sample times, from the series' start.
std::string TimeRange(const ImuSeries& series, Run run);

std::string NoiseNote(const NoiseEstimate& noise, const StillDetectorOptions& options);
std::string ThresholdNote(const DetectionDetail& d, const StillDetectorOptions& options,
                          double dt_s);
std::string FailureNote(const Classification& found, const WindowTests& tests);

/// Lists the accelerometer-still runs, long enough, that no kept segment overlaps.
void NoteGyroRejections(const ImuSeries& series, const Classification& found,
                        const StillDetectorOptions& options, double dt_s,
                        SegmentationResult& result);

/// Warns when the stated initial still period is not still throughout.
void NoteInitialCoverage(const Classification& found, const NoiseEstimate& noise,
                         SegmentationReport& report);

}  // namespace plumb::segmentation::detail

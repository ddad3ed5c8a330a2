// plumb/segmentation/still_runs.cc — the run finding of the still detector
// (still_detector.h, step 2): the window layout in blocks, the moving-window tests over the
// block sums that classify every block as still or not and collect the still runs, and the
// trimming of a run's ends.
#include <algorithm>
#include <cmath>
#include <utility>

#include "plumb/segmentation/still_detector_internal.h"

namespace plumb::segmentation::detail {
namespace {

/// Blocks per moving window when the window holds at least that many samples (odd, so that a
/// window is centred on a block). Boundaries are resolved to one block.
constexpr std::size_t kBlocksPerWindow = 17;

/// Collects maximal runs of samples with a true verdict, the verdicts coming in order.
class RunBuilder {
 public:
  /// The verdict for samples from `first` on (until the next call).
  void Mark(std::size_t first, bool still) {
    if (still && !in_run_) {
      begin_ = first;
      in_run_ = true;
    } else if (!still && in_run_) {
      runs_.push_back(Run{begin_, first});
      in_run_ = false;
    }
  }
  std::vector<Run> Finish(std::size_t n_samples) {
    if (in_run_) runs_.push_back(Run{begin_, n_samples});
    in_run_ = false;
    return std::move(runs_);
  }

 private:
  std::vector<Run> runs_;
  std::size_t begin_ = 0;
  bool in_run_ = false;
};

/// The longest interval between consecutive samples of each full block of `b` samples:
/// `inside` the block, and `before` it (from the previous block's last sample to its first; 0
/// for the first block). A window's longest interval is the largest `inside` of its blocks
/// and `before` of all but its first (LongestInterval).
struct BlockIntervals {
  std::vector<double> inside;
  std::vector<double> before;

  BlockIntervals(const std::vector<double>& t_s, std::size_t b, std::size_t full)
      : inside(full, 0.0), before(full, 0.0) {
    for (std::size_t j = 0; j < full; ++j) {
      const std::size_t first = j * b;
      if (j > 0) before[j] = t_s[first] - t_s[first - 1];
      for (std::size_t i = first + 1; i < first + b; ++i) {
        inside[j] = std::max(inside[j], t_s[i] - t_s[i - 1]);
      }
    }
  }

  /// The longest interval between consecutive samples of the window of `m` blocks from
  /// block `first_block`.
  double LongestInterval(std::size_t first_block, std::size_t m) const {
    double longest = inside[first_block];
    for (std::size_t j = first_block + 1; j < first_block + m; ++j) {
      longest = std::max({longest, inside[j], before[j]});
    }
    return longest;
  }
};

}  // namespace

/// The most samples a still-detection window holds: more than any recording has (a day at
/// 1 MHz is 8.6e10).
constexpr double kMaxWindowSamples = 1e12;

Geometry MakeGeometry(double window_s, double dt_s) {
  // Samples per window; bounded so that a sample interval near zero (a rate of 1e300 Hz)
  // gives a window longer than any series, not an integer overflow.
  const double target = std::min(std::max(5.0, window_s / dt_s), kMaxWindowSamples);
  Geometry g;
  if (target >= static_cast<double>(kBlocksPerWindow)) {
    g.blocks = kBlocksPerWindow;
    g.block = static_cast<std::size_t>(std::llround(target / kBlocksPerWindow));
  } else {
    g.block = 1;
    g.blocks = static_cast<std::size_t>(std::llround(target)) | 1U;  // odd
  }
  return g;
}

/// One pass over the block sums: a window of `blocks` blocks is tested at every block; its
/// verdict applies to the centre block's samples (the first and last half windows, and a short
/// last block, take the verdict of the nearest window). Returns the maximal still runs.
Classification Classify(const ImuSeries& series, const BlockMoments& blocks,
                        const WindowTests& tests) {
  Classification out;
  const std::size_t b = tests.geometry.block;
  const std::size_t m = tests.geometry.blocks;
  const std::size_t k = m / 2;
  const std::size_t full = blocks.num_full_blocks();
  const bool gyro = tests.gyro_variance || tests.rate;
  TriadMoments acc;
  TriadMoments gyr;
  std::size_t nonfinite = 0;  // non-finite blocks in the window
  RunBuilder all_tests;
  RunBuilder acc_tests;
  const BlockIntervals intervals(series.t_s, b, full);
  for (std::size_t c = k; c + k < full; ++c) {
    const std::size_t first_block = c - k;
    if (first_block % kResyncInterval == 0) {
      acc = blocks.AccOver(first_block * b, (first_block + m) * b);
      if (gyro) gyr = blocks.GyrOver(first_block * b, (first_block + m) * b);
      nonfinite = blocks.NonfiniteOver(first_block * b, (first_block + m) * b);
    } else {
      acc += blocks.acc(c + k);
      acc -= blocks.acc(first_block - 1);
      if (gyro) {
        gyr += blocks.gyr(c + k);
        gyr -= blocks.gyr(first_block - 1);
      }
      nonfinite += static_cast<std::size_t>(blocks.nonfinite(c + k));
      nonfinite -= static_cast<std::size_t>(blocks.nonfinite(first_block - 1));
    }
    ++out.windows;
    const std::size_t first_sample = c == k ? 0 : c * b;
    if (nonfinite > 0) {
      ++out.failed_nonfinite;
      acc_tests.Mark(first_sample, false);
      all_tests.Mark(first_sample, false);
      continue;
    }
    bool still = true;
    if (intervals.LongestInterval(first_block, m) > tests.max_gap_s) {
      ++out.failed_gap;
      still = false;
    }
    const Vec3 acc_scatter = acc.sum_sq - acc.sum.cwiseProduct(acc.sum) * tests.inverse_n;
    if (acc_scatter.dot(tests.acc_weight) > tests.acc_threshold) {
      ++out.failed_acc;
      still = false;
    }
    acc_tests.Mark(first_sample, still);
    if (tests.gyro_variance) {
      const Vec3 gyr_scatter = gyr.sum_sq - gyr.sum.cwiseProduct(gyr.sum) * tests.inverse_n;
      if (gyr_scatter.dot(tests.gyr_weight) > tests.gyr_threshold) {
        ++out.failed_gyr;
        still = false;
      }
    }
    if (tests.rate) {
      const Vec3 offset = gyr.sum - tests.rate_offset;  // n (window mean - still rate)
      if (offset.cwiseProduct(offset).dot(tests.rate_weight) > tests.rate_threshold) {
        ++out.failed_rate;
        still = false;
      }
    }
    all_tests.Mark(first_sample, still);
  }
  out.runs = all_tests.Finish(blocks.samples());
  out.acc_runs = acc_tests.Finish(blocks.samples());
  return out;
}

/// Trims edge_s from both ends of a run; returns an empty run when nothing is left.
Run Trim(const ImuSeries& series, Run run, double edge_s) {
  const auto first = series.t_s.begin() + static_cast<std::ptrdiff_t>(run.begin);
  const auto last = series.t_s.begin() + static_cast<std::ptrdiff_t>(run.end);
  const auto begin_it = std::lower_bound(first, last, series.t_s[run.begin] + edge_s);
  const auto end_it = std::upper_bound(begin_it, last, series.t_s[run.end - 1] - edge_s);
  const Run trimmed{static_cast<std::size_t>(begin_it - series.t_s.begin()),
                    static_cast<std::size_t>(end_it - series.t_s.begin())};
  return trimmed.end > trimmed.begin ? trimmed : Run{run.begin, run.begin};
}

}  // namespace plumb::segmentation::detail

// plumb/segmentation/block_moments.h — per-block sums of a series, read in one pass.
//
// The still detector reads the samples once into blocks of b consecutive samples: per axis,
// the sum and the sum of squares of (sample - reference), in double, with the reference the
// series' first sample. Every later step (the quietest stretch, the moving-window tests, the
// pooled noise) adds block sums instead of samples. Sums of squares about a fixed reference
// lose about eps (range / sigma)^2 of the variance to rounding: under 1e-9 for a triad whose
// range is 10^4 noise standard deviations. A block holding a non-finite value (NaN or inf) in
// a summed triad is flagged and its sums left at zero: no window over it can be called still.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/types.h"

namespace plumb::segmentation {

/// Sums of a triad's (sample - reference) and its square over some samples.
struct TriadMoments {
  Vec3 sum = Vec3::Zero();     ///< series units
  Vec3 sum_sq = Vec3::Zero();  ///< series units^2

  TriadMoments& operator+=(const TriadMoments& other) {
    sum += other.sum;
    sum_sq += other.sum_sq;
    return *this;
  }
  TriadMoments& operator-=(const TriadMoments& other) {
    sum -= other.sum;
    sum_sq -= other.sum_sq;
    return *this;
  }
  /// Per-axis sum of squared deviations from the mean of the n samples (never negative).
  Vec3 Scatter(double n) const { return (sum_sq - sum.cwiseProduct(sum) / n).cwiseMax(0.0); }
};

class BlockMoments {
 public:
  /// One pass over `series` (accelerometer, and gyroscope when `with_gyro`), in blocks of
  /// `block` >= 1 samples; the last block holds the remainder and may be shorter.
  BlockMoments(const ImuSeries& series, std::size_t block, bool with_gyro);

  std::size_t block() const { return block_; }
  std::size_t samples() const { return samples_; }
  std::size_t num_blocks() const { return acc_.size(); }
  /// Blocks holding exactly block() samples.
  std::size_t num_full_blocks() const { return samples_ / block_; }
  bool has_gyro() const { return !gyr_.empty(); }
  const Vec3& acc_reference() const { return acc_reference_; }
  const Vec3& gyr_reference() const { return gyr_reference_; }
  const TriadMoments& acc(std::size_t k) const { return acc_[k]; }
  const TriadMoments& gyr(std::size_t k) const { return gyr_[k]; }
  /// Whether block k holds a non-finite value in a summed triad (its sums are then zero).
  bool nonfinite(std::size_t k) const { return nonfinite_[k] != 0; }
  /// Blocks flagged non-finite among [begin, end) (samples, as for AccOver).
  std::size_t NonfiniteOver(std::size_t begin, std::size_t end) const;
  /// Samples holding a non-finite value.
  std::size_t nonfinite_samples() const { return nonfinite_samples_; }

  /// Moments over the samples [begin, end); begin must be a multiple of block() and end a
  /// multiple of block() or samples(). O(blocks spanned).
  TriadMoments AccOver(std::size_t begin, std::size_t end) const;
  TriadMoments GyrOver(std::size_t begin, std::size_t end) const;

 private:
  static TriadMoments Over(const std::vector<TriadMoments>& blocks, std::size_t block,
                           std::size_t begin, std::size_t end);
  void FlagNonfinite(const ImuSeries& series, bool with_gyro);

  std::size_t block_;
  std::size_t samples_;
  Vec3 acc_reference_ = Vec3::Zero();
  Vec3 gyr_reference_ = Vec3::Zero();
  std::vector<TriadMoments> acc_;
  std::vector<TriadMoments> gyr_;
  std::vector<std::uint8_t> nonfinite_;  ///< per block: 1 when it holds a non-finite value
  std::size_t nonfinite_samples_ = 0;
};

}  // namespace plumb::segmentation

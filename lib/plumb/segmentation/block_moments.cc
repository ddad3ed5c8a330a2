#include "plumb/segmentation/block_moments.h"

#include <algorithm>

namespace plumb::segmentation {
namespace {

/// Block sums of one triad, the differences formed in double.
std::vector<TriadMoments> SumBlocks(const std::vector<Vec3f>& samples, std::size_t block,
                                    const Vec3& reference) {
  std::vector<TriadMoments> blocks((samples.size() + block - 1) / block);
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const std::size_t end = std::min(samples.size(), (k + 1) * block);
    TriadMoments m;
    for (std::size_t i = k * block; i < end; ++i) {
      const Vec3 d = samples[i].cast<double>() - reference;
      m.sum += d;
      m.sum_sq += d.cwiseProduct(d);
    }
    blocks[k] = m;
  }
  return blocks;
}

/// The first sample whose three values are finite (zero when none is).
Vec3 FirstFinite(const std::vector<Vec3f>& samples) {
  for (const Vec3f& x : samples) {
    if (x.allFinite()) return x.cast<double>();
  }
  return Vec3::Zero();
}

}  // namespace

BlockMoments::BlockMoments(const ImuSeries& series, std::size_t block, bool with_gyro)
    : block_(std::max<std::size_t>(1, block)), samples_(series.acc.size()) {
  if (samples_ == 0) return;
  const bool gyro = with_gyro && !series.gyr.empty();
  acc_reference_ = FirstFinite(series.acc);
  acc_ = SumBlocks(series.acc, block_, acc_reference_);
  if (gyro) {
    gyr_reference_ = FirstFinite(series.gyr);
    gyr_ = SumBlocks(series.gyr, block_, gyr_reference_);
  }
  FlagNonfinite(series, gyro);
}

void BlockMoments::FlagNonfinite(const ImuSeries& series, bool with_gyro) {
  nonfinite_.assign(acc_.size(), 0);
  for (std::size_t k = 0; k < acc_.size(); ++k) {
    const bool acc_finite = acc_[k].sum_sq.allFinite();
    const bool gyr_finite = !with_gyro || gyr_[k].sum_sq.allFinite();
    if (acc_finite && gyr_finite) continue;
    nonfinite_[k] = 1;
    acc_[k] = TriadMoments();
    if (with_gyro) gyr_[k] = TriadMoments();
    const std::size_t end = std::min(samples_, (k + 1) * block_);
    for (std::size_t i = k * block_; i < end; ++i) {
      const bool bad = !series.acc[i].allFinite() || (with_gyro && !series.gyr[i].allFinite());
      if (bad) ++nonfinite_samples_;
    }
  }
}

std::size_t BlockMoments::NonfiniteOver(std::size_t begin, std::size_t end) const {
  std::size_t count = 0;
  const std::size_t last = (end + block_ - 1) / block_;
  for (std::size_t k = begin / block_; k < last; ++k) count += nonfinite_[k];
  return count;
}

TriadMoments BlockMoments::Over(const std::vector<TriadMoments>& blocks, std::size_t block,
                                std::size_t begin, std::size_t end) {
  TriadMoments m;
  const std::size_t last = (end + block - 1) / block;
  for (std::size_t k = begin / block; k < last; ++k) m += blocks[k];
  return m;
}

TriadMoments BlockMoments::AccOver(std::size_t begin, std::size_t end) const {
  return Over(acc_, block_, begin, end);
}

TriadMoments BlockMoments::GyrOver(std::size_t begin, std::size_t end) const {
  return Over(gyr_, block_, begin, end);
}

}  // namespace plumb::segmentation

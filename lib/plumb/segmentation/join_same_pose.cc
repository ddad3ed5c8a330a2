// plumb/segmentation/join_same_pose.cc — the join of the still detector (still_detector.h,
// step 3, StillDetectorOptions::join_same_pose): consecutive still runs are joined when the
// samples between them hold the same pose (equal accelerometer means, no rotation), by three
// chi^2(3) tests on block moments and a bound on the angle turned in the gap.
#include <algorithm>
#include <cmath>

#include "plumb/core/units.h"
#include "plumb/segmentation/still_detector_internal.h"
#include "plumb/signal/chi_square.h"

namespace plumb::segmentation::detail {
namespace {

/// Mean and per-axis sample variance of a triad over samples [begin, end), in double.
struct SpanStats {
  Vec3 mean = Vec3::Zero();
  Vec3 variance = Vec3::Zero();
  double n = 0.0;
};

/// Mean and sample variance from a span's block moments (sums about `reference`): the runs
/// and gaps the detector produces start and end on block boundaries, so no sample is read
/// again.
SpanStats Stats(const TriadMoments& m, const Vec3& reference, std::size_t begin,
                std::size_t end) {
  SpanStats out;
  out.n = static_cast<double>(end - begin);
  if (end <= begin) return out;
  out.mean = reference + m.sum / out.n;
  if (out.n > 1.0) out.variance = m.Scatter(out.n) / (out.n - 1.0);
  return out;
}

SpanStats AccStats(const BlockMoments& blocks, std::size_t begin, std::size_t end) {
  return Stats(blocks.AccOver(begin, end), blocks.acc_reference(), begin, end);
}

SpanStats GyrStats(const BlockMoments& blocks, std::size_t begin, std::size_t end) {
  return Stats(blocks.GyrOver(begin, end), blocks.gyr_reference(), begin, end);
}

/// sum_axes (a - b)^2 / (var_a + var_b + allowance^2): chi^2(3) when a and b estimate the same
/// triad with those variances of the means.
double MeanDistance(const Vec3& a, const Vec3& var_a, const Vec3& b, const Vec3& var_b,
                    const Vec3& allowance) {
  const Vec3 d = a - b;
  return (d.cwiseProduct(d).array() /
          (var_a + var_b + allowance.cwiseProduct(allowance)).array())
      .sum();
}

/// Variance of the mean of a span: its own sample variance (the gap's vibration, or the
/// still noise for a still run) times tau_int / n.
Vec3 VarianceOfMean(const SpanStats& span, const Vec3& noise_sigma, const Vec3& tau_int,
                    bool own_variance) {
  const Vec3 var = own_variance ? span.variance.cwiseMax(noise_sigma.cwiseProduct(noise_sigma))
                                : Vec3(noise_sigma.cwiseProduct(noise_sigma));
  return var.cwiseProduct(tau_int) / std::max(span.n, 1.0);
}

/// The largest angle the gyroscope turns away from the start of samples [begin, end), rad:
/// max_k |sum_{i<k} (omega_i - still_rate) dt_i| (small-angle accumulation, enough to tell a
/// vibration, milliradians, from a turn and back, radians).
double MaxExcursion(const ImuSeries& series, std::size_t begin, std::size_t end,
                    const Vec3& still_rate) {
  Vec3 angle = Vec3::Zero();
  double largest = 0.0;
  for (std::size_t i = begin; i < end && i + 1 < series.size(); ++i) {
    angle += (series.gyr[i].cast<double>() - still_rate) * (series.t_s[i + 1] - series.t_s[i]);
    largest = std::max(largest, angle.norm());
  }
  return largest;
}

/// What a vibration of the gap's own scatter can turn by chance: five standard deviations of
/// its random walk over the gap, kept within [0.5, 3] degrees, rad. The upper bound matters:
/// a real turn has a large scatter too, and a still vehicle shaking does not turn 3 degrees.
double ExcursionLimit(const SpanStats& rate, const Vec3& tau_int, double dt_s) {
  const double walk =
      std::sqrt(rate.variance.cwiseProduct(tau_int).maxCoeff() * std::max(rate.n, 1.0)) * dt_s;
  return std::clamp(5.0 * walk, 0.5 * units::kRadPerDeg, 3.0 * units::kRadPerDeg);
}

}  // namespace

/// Joins consecutive still runs whose samples in between show the same pose: a vehicle
/// standing still but vibrating (engine, wind, a hand on the airframe) fails the window
/// variance test in bursts and would otherwise be cut into several "poses" joined by
/// "motion" that holds no rotation — a problem the calibration cannot condition (issue 5:
/// plane408_centre_point.BIN, a 45 s still log, came out as 2 segments). Runs a and b with
/// the gap g between them are joined when, at the detector's chi^2(3) threshold on each:
///  - the accelerometer means of a and b agree (variance of each mean from the still noise,
///    plus the rate allowance's analogue: one per-sample noise sigma per axis);
///  - the gap's accelerometer mean agrees with theirs (the gap's own variance of its mean);
///  - the gap's mean rate is the still rate (the gap's own variance), and the angle the
///    gyroscope turns away from the first run's attitude anywhere in the gap stays within
///    what the gap's own scatter walks by chance (5 sigma, within 0.5-3 degrees): a turn, even
///    one back to the same attitude (its mean rate can be zero), fails. Without the gyroscope
///    (none, or use_gyro off) runs are never joined, and neither across a time gap (missing
///    samples over half a window).
/// A gap holding a pure translation and back also passes: its mean specific force is the
/// still one (the velocity change is zero), so the joined segment's mean is unbiased.
std::vector<Run> JoinSamePose(const ImuSeries& series, const BlockMoments& blocks,
                              const std::vector<Run>& runs,
                              const NoiseEstimate& noise, const StillDetectorOptions& options,
                              double dt_s, double max_gap_s, std::size_t& joined) {
  joined = 0;
  // Without the gyroscope a turn about the vertical keeps the accelerometer means: never join.
  const bool gyro = noise.has_gyro && blocks.has_gyro() && options.use_gyro;
  if (runs.size() < 2 || !options.join_same_pose || !gyro) return runs;
  const double threshold = signal::ChiSquareQuantileExact(1.0 - options.false_alarm, 3.0);
  std::vector<Run> out{runs.front()};
  SpanStats a = AccStats(blocks, runs.front().begin, runs.front().end);
  for (std::size_t k = 1; k < runs.size(); ++k) {
    const Run& next = runs[k];
    // A time gap (missing samples, over max_gap_s) between the runs is never joined.
    const double gap_s = series.t_s[next.begin] - series.t_s[out.back().end - 1];
    const double expected_s = static_cast<double>(next.begin - out.back().end + 1) * dt_s;
    if (gap_s > expected_s + max_gap_s) {
      out.push_back(next);
      a = AccStats(blocks, next.begin, next.end);
      continue;
    }
    // Runs and gaps lie on block boundaries; a gap holding a non-finite sample is not joined.
    const auto aligned = [&](std::size_t i) {
      return i % blocks.block() == 0 || i == blocks.samples();
    };
    if (!aligned(out.back().end) || !aligned(next.begin) || !aligned(next.end) ||
        blocks.NonfiniteOver(out.back().end, next.begin) > 0) {
      out.push_back(next);
      a = AccStats(blocks, next.begin, next.end);
      continue;
    }
    const SpanStats b = AccStats(blocks, next.begin, next.end);
    const SpanStats gap = AccStats(blocks, out.back().end, next.begin);
    const Vec3 var_a = VarianceOfMean(a, noise.acc_sigma, noise.acc_tau_int, false);
    const Vec3 var_b = VarianceOfMean(b, noise.acc_sigma, noise.acc_tau_int, false);
    const Vec3 var_gap = VarianceOfMean(gap, noise.acc_sigma, noise.acc_tau_int, true);
    bool same = gap.n > 0.0 &&
                MeanDistance(a.mean, var_a, b.mean, var_b, noise.acc_sigma) <= threshold &&
                MeanDistance(gap.mean, var_gap, 0.5 * (a.mean + b.mean), 0.25 * (var_a + var_b),
                             noise.acc_sigma) <= threshold;
    if (same) {
      const SpanStats rate = GyrStats(blocks, out.back().end, next.begin);
      const Vec3 var_rate = VarianceOfMean(rate, noise.gyr_sigma, noise.gyr_tau_int, true);
      same = MeanDistance(rate.mean, var_rate, noise.gyr_still_rate, Vec3::Zero(),
                          RateAllowance(noise, options)) <= threshold &&
             MaxExcursion(series, out.back().end, next.begin, noise.gyr_still_rate) <=
                 ExcursionLimit(rate, noise.gyr_tau_int, dt_s);
    }
    if (same) {
      out.back().end = next.end;
      a = AccStats(blocks, out.back().begin, out.back().end);
      ++joined;
    } else {
      out.push_back(next);
      a = b;
    }
  }
  return out;
}

}  // namespace plumb::segmentation::detail

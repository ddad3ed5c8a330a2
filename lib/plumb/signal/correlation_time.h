// plumb/signal/correlation_time.h — how much the samples of a still period are correlated.
//
// A MEMS IMU samples behind a low-pass filter, so consecutive samples are correlated and the
// mean of N samples is noisier than sigma / sqrt(N):
//   var(mean) = sigma^2 tau_int / N,   tau_int = 1 + 2 sum_{k>=1} rho_k   (samples),
// with rho_k the autocorrelation at lag k (tau_int = 1 for white noise, (1 + phi) / (1 - phi)
// for AR(1) noise x_i = phi x_{i-1} + e_i). Likewise the sample variance of N samples has
//   var(s^2) = 2 sigma^4 tau_sq / N,   tau_sq = 1 + 2 sum_{k>=1} rho_k^2,
// so it has about N / tau_sq degrees of freedom (used by the still detector's threshold).
//
// Estimator: the autocovariance is pooled over several still chunks, each centred on its own
// mean (or its own line, with `detrend`) (C_k = sum over chunks of sum_i y_i y_{i+k}, divided by the number of such pairs), and
// the sum over lags stops at Sokal's automatic window: the first M with M >= c tau_int(M)
// (A. Sokal, "Monte Carlo methods in statistical mechanics", 1997; c = 5 by default). The cost
// is O(N M) for N samples and the first 64 lags (M is about c tau_int, small for IMU noise);
// a window that runs past them (a drifting axis) takes the further lags from each chunk's
// power spectrum at once, O(N log N). Centring on each chunk's mean biases tau_int low by about
// tau_int / n for chunks of n samples.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/jobs.h"
#include "plumb/core/segment.h"
#include "plumb/signal/axis_view.h"

namespace plumb::signal {

struct CorrelationTimeOptions {
  /// Sokal's window factor c: lags are summed up to the first M with M >= c tau_int(M).
  /// Dimensionless, (1, 20]; larger is less biased and noisier. 5 is the usual choice.
  double sokal_c = 5.0;
  /// Largest lag summed, samples, >= 1. Reaching it (or half the longest chunk) leaves the
  /// estimate marked not converged.
  std::size_t max_lag = 5000;
  /// Centre each chunk on its least-squares line instead of its mean: a slow drift inside a
  /// chunk (a warming board, the bias's wander) then does not count as noise. The variance's
  /// divisor loses one more degree of freedom per chunk (samples - 2 chunks).
  bool detrend = false;
};

/// Result for one axis.
struct CorrelationTime {
  /// Integrated autocorrelation time 1 + 2 sum_{k=1}^{M} rho_k, samples (1 for white noise).
  /// Floored at 1e-3 (strongly anticorrelated samples).
  double tau_int = 1.0;
  /// 1 + 2 sum_{k=1}^{M} rho_k^2, samples (1 for white noise); a sample variance over n samples
  /// has about n / tau_sq degrees of freedom.
  double tau_sq = 1.0;
  /// Pooled variance about each chunk's own mean (sum of (n_c - 1) as divisor), units^2.
  double variance = 0.0;
  std::size_t window = 0;   ///< M, the number of lags summed
  std::size_t samples = 0;  ///< samples in the chunks used
  std::size_t chunks = 0;   ///< chunks used (those with at least 2 samples)
  /// True when the window condition M >= c tau_int was met before max_lag or half the longest
  /// chunk; otherwise tau_int is a lower bound.
  bool converged = false;
};

/// tau_int, tau_sq and the pooled variance of one axis from several still chunks. Chunks with
/// fewer than 2 samples (3 with detrend) are skipped. Throws plumb::Error if none is left, the pooled
/// variance is zero or not finite, or the options are out of range.
CorrelationTime EstimateCorrelationTime(const std::vector<AxisView>& chunks,
                                        const CorrelationTimeOptions& options = {});

/// The same for one axis (0-2) of the accelerometer or gyroscope over still segments of a
/// series (their [begin, end) ranges; attitude and labels are ignored).
CorrelationTime EstimateCorrelationTime(const ImuSeries& series,
                                        const std::vector<StillSegment>& segments, Sensor sensor,
                                        int axis, const CorrelationTimeOptions& options = {});

/// The same for the three axes of the accelerometer or gyroscope.
std::array<CorrelationTime, 3> EstimateCorrelationTime(
    const ImuSeries& series, const std::vector<StillSegment>& segments, Sensor sensor,
    const CorrelationTimeOptions& options = {});

/// The three axes of each of `sensors`, in that order (x, y, z of the first, then of the
/// next), each axis a job run through `run_jobs` (the same results without it); an axis's
/// error is thrown after all have run, the first in that order.
std::vector<CorrelationTime> EstimateCorrelationTimes(const ImuSeries& series,
                                                      const std::vector<StillSegment>& segments,
                                                      const std::vector<Sensor>& sensors,
                                                      const CorrelationTimeOptions& options,
                                                      const JobRunner& run_jobs);

/// Variance of the mean of `count` correlated samples: variance * tau_int / count, units^2.
/// Valid for count much larger than tau_int. Returns +inf for count == 0.
double VarianceOfMean(double variance, double tau_int, std::size_t count);

}  // namespace plumb::signal

// plumb/signal/allan.h — overlapping Allan deviation of a uniformly sampled series.
//
// For samples x_i (i = 0..n-1) at interval dt, the integral theta_k = dt sum_{i<k} x_i
// (k = 0..n) and a cluster of m samples (tau = m dt):
//   AVAR(tau) = sum_{k=0}^{n-2m} (theta_{k+2m} - 2 theta_{k+m} + theta_k)^2
//               / (2 tau^2 (n + 1 - 2m)),
// the fully overlapping estimator (IEEE Std 952, annex C). White noise of standard deviation
// sigma gives ADEV = sigma / sqrt(m); a random walk whose steps have standard deviation q gives
// ADEV = q sqrt(m / 3). The cost is O(n) per cluster size. The integral is formed in double
// after subtracting the first sample (AVAR ignores a constant offset).
#pragma once

#include <cstddef>
#include <vector>

#include "plumb/signal/axis_view.h"

namespace plumb::signal {

struct AllanOptions {
  /// Cluster sizes m, samples, each in [1, n / 2]; sorted and deduplicated. Empty: log-spaced,
  /// m = round(10^(j / points_per_decade)) for j = 0, 1, ... while m <= n / 2.
  std::vector<std::size_t> cluster_sizes;
  /// Density of the automatic log spacing, points per decade of tau, [1, 100].
  int points_per_decade = 10;
};

struct AllanDeviation {
  std::vector<std::size_t> cluster_size;  ///< m, samples
  std::vector<double> tau_s;              ///< cluster time m dt, s
  std::vector<double> adev;               ///< overlapping Allan deviation, units of x
  std::vector<std::size_t> terms;         ///< second differences averaged, n + 1 - 2m
};

/// Overlapping Allan deviation of `x` sampled every `dt_s` seconds. Throws plumb::Error if
/// dt_s is not positive and finite, x has fewer than 2 samples, a given cluster size is 0 or
/// above n / 2, or points_per_decade is out of range.
AllanDeviation OverlappingAllanDeviation(const AxisView& x, double dt_s,
                                         const AllanOptions& options = {});

}  // namespace plumb::signal

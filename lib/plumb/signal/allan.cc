#include "plumb/signal/allan.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "plumb/core/error.h"

namespace plumb::signal {
namespace {

std::vector<std::size_t> LogSpacedClusterSizes(std::size_t m_max, int points_per_decade) {
  std::vector<std::size_t> sizes;
  const double decades = std::log10(static_cast<double>(m_max));
  const int steps = static_cast<int>(std::floor(decades * points_per_decade + 1e-9));
  for (int j = 0; j <= steps; ++j) {
    const double m = std::round(std::pow(10.0, static_cast<double>(j) / points_per_decade));
    sizes.push_back(std::min(m_max, static_cast<std::size_t>(m)));
  }
  return sizes;
}

std::vector<std::size_t> ClusterSizes(const AllanOptions& options, std::size_t n) {
  const std::size_t m_max = n / 2;
  std::vector<std::size_t> sizes = options.cluster_sizes;
  if (sizes.empty()) {
    if (options.points_per_decade < 1 || options.points_per_decade > 100) {
      throw Error("Allan deviation: points_per_decade = " +
                  std::to_string(options.points_per_decade) + " is not in [1, 100]");
    }
    sizes = LogSpacedClusterSizes(m_max, options.points_per_decade);
  }
  for (std::size_t m : sizes) {
    if (m < 1 || m > m_max) {
      throw Error("Allan deviation: cluster size " + std::to_string(m) +
                  " samples is not in [1, " + std::to_string(m_max) + "] for " +
                  std::to_string(n) + " samples");
    }
  }
  std::sort(sizes.begin(), sizes.end());
  sizes.erase(std::unique(sizes.begin(), sizes.end()), sizes.end());
  return sizes;
}

}  // namespace

AllanDeviation OverlappingAllanDeviation(const AxisView& x, double dt_s,
                                         const AllanOptions& options) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    throw Error("Allan deviation: sample interval " + std::to_string(dt_s) +
                " s must be positive and finite");
  }
  const auto n = static_cast<std::size_t>(x.size());
  if (n < 2) {
    throw Error("Allan deviation: needs at least 2 samples, got " + std::to_string(n));
  }
  const std::vector<std::size_t> sizes = ClusterSizes(options, n);

  // theta_k / dt = sum_{i<k} (x_i - x_0), k = 0..n.
  std::vector<double> theta(n + 1, 0.0);
  const double offset = x[0];
  for (std::size_t i = 0; i < n; ++i) {
    theta[i + 1] = theta[i] + (static_cast<double>(x[static_cast<Eigen::Index>(i)]) - offset);
  }

  AllanDeviation out;
  for (std::size_t m : sizes) {
    const std::size_t terms = n + 1 - 2 * m;
    double sum = 0.0;
    for (std::size_t k = 0; k < terms; ++k) {
      const double d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
      sum += d * d;
    }
    // theta is in units of dt, so tau^2 = m^2 dt^2 cancels the dt^2 of the differences.
    const double md = static_cast<double>(m);
    const double avar = sum / (2.0 * md * md * static_cast<double>(terms));
    out.cluster_size.push_back(m);
    out.tau_s.push_back(md * dt_s);
    out.adev.push_back(std::sqrt(avar));
    out.terms.push_back(terms);
  }
  return out;
}

}  // namespace plumb::signal

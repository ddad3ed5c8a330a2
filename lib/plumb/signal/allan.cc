#include "plumb/signal/allan.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "plumb/core/error.h"
#include "plumb/signal/chi_square.h"

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

void CheckConfidence(double confidence) {
  if (!(confidence > 0.0 && confidence < 1.0)) {
    throw Error("Allan deviation: confidence " + std::to_string(confidence) +
                " is not in (0, 1)");
  }
}

/// theta_k / dt = sum_{i<k} (x_i - x_0), k = 0..n.
std::vector<double> Integral(const AxisView& x) {
  const auto n = static_cast<std::size_t>(x.size());
  std::vector<double> theta(n + 1, 0.0);
  const double offset = x[0];
  for (std::size_t i = 0; i < n; ++i) {
    theta[i + 1] = theta[i] + (static_cast<double>(x[static_cast<Eigen::Index>(i)]) - offset);
  }
  return theta;
}

/// Sum of the squared second differences of theta at cluster size m (theta in units of dt).
double SecondDifferenceSum(const std::vector<double>& theta, std::size_t m) {
  const std::size_t terms = theta.size() - 2 * m;  // n + 1 - 2m
  double sum = 0.0;
  for (std::size_t k = 0; k < terms; ++k) {
    const double d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
    sum += d * d;
  }
  return sum;
}

}  // namespace

const char* PowerLawNoiseName(PowerLawNoise noise) {
  switch (noise) {
    case PowerLawNoise::kWhitePhase: return "white PM";
    case PowerLawNoise::kFlickerPhase: return "flicker PM";
    case PowerLawNoise::kWhiteFrequency: return "white FM";
    case PowerLawNoise::kFlickerFrequency: return "flicker FM";
    case PowerLawNoise::kRandomWalkFrequency: return "random-walk FM";
  }
  return "?";
}

double OverlappingAllanEdf(std::size_t n, std::size_t m, PowerLawNoise noise) {
  if (m < 1 || 2 * m > n) {
    throw Error("Allan EDF: cluster size " + std::to_string(m) + " is not in [1, " +
                std::to_string(n / 2) + "] for " + std::to_string(n) + " samples");
  }
  const double N = static_cast<double>(n) + 1.0;  // phase points
  const double M = static_cast<double>(m);
  double edf = 1.0;
  switch (noise) {
    case PowerLawNoise::kWhitePhase:
      edf = (N + 1.0) * (N - 2.0 * M) / (2.0 * (N - M));
      break;
    case PowerLawNoise::kFlickerPhase: {
      const double a = std::log((N - 1.0) / (2.0 * M));
      const double b = std::log((2.0 * M + 1.0) * (N - 1.0) / 4.0);
      edf = a > 0.0 && b > 0.0 ? std::exp(std::sqrt(a * b)) : 1.0;
      break;
    }
    case PowerLawNoise::kWhiteFrequency:
      edf = (3.0 * (N - 1.0) / (2.0 * M) - 2.0 * (N - 2.0) / N) * 4.0 * M * M /
            (4.0 * M * M + 5.0);
      break;
    case PowerLawNoise::kFlickerFrequency:
      edf = m == 1 ? 2.0 * (N - 2.0) * (N - 2.0) / (2.3 * N - 4.9)
                   : 5.0 * N * N / (4.0 * M * (N + 3.0 * M));
      break;
    case PowerLawNoise::kRandomWalkFrequency:
      edf = N > 3.0 ? (N - 2.0) / (M * (N - 3.0) * (N - 3.0)) *
                          ((N - 1.0) * (N - 1.0) - 3.0 * M * (N - 1.0) + 4.0 * M * M)
                    : 1.0;
      break;
  }
  return std::isfinite(edf) ? std::max(1.0, edf) : 1.0;
}

double PooledAllanEdf(const std::vector<std::size_t>& record_sizes, std::size_t m,
                      PowerLawNoise noise) {
  double total = 0.0;
  for (std::size_t n : record_sizes) {
    if (m >= 1 && n >= 2 * m) total += static_cast<double>(n + 1 - 2 * m);
  }
  if (total <= 0.0) {
    throw Error("Allan EDF: no record has the " + std::to_string(2 * m) +
                " samples of two clusters of " + std::to_string(m));
  }
  double inverse = 0.0;  // sum_k w_k^2 / edf_k
  for (std::size_t n : record_sizes) {
    if (n < 2 * m) continue;
    const double w = static_cast<double>(n + 1 - 2 * m) / total;
    inverse += w * w / OverlappingAllanEdf(n, m, noise);
  }
  return 1.0 / inverse;
}

std::pair<double, double> AllanInterval(double adev, double edf, double confidence) {
  CheckConfidence(confidence);
  if (!(edf > 0.0) || !std::isfinite(edf)) {
    throw Error("Allan interval: degrees of freedom " + Number(edf) +
                " must be positive and finite");
  }
  const double tail = 0.5 * (1.0 - confidence);
  const double upper_q = ChiSquareQuantileExact(1.0 - tail, edf);
  const double lower_q = ChiSquareQuantileExact(tail, edf);
  return {adev * std::sqrt(edf / upper_q), adev * std::sqrt(edf / lower_q)};
}

AllanDeviation PooledAllanPoints(const std::vector<AxisView>& records, double dt_s,
                                 const AllanOptions& options) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) {
    throw Error("Allan deviation: sample interval " + Number(dt_s) +
                " s must be positive and finite");
  }
  CheckConfidence(options.confidence);
  AllanDeviation out;
  out.dt_s = dt_s;
  std::vector<std::vector<double>> thetas;
  std::size_t longest = 0;
  for (const AxisView& x : records) {
    const auto n = static_cast<std::size_t>(x.size());
    if (n < 2) continue;
    out.record_sizes.push_back(n);
    thetas.push_back(Integral(x));
    longest = std::max(longest, n);
  }
  if (longest < 2) {
    std::size_t most = 0;
    for (const AxisView& x : records) most = std::max(most, static_cast<std::size_t>(x.size()));
    throw Error("Allan deviation: needs at least 2 samples, got " + std::to_string(most));
  }
  // Record by record (each stays in cache for all its cluster sizes), every cluster size's sum
  // accumulated over the records in their order.
  const std::vector<std::size_t> sizes = ClusterSizes(options, longest);
  std::vector<double> sums(sizes.size(), 0.0);
  std::vector<std::size_t> term_counts(sizes.size(), 0);
  for (const auto& theta : thetas) {
    for (std::size_t j = 0; j < sizes.size(); ++j) {
      const std::size_t m = sizes[j];
      if (theta.size() < 2 * m + 1) continue;
      term_counts[j] += theta.size() - 2 * m;
      sums[j] += SecondDifferenceSum(theta, m);
    }
  }
  for (std::size_t j = 0; j < sizes.size(); ++j) {
    const std::size_t m = sizes[j], terms = term_counts[j];
    const double sum = sums[j];
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

AllanDeviation PooledAllanDeviation(const std::vector<AxisView>& records, double dt_s,
                                    const AllanOptions& options) {
  AllanDeviation out = PooledAllanPoints(records, dt_s, options);
  SetAllanIntervals(out, std::vector<PowerLawNoise>(out.adev.size(), options.noise),
                    options.confidence);
  return out;
}

AllanDeviation OverlappingAllanDeviation(const AxisView& x, double dt_s,
                                         const AllanOptions& options) {
  return PooledAllanDeviation({x}, dt_s, options);
}

void SetAllanIntervals(AllanDeviation& adev, const std::vector<PowerLawNoise>& noise,
                       double confidence) {
  CheckConfidence(confidence);
  if (noise.size() != adev.adev.size()) {
    throw Error("Allan intervals: " + std::to_string(noise.size()) + " noise types for " +
                std::to_string(adev.adev.size()) + " points");
  }
  const std::size_t points = adev.adev.size();
  adev.noise = noise;
  adev.confidence = confidence;
  adev.edf.assign(points, 0.0);
  adev.adev_lower.assign(points, 0.0);
  adev.adev_upper.assign(points, 0.0);
  for (std::size_t j = 0; j < points; ++j) {
    adev.edf[j] = PooledAllanEdf(adev.record_sizes, adev.cluster_size[j], noise[j]);
    const auto [lower, upper] = AllanInterval(adev.adev[j], adev.edf[j], confidence);
    adev.adev_lower[j] = lower;
    adev.adev_upper[j] = upper;
  }
}

}  // namespace plumb::signal

#include "plumb/signal/correlation_time.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "plumb/core/error.h"

namespace plumb::signal {
namespace {

/// Samples of every usable chunk centred on the chunk's mean, stored back to back.
struct CentredChunks {
  std::vector<double> values;
  std::vector<std::size_t> offsets;  ///< chunk c is values[offsets[c], offsets[c + 1])
  std::size_t longest = 0;

  std::size_t count() const { return offsets.size() - 1; }
  std::size_t length(std::size_t c) const { return offsets[c + 1] - offsets[c]; }
};

CentredChunks Centre(const std::vector<AxisView>& chunks, bool detrend) {
  CentredChunks out;
  out.offsets.push_back(0);
  for (const AxisView& chunk : chunks) {
    const auto n = static_cast<std::size_t>(chunk.size());
    if (n < (detrend ? 3u : 2u)) continue;
    const double mean = chunk.cast<double>().mean();
    // The least-squares slope against the sample index about its middle (0 without detrend).
    const double mid = 0.5 * static_cast<double>(n - 1);
    double slope = 0.0;
    if (detrend) {
      double sxy = 0.0, sxx = 0.0;
      for (Eigen::Index i = 0; i < chunk.size(); ++i) {
        const double x = static_cast<double>(i) - mid;
        sxy += x * (static_cast<double>(chunk[i]) - mean);
        sxx += x * x;
      }
      slope = sxy / sxx;
    }
    for (Eigen::Index i = 0; i < chunk.size(); ++i) {
      out.values.push_back(static_cast<double>(chunk[i]) - mean -
                           slope * (static_cast<double>(i) - mid));
    }
    out.offsets.push_back(out.values.size());
    out.longest = std::max(out.longest, n);
  }
  return out;
}

/// Lags computed per pass over the data: the window usually stops within a few lags, and
/// one pass for several keeps the samples in cache once instead of streaming them per lag.
constexpr std::size_t kLagsPerPass = 8;

/// Autocovariances at lags first .. first + count - 1 pooled over chunks (each divided by its
/// number of pairs), NaN for a lag no chunk is longer than. One pass over each chunk; each
/// lag's sum is accumulated in the same order as a pass of its own would.
std::array<double, kLagsPerPass> PooledAutocovariances(const CentredChunks& data,
                                                       std::size_t first, std::size_t count) {
  std::array<double, kLagsPerPass> sum{}, out{};
  std::array<std::size_t, kLagsPerPass> pairs{};
  for (std::size_t c = 0; c < data.count(); ++c) {
    const std::size_t n = data.length(c);
    if (n <= first) continue;
    const double* y = data.values.data() + data.offsets[c];
    std::array<double, kLagsPerPass> chunk_sum{};
    const std::size_t lags = std::min(count, n - first);  // lags this chunk has pairs for
    for (std::size_t i = 0; i + first < n; ++i) {
      const std::size_t reach = std::min(lags, n - first - i);
      for (std::size_t j = 0; j < reach; ++j) chunk_sum[j] += y[i] * y[i + first + j];
    }
    for (std::size_t j = 0; j < lags; ++j) {
      sum[j] += chunk_sum[j];
      pairs[j] += n - first - j;
    }
  }
  for (std::size_t j = 0; j < count; ++j) {
    out[j] = pairs[j] == 0 ? std::numeric_limits<double>::quiet_NaN()
                           : sum[j] / static_cast<double>(pairs[j]);
  }
  return out;
}

void CheckOptions(const CorrelationTimeOptions& options) {
  if (!(options.sokal_c > 1.0 && options.sokal_c <= 20.0)) {
    throw Error("correlation time: Sokal window factor c = " + Number(options.sokal_c) +
                " is not in (1, 20]");
  }
  if (options.max_lag < 1) throw Error("correlation time: max_lag must be at least 1");
}

}  // namespace

CorrelationTime EstimateCorrelationTime(const std::vector<AxisView>& chunks,
                                        const CorrelationTimeOptions& options) {
  CheckOptions(options);
  const CentredChunks data = Centre(chunks, options.detrend);
  if (data.count() == 0) {
    throw Error(std::string("correlation time: no chunk has at least ") +
                (options.detrend ? "3" : "2") + " samples (" +
                std::to_string(chunks.size()) + " chunks given)");
  }
  CorrelationTime out;
  out.chunks = data.count();
  out.samples = data.values.size();
  double sum_sq = 0.0;
  for (double y : data.values) sum_sq += y * y;
  const std::size_t fitted = (options.detrend ? 2 : 1) * out.chunks;  // means (and slopes)
  out.variance = sum_sq / static_cast<double>(out.samples - fitted);
  const double c0 = sum_sq / static_cast<double>(out.samples);
  if (!(c0 > 0.0) || !std::isfinite(c0)) {
    throw Error("correlation time: the samples have zero or non-finite variance (" +
                Number(out.variance) + ")");
  }

  const std::size_t last_lag = std::min(options.max_lag, data.longest / 2);
  double tau = 1.0;
  double tau_sq = 1.0;
  std::array<double, kLagsPerPass> covariances{};
  for (std::size_t k = 1; k <= last_lag; ++k) {
    const std::size_t slot = (k - 1) % kLagsPerPass;
    if (slot == 0) {
      covariances = PooledAutocovariances(data, k, std::min(kLagsPerPass, last_lag + 1 - k));
    }
    const double rho = covariances[slot] / c0;
    tau += 2.0 * rho;
    tau_sq += 2.0 * rho * rho;
    out.window = k;
    if (static_cast<double>(k) >= options.sokal_c * tau) {
      out.converged = true;
      break;
    }
  }
  out.tau_int = std::max(tau, 1e-3);
  out.tau_sq = tau_sq;
  return out;
}

std::array<CorrelationTime, 3> EstimateCorrelationTime(const ImuSeries& series,
                                                       const std::vector<StillSegment>& segments,
                                                       Sensor sensor,
                                                       const CorrelationTimeOptions& options) {
  std::array<CorrelationTime, 3> out;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<AxisView> chunks;
    chunks.reserve(segments.size());
    for (const StillSegment& segment : segments) {
      chunks.push_back(ViewAxis(series, sensor, axis, segment.begin, segment.end));
    }
    out[static_cast<std::size_t>(axis)] = EstimateCorrelationTime(chunks, options);
  }
  return out;
}

double VarianceOfMean(double variance, double tau_int, std::size_t count) {
  if (count == 0) return std::numeric_limits<double>::infinity();
  return variance * tau_int / static_cast<double>(count);
}

}  // namespace plumb::signal

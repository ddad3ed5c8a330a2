#include "plumb/signal/correlation_time.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <exception>
#include <limits>
#include <string>
#include <utility>

#include <unsupported/Eigen/FFT>

#include "plumb/core/error.h"

namespace plumb::signal {
namespace {

/// The usable chunks (at least 3 samples with a detrend, else 2), each centred on its own
/// mean (and line) when asked for: one chunk at a time, in a buffer that stays in cache,
/// rather than every centred sample stored at once (hours of data are tens of MB per axis).
class CentredChunks {
 public:
  CentredChunks(const std::vector<AxisView>& chunks, bool detrend)
      : chunks_(chunks), detrend_(detrend) {
    for (std::size_t c = 0; c < chunks.size(); ++c) {
      const auto n = static_cast<std::size_t>(chunks[c].size());
      if (n < (detrend ? 3u : 2u)) continue;
      usable_.push_back(c);
      samples_ += n;
      longest_ = std::max(longest_, n);
    }
  }
  std::size_t count() const { return usable_.size(); }
  std::size_t samples() const { return samples_; }
  std::size_t longest() const { return longest_; }
  std::size_t length(std::size_t c) const {
    return static_cast<std::size_t>(chunks_[usable_[c]].size());
  }

  /// Usable chunk c about its mean (and least-squares line against the sample index).
  const std::vector<double>& Centred(std::size_t c) const {
    const AxisView& chunk = chunks_[usable_[c]];
    const auto n = static_cast<std::size_t>(chunk.size());
    const double mean = chunk.cast<double>().mean();
    const double mid = 0.5 * static_cast<double>(n - 1);
    double slope = 0.0;
    if (detrend_) {
      double sxy = 0.0, sxx = 0.0;
      for (Eigen::Index i = 0; i < chunk.size(); ++i) {
        const double x = static_cast<double>(i) - mid;
        sxy += x * (static_cast<double>(chunk[i]) - mean);
        sxx += x * x;
      }
      slope = sxy / sxx;
    }
    buffer_.resize(n);
    for (Eigen::Index i = 0; i < chunk.size(); ++i) {
      buffer_[static_cast<std::size_t>(i)] =
          static_cast<double>(chunk[i]) - mean - slope * (static_cast<double>(i) - mid);
    }
    return buffer_;
  }

 private:
  const std::vector<AxisView>& chunks_;
  bool detrend_;
  std::vector<std::size_t> usable_;
  std::size_t samples_ = 0, longest_ = 0;
  mutable std::vector<double> buffer_;
};

/// Lags computed per pass over the data: the window usually stops within a few lags, and
/// one pass for several keeps the samples in cache once instead of streaming them per lag.
constexpr std::size_t kLagsPerPass = 8;

/// Each lag's pooled sum of products divided by its number of pairs (the first `count` of
/// them), NaN for a lag without pairs (no chunk is longer than it).
template <typename Sums, typename Pairs>
Sums PerPair(Sums sum, const Pairs& pairs, std::size_t count) {
  for (std::size_t j = 0; j < count; ++j) {
    sum[j] = pairs[j] == 0 ? std::numeric_limits<double>::quiet_NaN()
                           : sum[j] / static_cast<double>(pairs[j]);
  }
  return sum;
}

/// Autocovariances at lags first .. first + count - 1 pooled over chunks (each divided by its
/// number of pairs), NaN for a lag no chunk is longer than. One pass over each chunk; each
/// lag's sum is accumulated in the same order as a pass of its own would. With `sum_sq`, the
/// squares of every centred sample are added to it too, in order.
std::array<double, kLagsPerPass> PooledAutocovariances(const CentredChunks& data,
                                                       std::size_t first, std::size_t count,
                                                       double* sum_sq = nullptr) {
  std::array<double, kLagsPerPass> sum{};
  std::array<std::size_t, kLagsPerPass> pairs{};
  for (std::size_t c = 0; c < data.count(); ++c) {
    const std::size_t n = data.length(c);
    if (n <= first && sum_sq == nullptr) continue;
    const std::vector<double>& centred = data.Centred(c);
    const double* y = centred.data();
    if (sum_sq != nullptr) {
      for (double v : centred) *sum_sq += v * v;
    }
    if (n <= first) continue;
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
  return PerPair(sum, pairs, count);
}

/// Lags summed from direct passes (PooledAutocovariances); a window that runs past them takes
/// every further lag from the chunks' spectra at once (PooledAutocovariancesFft): O(N M) for
/// M lags against O(N log N), which matters when the window runs to thousands of lags (an
/// axis that drifts within its still periods).
constexpr std::size_t kDirectLags = 64;
static_assert(kDirectLags % kLagsPerPass == 0, "the direct passes end at the last direct lag");

/// Autocovariances at lags first .. last pooled over chunks as PooledAutocovariances gives
/// them (each lag's sum of products over every chunk, divided by its number of pairs; NaN for
/// a lag no chunk is longer than), from each chunk's power spectrum: the chunk zero-padded to
/// a power of two of at least its length + last (no wrap-around up to lag last), transformed,
/// squared in magnitude and transformed back gives sum_i y_i y_{i+k} for every k at once. The
/// sums equal the direct ones to rounding (about 1e-15 of the chunk's sum of squares).
std::vector<double> PooledAutocovariancesFft(const CentredChunks& data, std::size_t first,
                                             std::size_t last) {
  const std::size_t count = last + 1 - first;
  std::vector<double> sum(count, 0.0);
  std::vector<std::size_t> pairs(count, 0);
  Eigen::FFT<double> fft;
  std::vector<double> padded, products;
  std::vector<std::complex<double>> spectrum;
  for (std::size_t c = 0; c < data.count(); ++c) {
    const std::size_t n = data.length(c);
    if (n <= first) continue;
    const std::size_t reach = std::min(last, n - 1);  // the last lag with a pair in this chunk
    std::size_t size = 1;
    while (size < n + reach) size *= 2;
    const std::vector<double>& centred = data.Centred(c);
    padded.assign(size, 0.0);
    std::copy(centred.begin(), centred.end(), padded.begin());
    fft.fwd(spectrum, padded);
    for (std::complex<double>& z : spectrum) z = std::norm(z);
    fft.inv(products, spectrum);
    for (std::size_t k = first; k <= reach; ++k) {
      sum[k - first] += products[k];
      pairs[k - first] += n - k;
    }
  }
  return PerPair(std::move(sum), pairs, count);
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
  const CentredChunks data(chunks, options.detrend);
  if (data.count() == 0) {
    throw Error(std::string("correlation time: no chunk has at least ") +
                (options.detrend ? "3" : "2") + " samples (" +
                std::to_string(chunks.size()) + " chunks given)");
  }
  CorrelationTime out;
  out.chunks = data.count();
  out.samples = data.samples();
  // The first pass gives the variance and the first lags' covariances together.
  const std::size_t last_lag = std::min(options.max_lag, data.longest() / 2);
  double sum_sq = 0.0;
  std::array<double, kLagsPerPass> covariances =
      PooledAutocovariances(data, 1, std::min(kLagsPerPass, last_lag), &sum_sq);
  const std::size_t fitted = (options.detrend ? 2 : 1) * out.chunks;  // means (and slopes)
  out.variance = sum_sq / static_cast<double>(out.samples - fitted);
  const double c0 = sum_sq / static_cast<double>(out.samples);
  if (!(c0 > 0.0) || !std::isfinite(c0)) {
    throw InsufficientDataError(
        "the samples have " + std::string(std::isfinite(c0) ? "no variance" : "a non-finite variance") +
        " about their line in every still segment (the same value throughout, or a straight "
        "line): there is no sensor noise to weigh the fit by, and a real IMU's output at rest "
        "varies by a few counts; check that the file's columns are the sensor's");
  }

  double tau = 1.0;
  double tau_sq = 1.0;
  std::vector<double> far;  // the lags past kDirectLags, from the spectra
  for (std::size_t k = 1; k <= last_lag; ++k) {
    double covariance = 0.0;
    if (k > kDirectLags) {
      if (far.empty()) far = PooledAutocovariancesFft(data, k, last_lag);
      covariance = far[k - kDirectLags - 1];
    } else {
      const std::size_t slot = (k - 1) % kLagsPerPass;
      if (slot == 0 && k > 1) {
        covariances = PooledAutocovariances(data, k, std::min(kLagsPerPass, last_lag + 1 - k));
      }
      covariance = covariances[slot];
    }
    const double rho = covariance / c0;
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

CorrelationTime EstimateCorrelationTime(const ImuSeries& series,
                                        const std::vector<StillSegment>& segments, Sensor sensor,
                                        int axis, const CorrelationTimeOptions& options) {
  std::vector<AxisView> chunks;
  chunks.reserve(segments.size());
  for (const StillSegment& segment : segments) {
    chunks.push_back(ViewAxis(series, sensor, axis, segment.begin, segment.end));
  }
  try {
    return EstimateCorrelationTime(chunks, options);
  } catch (const InsufficientDataError& e) {
    throw InsufficientDataError(std::string(SensorName(sensor)) + " " + "xyz"[axis] + ": " +
                                e.what());
  }
}

std::vector<CorrelationTime> EstimateCorrelationTimes(const ImuSeries& series,
                                                      const std::vector<StillSegment>& segments,
                                                      const std::vector<Sensor>& sensors,
                                                      const CorrelationTimeOptions& options,
                                                      const JobRunner& run_jobs) {
  const int count = 3 * static_cast<int>(sensors.size());
  std::vector<CorrelationTime> out(static_cast<std::size_t>(count));
  std::vector<std::exception_ptr> errors(out.size());
  RunJobs(run_jobs, count, [&](int job) {
    const auto k = static_cast<std::size_t>(job);
    try {
      out[k] = EstimateCorrelationTime(series, segments, sensors[k / 3], job % 3, options);
    } catch (...) {
      errors[k] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return out;
}

std::array<CorrelationTime, 3> EstimateCorrelationTime(const ImuSeries& series,
                                                       const std::vector<StillSegment>& segments,
                                                       Sensor sensor,
                                                       const CorrelationTimeOptions& options) {
  std::array<CorrelationTime, 3> out;
  for (int axis = 0; axis < 3; ++axis) {
    out[static_cast<std::size_t>(axis)] =
        EstimateCorrelationTime(series, segments, sensor, axis, options);
  }
  return out;
}

double VarianceOfMean(double variance, double tau_int, std::size_t count) {
  if (count == 0) return std::numeric_limits<double>::infinity();
  return variance * tau_int / static_cast<double>(count);
}

}  // namespace plumb::signal

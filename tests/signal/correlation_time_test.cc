#include "plumb/signal/correlation_time.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "plumb/core/error.h"
#include "noise.h"

namespace plumb::signal {
namespace {

/// Ten still chunks of 20000 samples of AR(1) noise with the same phi, different seeds and
/// different offsets (each chunk is centred on its own mean).
struct PooledAr1 {
  std::vector<std::vector<float>> data;
  std::vector<AxisView> views;

  PooledAr1(double phi, double sigma_e) {
    for (int c = 0; c < 10; ++c) {
      data.push_back(testing::Ar1Noise(100 + static_cast<std::uint64_t>(c), 20000, phi, sigma_e,
                                       0.3 * c - 1.0));
    }
    for (const auto& d : data) views.push_back(ViewContiguous(d.data(), d.size()));
  }
};

TEST(CorrelationTime, WhiteNoiseIsOne) {
  const PooledAr1 noise(0.0, 0.02);
  const CorrelationTime ct = EstimateCorrelationTime(noise.views);
  EXPECT_TRUE(ct.converged);
  EXPECT_EQ(ct.chunks, 10U);
  EXPECT_EQ(ct.samples, 200000U);
  EXPECT_NEAR(ct.tau_int, 1.0, 0.05);
  EXPECT_NEAR(ct.tau_sq, 1.0, 0.01);
  EXPECT_NEAR(std::sqrt(ct.variance), 0.02, 0.0003);
}

TEST(CorrelationTime, DetrendIgnoresADriftInsideEachChunk) {
  // White noise of sigma 0.02 plus a ramp of 0.2 over each chunk (a board warming during the
  // hold): about the chunk's mean the ramp adds 0.2 / sqrt(12) = 0.058 to the scatter, about
  // its line nothing; white noise alone gives the same either way.
  PooledAr1 noise(0.0, 0.02);
  for (auto& d : noise.data) {
    for (std::size_t i = 0; i < d.size(); ++i) {
      d[i] += static_cast<float>(0.2 * static_cast<double>(i) / static_cast<double>(d.size()));
    }
  }
  CorrelationTimeOptions line;
  line.detrend = true;
  const CorrelationTime about_mean = EstimateCorrelationTime(noise.views);
  const CorrelationTime about_line = EstimateCorrelationTime(noise.views, line);
  EXPECT_GT(std::sqrt(about_mean.variance), 0.05);
  EXPECT_NEAR(std::sqrt(about_line.variance), 0.02, 0.0003);
  EXPECT_NEAR(about_line.tau_int, 1.0, 0.05);
  const PooledAr1 white(0.0, 0.02);
  EXPECT_NEAR(EstimateCorrelationTime(white.views, line).variance,
              EstimateCorrelationTime(white.views).variance, 1e-3 * 0.02 * 0.02);
}

TEST(CorrelationTime, Ar1MatchesTheory) {
  for (double phi : {0.5, 0.8, 0.9}) {
    const PooledAr1 noise(phi, 0.01);
    const CorrelationTime ct = EstimateCorrelationTime(noise.views);
    const double tau = (1.0 + phi) / (1.0 - phi);
    const double tau_sq = (1.0 + phi * phi) / (1.0 - phi * phi);
    // Sokal: var(tau_hat) / tau^2 ~ 2 (2 M + 1) / N with M ~ 5 tau; allow 4 standard errors.
    const double relative_tolerance = 4.0 * std::sqrt(2.0 * (10.0 * tau + 1.0) / 200000.0);
    EXPECT_TRUE(ct.converged) << "phi " << phi;
    EXPECT_NEAR(ct.tau_int / tau, 1.0, relative_tolerance) << "phi " << phi << " tau_int "
                                                           << ct.tau_int;
    EXPECT_NEAR(ct.tau_sq / tau_sq, 1.0, relative_tolerance) << "phi " << phi << " tau_sq "
                                                             << ct.tau_sq;
    EXPECT_NEAR(ct.variance * (1.0 - phi * phi) / (0.01 * 0.01), 1.0, 0.05) << "phi " << phi;
  }
}

TEST(CorrelationTime, PredictsTheScatterOfChunkMeans) {
  // 400 chunks of 500 samples of AR(1) with phi = 0.8: the scatter of their means must match
  // sigma^2 tau_int / n, not sigma^2 / n (which would be 9 times too small).
  const double phi = 0.8;
  const std::vector<float> x = testing::Ar1Noise(7, 200000, phi, 0.01);
  std::vector<AxisView> chunks;
  std::vector<double> means;
  for (std::size_t c = 0; c < 400; ++c) {
    chunks.push_back(ViewContiguous(x.data() + 500 * c, 500));
    means.push_back(chunks.back().cast<double>().mean());
  }
  const CorrelationTime ct = EstimateCorrelationTime(chunks);
  double mean_of_means = 0.0;
  for (double m : means) mean_of_means += m;
  mean_of_means /= static_cast<double>(means.size());
  double scatter = 0.0;
  for (double m : means) scatter += (m - mean_of_means) * (m - mean_of_means);
  scatter /= static_cast<double>(means.size() - 1);
  const double predicted = VarianceOfMean(ct.variance, ct.tau_int, 500);
  // The scatter of 400 means has a relative standard error of about sqrt(2 / 400) = 7%.
  EXPECT_NEAR(scatter / predicted, 1.0, 0.25);
  EXPECT_GT(scatter / VarianceOfMean(ct.variance, 1.0, 500), 5.0);
}

TEST(CorrelationTime, TriadsOverStillSegments) {
  const std::vector<float> x = testing::Ar1Noise(3, 30000, 0.6, 0.01, 9.8);
  const std::vector<float> y = testing::Ar1Noise(4, 30000, 0.0, 0.01);
  ImuSeries s;
  for (std::size_t i = 0; i < x.size(); ++i) {
    s.t_s.push_back(0.01 * static_cast<double>(i));
    s.acc.emplace_back(x[i], y[i], x[i] + y[i]);
  }
  const auto ct = EstimateCorrelationTime(s, {StillSegment{0, 10000}, StillSegment{12000, 30000}},
                                          Sensor::kAccel);
  EXPECT_NEAR(ct[0].tau_int, 4.0, 0.4);
  EXPECT_NEAR(ct[1].tau_int, 1.0, 0.1);
  EXPECT_EQ(ct[2].samples, 28000U);
  EXPECT_THROW(EstimateCorrelationTime(s, {StillSegment{0, 10}}, Sensor::kGyro), Error);
}

/// Runs the jobs last to first, half of them on a second thread.
void ReverseOnTwoThreads(int count, const std::function<void(int)>& job) {
  std::thread other([&] {
    for (int k = count - 1; k >= 0; k -= 2) job(k);
  });
  for (int k = count - 2; k >= 0; k -= 2) job(k);
  other.join();
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(CorrelationTime, EverySensorsAxesAsJobsInTheirOrder) {
  ImuSeries s;
  const std::vector<float> a = testing::Ar1Noise(7, 20000, 0.5, 0.01, 9.8);
  const std::vector<float> b = testing::Ar1Noise(8, 20000, 0.0, 0.001);
  for (std::size_t i = 0; i < a.size(); ++i) {
    s.t_s.push_back(0.01 * static_cast<double>(i));
    s.acc.emplace_back(a[i], b[i], a[i] - b[i]);
    s.gyr.emplace_back(b[i], 2.0F * a[i], a[i] + b[i]);
  }
  const std::vector<StillSegment> still{StillSegment{0, 8000}, StillSegment{9000, 20000}};
  const std::vector<Sensor> both{Sensor::kAccel, Sensor::kGyro};
  const std::vector<CorrelationTime> jobs =
      EstimateCorrelationTimes(s, still, both, {}, ReverseOnTwoThreads);
  ASSERT_EQ(jobs.size(), 6U);
  for (int k = 0; k < 6; ++k) {
    const CorrelationTime one = EstimateCorrelationTime(s, still, both[k / 3], k % 3);
    EXPECT_TRUE(SameBits(jobs[k].tau_int, one.tau_int)) << "axis " << k;
    EXPECT_TRUE(SameBits(jobs[k].variance, one.variance)) << "axis " << k;
    EXPECT_EQ(jobs[k].window, one.window) << "axis " << k;
  }
  // An axis's error is thrown after the others have run: the first in axis order (the
  // accelerometer's y, constant here: zero variance; the gyroscope's x, not a number, fails
  // too, with another message).
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.acc[i].y() = 1.0F;
    s.gyr[i].x() = std::nanf("");
  }
  try {
    EstimateCorrelationTimes(s, still, both, {}, ReverseOnTwoThreads);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string accel_error = [&] {
      try {
        EstimateCorrelationTime(s, still, Sensor::kAccel, 1);
      } catch (const Error& first) {
        return std::string(first.what());
      }
      return std::string();
    }();
    const std::string gyro_error = [&] {
      try {
        EstimateCorrelationTime(s, still, Sensor::kGyro, 0);
      } catch (const Error& other) {
        return std::string(other.what());
      }
      return std::string();
    }();
    EXPECT_FALSE(accel_error.empty());
    EXPECT_FALSE(gyro_error.empty());
    EXPECT_NE(accel_error, gyro_error);
    EXPECT_EQ(std::string(e.what()), accel_error);
  }
}

TEST(CorrelationTime, RejectsUnusableInput) {
  const std::vector<float> constant(100, 1.0F);
  EXPECT_THROW(EstimateCorrelationTime({ViewContiguous(constant.data(), 100)}), Error);
  EXPECT_THROW(EstimateCorrelationTime({ViewContiguous(constant.data(), 1)}), Error);
  CorrelationTimeOptions bad;
  bad.sokal_c = 0.5;
  const std::vector<float> x = testing::Ar1Noise(5, 100, 0.0, 1.0);
  EXPECT_THROW(EstimateCorrelationTime({ViewContiguous(x.data(), 100)}, bad), Error);
}

TEST(CorrelationTime, MarksTheWindowNotReached) {
  CorrelationTimeOptions short_lags;
  short_lags.max_lag = 10;
  const std::vector<float> x = testing::Ar1Noise(6, 20000, 0.95, 0.01);
  const CorrelationTime ct = EstimateCorrelationTime({ViewContiguous(x.data(), x.size())},
                                                     short_lags);
  EXPECT_FALSE(ct.converged);
  EXPECT_EQ(ct.window, 10U);
}

/// The estimator by its definition (correlation_time.h), one lag at a time: each chunk
/// centred on its mean, C_k = sum over chunks of sum_i y_i y_{i+k} / (pairs at lag k), rho_k =
/// C_k / C_0 with C_0 = sum y^2 / N, summed until M >= c tau_int(M) or the last lag.
CorrelationTime ByDefinition(const std::vector<std::vector<float>>& chunks, double sokal_c,
                             std::size_t max_lag) {
  std::vector<std::vector<double>> centred;
  std::size_t samples = 0, longest = 0;
  double sum_sq = 0.0;
  for (const std::vector<float>& chunk : chunks) {
    double mean = 0.0;
    for (float v : chunk) mean += v;
    mean /= static_cast<double>(chunk.size());
    std::vector<double> y;
    for (float v : chunk) y.push_back(v - mean);
    for (double v : y) sum_sq += v * v;
    samples += y.size();
    longest = std::max(longest, y.size());
    centred.push_back(y);
  }
  const double c0 = sum_sq / static_cast<double>(samples);
  CorrelationTime out;
  double tau = 1.0, tau_sq = 1.0;
  for (std::size_t k = 1; k <= std::min(max_lag, longest / 2); ++k) {
    double sum = 0.0;
    std::size_t pairs = 0;
    for (const std::vector<double>& y : centred) {
      for (std::size_t i = 0; i + k < y.size(); ++i) sum += y[i] * y[i + k];
      pairs += y.size() > k ? y.size() - k : 0;
    }
    const double rho = sum / static_cast<double>(pairs) / c0;
    tau += 2.0 * rho;
    tau_sq += 2.0 * rho * rho;
    out.window = k;
    if (static_cast<double>(k) >= sokal_c * tau) {
      out.converged = true;
      break;
    }
  }
  out.tau_int = tau;
  out.tau_sq = tau_sq;
  return out;
}

// A window of about a thousand lags: the lags past the first ones come from the chunks'
// spectra (correlation_time.cc); they must give what the definition gives, lag by lag, to
// rounding, whether the window closes or runs to max_lag.
TEST(CorrelationTime, LongWindowsEqualTheDefinition) {
  std::vector<std::vector<float>> data;
  for (int c = 0; c < 4; ++c) {
    data.push_back(testing::Ar1Noise(200 + static_cast<std::uint64_t>(c),
                                     5000 + 700 * static_cast<std::size_t>(c), 0.99, 0.01,
                                     0.2 * c));
  }
  std::vector<AxisView> views;
  for (const auto& d : data) views.push_back(ViewContiguous(d.data(), d.size()));
  for (std::size_t max_lag : {std::size_t{5000}, std::size_t{300}}) {
    CorrelationTimeOptions options;
    options.max_lag = max_lag;
    const CorrelationTime ct = EstimateCorrelationTime(views, options);
    const CorrelationTime expected = ByDefinition(data, options.sokal_c, max_lag);
    EXPECT_GT(ct.window, 64U) << "max_lag " << max_lag;  // past the direct lags
    EXPECT_EQ(ct.window, expected.window) << "max_lag " << max_lag;
    EXPECT_EQ(ct.converged, expected.converged) << "max_lag " << max_lag;
    EXPECT_NEAR(ct.tau_int / expected.tau_int, 1.0, 1e-9) << "max_lag " << max_lag;
    EXPECT_NEAR(ct.tau_sq / expected.tau_sq, 1.0, 1e-9) << "max_lag " << max_lag;
  }
}

}  // namespace
}  // namespace plumb::signal

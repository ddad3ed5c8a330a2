#include "plumb/signal/allan.h"

#include <cmath>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "plumb/core/error.h"
#include "noise.h"

namespace plumb::signal {
namespace {

TEST(AllanDeviation, WhiteNoiseFallsAsOneOverRootTau) {
  const double sigma = 0.05;
  const double dt_s = 0.01;
  const std::vector<float> x = testing::Ar1Noise(21, 400000, 0.0, sigma, 9.8);
  const AllanDeviation ad = OverlappingAllanDeviation(ViewContiguous(x.data(), x.size()), dt_s);
  ASSERT_GT(ad.tau_s.size(), 40U);  // 10 per decade over more than 5 decades
  EXPECT_EQ(ad.cluster_size.front(), 1U);
  EXPECT_LE(ad.cluster_size.back(), 200000U);  // the last of 10^(j/10) up to n / 2
  EXPECT_GT(ad.cluster_size.back(), 150000U);
  EXPECT_NEAR(ad.tau_s.front(), dt_s, 1e-15);
  for (std::size_t j = 0; j < ad.tau_s.size(); ++j) {
    const double m = static_cast<double>(ad.cluster_size[j]);
    if (m > 1000.0) break;  // beyond that fewer than 400 independent clusters
    EXPECT_NEAR(ad.adev[j] / (sigma / std::sqrt(m)), 1.0, 0.08) << "m " << m;
  }
}

TEST(AllanDeviation, RandomWalkRisesAsRootTauOverThree) {
  const double q = 1e-3;
  const std::vector<float> x = testing::RandomWalk(22, 400000, q);
  AllanOptions options;
  options.cluster_sizes = {1000, 10, 100};  // sorted on output
  const AllanDeviation ad = OverlappingAllanDeviation(ViewContiguous(x.data(), x.size()), 0.001,
                                                      options);
  ASSERT_EQ(ad.cluster_size.size(), 3U);
  EXPECT_EQ(ad.cluster_size[0], 10U);
  EXPECT_NEAR(ad.tau_s[2], 1.0, 1e-12);
  for (std::size_t j = 0; j < 3; ++j) {
    const double m = static_cast<double>(ad.cluster_size[j]);
    // The m = 1 term q^2 / 2 adds white-like noise; it is negligible from m = 10 on.
    EXPECT_NEAR(ad.adev[j] / (q * std::sqrt(m / 3.0)), 1.0, 0.12) << "m " << m;
    EXPECT_EQ(ad.terms[j], 400001U - 2 * ad.cluster_size[j]);
  }
}

// ---- NIST SP 1065's 1000-point test sequence ---------------------------------------------------

/// The test data of NIST SP 1065 (pp. 107-108) and of Riley's "The Calculation of Time Domain
/// Frequency Stability" (Table III), which Allan-deviation libraries validate against:
/// n_0 = 1234567890, n_{i+1} = 16807 n_i mod (2^31 - 1), fractional frequency
/// x_i = n_i / (2^31 - 1), i = 0..999, tau_0 = 1 s.
std::vector<float> Nist1000() {
  std::vector<std::uint64_t> n(1000);
  n[0] = 1234567890;
  for (std::size_t i = 1; i < n.size(); ++i) n[i] = (16807 * n[i - 1]) % 2147483647;
  std::vector<float> x(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    x[i] = static_cast<float>(static_cast<double>(n[i]) / 2147483647.0);
  }
  return x;
}

TEST(AllanDeviation, Nist1000PointSequenceGivesThePublishedValues) {
  std::vector<std::uint64_t> first = {1234567890};
  for (int i = 0; i < 3; ++i) first.push_back((16807 * first.back()) % 2147483647);
  // The generator's first numbers as published.
  EXPECT_EQ(first[1], 395529916U);
  EXPECT_EQ(first[2], 1209410747U);
  EXPECT_EQ(first[3], 633705974U);
  const std::vector<float> x = Nist1000();
  AllanOptions options;
  options.cluster_sizes = {1, 10, 100};
  const AllanDeviation ad =
      OverlappingAllanDeviation(ViewContiguous(x.data(), x.size()), 1.0, options);
  ASSERT_EQ(ad.adev.size(), 3U);
  // Overlapping ADEV at tau = 1, 10, 100 s, 7 significant digits: agree to half a unit of the
  // last one.
  EXPECT_NEAR(ad.adev[0], 2.922319e-01, 0.5e-7);
  EXPECT_NEAR(ad.adev[1], 9.159953e-02, 0.5e-8);
  EXPECT_NEAR(ad.adev[2], 3.241343e-02, 0.5e-8);
  EXPECT_EQ(ad.terms[0], 999U);  // N - 2m with N = 1001 phase points
  EXPECT_EQ(ad.terms[2], 801U);
}

// ---- Equivalent degrees of freedom and intervals -----------------------------------------------

TEST(AllanEdf, WhiteFmAtOneSampleMatchesTheFirstDifferences) {
  // m = 1: AVAR is the mean of (x_{k+1} - x_k)^2 / 2 over n - 1 differences that correlate -1/2
  // with their neighbours; their EDF is 2 (n - 1)^2 / (3n - 4), about 2n / 3.
  const std::size_t n = 10000;
  const double exact = 2.0 * (n - 1.0) * (n - 1.0) / (3.0 * n - 4.0);
  EXPECT_NEAR(OverlappingAllanEdf(n, 1, PowerLawNoise::kWhiteFrequency) / exact, 1.0, 1e-3);
}

TEST(AllanEdf, OneSecondDifferenceHasOneDegreeOfFreedom) {
  for (PowerLawNoise noise :
       {PowerLawNoise::kWhitePhase, PowerLawNoise::kFlickerPhase, PowerLawNoise::kWhiteFrequency,
        PowerLawNoise::kFlickerFrequency, PowerLawNoise::kRandomWalkFrequency}) {
    const double edf = OverlappingAllanEdf(1000, 500, noise);
    EXPECT_GE(edf, 1.0) << PowerLawNoiseName(noise);
    EXPECT_LT(edf, 1.1) << PowerLawNoiseName(noise);
    // Fewer degrees of freedom for longer clusters.
    EXPECT_GT(OverlappingAllanEdf(1000, 10, noise), OverlappingAllanEdf(1000, 100, noise));
  }
  // Flicker FM at m = 1 keeps most of the samples' degrees of freedom (2 (N-2)^2 / (2.3 N - 4.9)).
  EXPECT_NEAR(OverlappingAllanEdf(1000, 1, PowerLawNoise::kFlickerFrequency), 868.81, 0.01);
  EXPECT_THROW(OverlappingAllanEdf(1000, 0, PowerLawNoise::kWhiteFrequency), Error);
  EXPECT_THROW(OverlappingAllanEdf(1000, 501, PowerLawNoise::kWhiteFrequency), Error);
}

TEST(AllanEdf, PooledRecordsAddTheirDegreesOfFreedom) {
  const auto wfm = PowerLawNoise::kWhiteFrequency;
  const double one = OverlappingAllanEdf(2000, 50, wfm);
  EXPECT_DOUBLE_EQ(PooledAllanEdf({2000}, 50, wfm), one);
  EXPECT_NEAR(PooledAllanEdf({2000, 2000, 2000}, 50, wfm), 3.0 * one, 1e-9 * one);
  // A record shorter than two clusters adds nothing.
  EXPECT_DOUBLE_EQ(PooledAllanEdf({2000, 99}, 50, wfm), one);
  EXPECT_THROW(PooledAllanEdf({99}, 50, wfm), Error);
}

TEST(AllanInterval, UsesTheExactChiSquareQuantiles) {
  // edf = 4, 90 %: chi2_0.05(4) = 0.7107230, chi2_0.95(4) = 9.487729 (R: qchisq).
  const auto [lower, upper] = AllanInterval(1.0, 4.0, 0.9);
  EXPECT_NEAR(lower, std::sqrt(4.0 / 9.487729), 1e-6);
  EXPECT_NEAR(upper, std::sqrt(4.0 / 0.7107230), 1e-6);
  EXPECT_THROW(AllanInterval(1.0, 0.0, 0.9), Error);
  EXPECT_THROW(AllanInterval(1.0, 4.0, 1.0), Error);
}

/// Fraction of `records` simulated records whose interval at cluster size m holds `truth`.
template <typename Make>
double Coverage(int records, std::size_t m, PowerLawNoise noise, double truth, Make make) {
  int inside = 0;
  for (int r = 0; r < records; ++r) {
    const std::vector<float> x = make(r);
    AllanOptions options;
    options.cluster_sizes = {m};
    options.noise = noise;
    const AllanDeviation ad =
        OverlappingAllanDeviation(ViewContiguous(x.data(), x.size()), 1.0, options);
    inside += ad.adev_lower[0] <= truth && truth <= ad.adev_upper[0] ? 1 : 0;
  }
  return static_cast<double>(inside) / records;
}

TEST(AllanInterval, OneSigmaIntervalsHoldTheTruthTwoTimesInThree) {
  // 400 records: the fraction is 0.683 +- 0.023 (one binomial sigma) when the EDF is right.
  const double sigma = 1.0, q = 1.0;
  const auto white = [&](int first_seed) {
    return [=](int r) { return testing::Ar1Noise(first_seed + r, 1000, 0.0, sigma); };
  };
  const double white10 = Coverage(400, 10, PowerLawNoise::kWhiteFrequency,
                                  sigma / std::sqrt(10.0), white(1000));
  EXPECT_NEAR(white10, kOneSigmaConfidence, 0.07);
  const double white100 =
      Coverage(400, 100, PowerLawNoise::kWhiteFrequency, sigma / 10.0, white(2000));
  EXPECT_NEAR(white100, kOneSigmaConfidence, 0.07);
  // A discrete random walk: AVAR = q^2 (2 m^2 + 1) / (6 m); few degrees of freedom at m = 100.
  const double m = 100.0;
  const double walk = Coverage(400, 100, PowerLawNoise::kRandomWalkFrequency,
                               q * std::sqrt((2.0 * m * m + 1.0) / (6.0 * m)),
                               [&](int r) { return testing::RandomWalk(3000 + r, 1000, q); });
  EXPECT_NEAR(walk, kOneSigmaConfidence, 0.07);
}

// ---- Pooled records ----------------------------------------------------------------------------

TEST(AllanDeviation, PooledRecordsShareTheirSecondDifferences) {
  const std::vector<float> a = testing::Ar1Noise(31, 3000, 0.0, 1.0, 2.0);
  const std::vector<float> b = testing::Ar1Noise(32, 400, 0.0, 1.0, -5.0);  // another offset
  AllanOptions options;
  options.cluster_sizes = {10, 150, 1000};
  const AxisView va = ViewContiguous(a.data(), a.size());
  const AxisView vb = ViewContiguous(b.data(), b.size());
  const AllanDeviation pooled = PooledAllanDeviation({va, vb}, 0.5, options);
  const AllanDeviation only_a = OverlappingAllanDeviation(va, 0.5, options);
  AllanOptions short_options;
  short_options.cluster_sizes = {10, 150};
  const AllanDeviation only_b = OverlappingAllanDeviation(vb, 0.5, short_options);
  ASSERT_EQ(pooled.adev.size(), 3U);
  EXPECT_EQ(pooled.record_sizes, (std::vector<std::size_t>{3000, 400}));
  for (std::size_t j = 0; j < 2; ++j) {
    // Sums of squared differences add; the offsets do not matter.
    const double sum = only_a.adev[j] * only_a.adev[j] * only_a.terms[j] +
                       only_b.adev[j] * only_b.adev[j] * only_b.terms[j];
    EXPECT_EQ(pooled.terms[j], only_a.terms[j] + only_b.terms[j]);
    EXPECT_NEAR(pooled.adev[j], std::sqrt(sum / pooled.terms[j]), 1e-12);
    EXPECT_GT(pooled.edf[j], only_a.edf[j]);
  }
  // m = 1000 does not fit in b: a alone.
  EXPECT_EQ(pooled.terms[2], only_a.terms[2]);
  EXPECT_DOUBLE_EQ(pooled.adev[2], only_a.adev[2]);
  // Automatic cluster sizes reach half the longest record.
  const AllanDeviation automatic = PooledAllanDeviation({vb, va}, 0.5);
  EXPECT_LE(automatic.cluster_size.back(), 1500U);
  EXPECT_GT(automatic.cluster_size.back(), 1000U);
}

TEST(AllanDeviation, RejectsBadArguments) {
  const std::vector<float> x = testing::Ar1Noise(23, 100, 0.0, 1.0);
  const AxisView view = ViewContiguous(x.data(), x.size());
  EXPECT_THROW(OverlappingAllanDeviation(view, 0.0), Error);
  EXPECT_THROW(OverlappingAllanDeviation(ViewContiguous(x.data(), 1), 0.01), Error);
  AllanOptions too_long;
  too_long.cluster_sizes = {51};
  EXPECT_THROW(OverlappingAllanDeviation(view, 0.01, too_long), Error);
  AllanOptions zero;
  zero.cluster_sizes = {0};
  EXPECT_THROW(OverlappingAllanDeviation(view, 0.01, zero), Error);
  AllanOptions certain;
  certain.confidence = 1.0;
  EXPECT_THROW(OverlappingAllanDeviation(view, 0.01, certain), Error);
  EXPECT_THROW(PooledAllanDeviation({ViewContiguous(x.data(), 1)}, 0.01), Error);
}

}  // namespace
}  // namespace plumb::signal

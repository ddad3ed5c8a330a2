#include "plumb/signal/allan.h"

#include <cmath>

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
}

}  // namespace
}  // namespace plumb::signal

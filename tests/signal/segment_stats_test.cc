#include "plumb/signal/segment_stats.h"

#include <cmath>

#include <gtest/gtest.h>

#include "plumb/core/error.h"
#include "noise.h"

namespace plumb::signal {
namespace {

ImuSeries FourSamples() {
  ImuSeries s;
  s.t_s = {1.7e9, 1.7e9 + 0.01, 1.7e9 + 0.02, 1.7e9 + 0.03};
  s.acc = {Vec3f(1, 2, 3), Vec3f(3, 2, 3), Vec3f(5, 2, 4), Vec3f(7, 2, 4)};
  s.gyr = {Vec3f(0, 0, 1), Vec3f(0, 0, 1), Vec3f(0, 1, 1), Vec3f(0, 1, 1)};
  s.temp_c = {20.0F, 21.0F, 23.0F, 22.0F};
  return s;
}

TEST(SegmentStats, HandComputedValues) {
  const SegmentStats st = ComputeSegmentStats(FourSamples(), 0, 4);
  EXPECT_EQ(st.count, 4U);
  // Unix-epoch times: a double resolves 2.4e-7 s at 1.7e9 s.
  EXPECT_NEAR(st.t_mid_s - 1.7e9, 0.015, 1e-6);
  EXPECT_NEAR(st.t_end_s - st.t_begin_s, 0.03, 1e-6);
  EXPECT_TRUE(st.acc_mean.isApprox(Vec3(4, 2, 3.5)));
  // x: deviations -3 -1 1 3 -> 20 / 3; z: 4 * 0.25 / 3.
  EXPECT_NEAR(st.acc_std.x(), std::sqrt(20.0 / 3.0), 1e-12);
  EXPECT_NEAR(st.acc_std.y(), 0.0, 1e-12);
  EXPECT_NEAR(st.acc_std.z(), std::sqrt(1.0 / 3.0), 1e-12);
  ASSERT_TRUE(st.has_gyro);
  EXPECT_TRUE(st.gyr_mean.isApprox(Vec3(0, 0.5, 1)));
  EXPECT_NEAR(st.gyr_std.y(), std::sqrt(1.0 / 3.0), 1e-12);
  EXPECT_NEAR(st.temp_mean_c, 21.5, 1e-12);
  EXPECT_EQ(st.temp_min_c, 20.0);
  EXPECT_EQ(st.temp_max_c, 23.0);
}

TEST(SegmentStats, SubRangeWithoutGyroOrTemperature) {
  ImuSeries s = FourSamples();
  s.gyr.clear();
  s.temp_c.clear();
  const SegmentStats st = ComputeSegmentStats(s, StillSegment{2, 3});
  EXPECT_EQ(st.count, 1U);
  EXPECT_TRUE(st.acc_mean.isApprox(Vec3(5, 2, 4)));
  EXPECT_TRUE(st.acc_std.array().isNaN().all());
  EXPECT_FALSE(st.has_gyro);
  EXPECT_TRUE(st.gyr_mean.array().isNaN().all());
  EXPECT_TRUE(std::isnan(st.temp_mean_c));
}

TEST(SegmentStats, AccurateForSmallNoiseOnLargeOffset) {
  // 1e6 float samples of 9.8 + N(0, 1e-3): the double reference from the same floats.
  const std::vector<float> x = testing::Ar1Noise(11, 1000000, 0.0, 1e-3, 9.8);
  ImuSeries s;
  for (std::size_t i = 0; i < x.size(); ++i) {
    s.t_s.push_back(0.001 * static_cast<double>(i));
    s.acc.emplace_back(x[i], -x[i], 0.5F * x[i]);
  }
  double mean = 0.0;
  for (float v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double ss = 0.0;
  for (float v : x) ss += (v - mean) * (v - mean);
  const double sd = std::sqrt(ss / static_cast<double>(x.size() - 1));
  const SegmentStats st = ComputeSegmentStats(s, 0, s.size());
  EXPECT_NEAR(st.acc_mean.x(), mean, 1e-12);
  EXPECT_NEAR(st.acc_std.x() / sd, 1.0, 1e-9);
  EXPECT_NEAR(st.acc_std.z() / (0.5 * sd), 1.0, 1e-9);  // 0.5 * x is exact in float
}

TEST(SegmentStats, RejectsEmptyOrOutOfRange) {
  const ImuSeries s = FourSamples();
  EXPECT_THROW(ComputeSegmentStats(s, 2, 2), Error);
  EXPECT_THROW(ComputeSegmentStats(s, 3, 5), Error);
  ImuSeries broken = s;
  broken.gyr.pop_back();
  EXPECT_THROW(ComputeSegmentStats(broken, 0, 3), Error);
}

}  // namespace
}  // namespace plumb::signal

#include "plumb/core/imu_series.h"

#include <gtest/gtest.h>

namespace plumb {
namespace {

ImuSeries Series(std::initializer_list<double> times) {
  ImuSeries s;
  for (double t : times) {
    s.t_s.push_back(t);
    s.acc.emplace_back(0.f, 0.f, -9.8f);
  }
  return s;
}

TEST(ImuSeries, MedianIntervalIgnoresAGap) {
  EXPECT_DOUBLE_EQ(Series({0.0, 0.01, 0.02, 0.03, 5.0}).median_dt_s(), 0.01);
}

TEST(ImuSeries, DurationAndEmptiness) {
  const ImuSeries s = Series({10.0, 10.5, 12.0});
  EXPECT_DOUBLE_EQ(s.duration_s(), 2.0);
  EXPECT_FALSE(s.has_gyro());
  EXPECT_DOUBLE_EQ(ImuSeries().duration_s(), 0.0);
  EXPECT_DOUBLE_EQ(Series({1.0}).median_dt_s(), 0.0);
}

}  // namespace
}  // namespace plumb

#include "plumb/signal/chi_square.h"

#include <gtest/gtest.h>

#include "plumb/core/error.h"

namespace plumb::signal {
namespace {

TEST(NormalQuantile, MatchesTables) {
  EXPECT_NEAR(NormalQuantile(0.5), 0.0, 1e-12);
  EXPECT_NEAR(NormalQuantile(0.975), 1.959963984540054, 1e-10);
  EXPECT_NEAR(NormalQuantile(0.999), 3.090232306167813, 1e-10);
  EXPECT_NEAR(NormalQuantile(1e-6), -4.753424308817090, 1e-9);
}

TEST(ChiSquareQuantile, MatchesExactValues) {
  // R: qchisq. The 99 % point of chi^2(1) is 6.635 (a cube-root approximation printed 6.59).
  EXPECT_NEAR(ChiSquareQuantileExact(0.99, 1.0), 6.634897, 1e-6);
  EXPECT_NEAR(ChiSquareQuantileExact(0.999, 3.0), 16.26624, 1e-5);
  EXPECT_NEAR(ChiSquareQuantileExact(0.999, 100.0), 149.4493, 1e-4);
  EXPECT_NEAR(ChiSquareQuantileExact(0.5, 10.0), 9.341818, 1e-6);
  EXPECT_NEAR(ChiSquareQuantileExact(0.001, 30.0), 11.587951, 1e-6);
}

TEST(ChiSquareQuantile, RejectsBadArguments) {
  EXPECT_THROW(ChiSquareQuantileExact(1.0, 3.0), Error);
  EXPECT_THROW(ChiSquareQuantileExact(0.5, 0.0), Error);
  EXPECT_THROW(NormalQuantile(0.0), Error);
}

}  // namespace
}  // namespace plumb::signal

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

TEST(ChiSquareQuantile, WilsonHilfertyIsCloseToExactValues) {
  // Exact quantiles (R: qchisq) and the approximation's documented accuracy.
  EXPECT_NEAR(ChiSquareQuantile(0.999, 3.0), 16.26624, 0.02 * 16.26624);
  EXPECT_NEAR(ChiSquareQuantile(0.999, 100.0), 149.4493, 0.002 * 149.4493);
  EXPECT_NEAR(ChiSquareQuantile(0.5, 10.0), 9.341818, 0.002 * 9.341818);
  EXPECT_NEAR(ChiSquareQuantile(0.001, 30.0), 11.58790, 0.01 * 11.58790);
}

TEST(ChiSquareQuantile, RejectsBadArguments) {
  EXPECT_THROW(ChiSquareQuantile(1.0, 3.0), Error);
  EXPECT_THROW(ChiSquareQuantile(0.5, 0.0), Error);
  EXPECT_THROW(NormalQuantile(0.0), Error);
}

}  // namespace
}  // namespace plumb::signal

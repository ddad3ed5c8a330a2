// The second-order Butterworth high-pass of plumb/signal/high_pass.h.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/signal/high_pass.h"

namespace plumb::signal {
namespace {

// |H(e^{jw})| of a biquad at frequency f_hz for samples at rate_hz.
double Gain(const Biquad& f, double f_hz, double rate_hz) {
  const std::complex<double> z1 = std::polar(1.0, -2.0 * M_PI * f_hz / rate_hz);  // z^-1
  const std::complex<double> num = f.b0 + f.b1 * z1 + f.b2 * z1 * z1;
  const std::complex<double> den = 1.0 + f.a1 * z1 + f.a2 * z1 * z1;
  return std::abs(num / den);
}

TEST(HighPass, ButterworthGainIsMinus3DbAtCutoffZeroAtDcOneAtNyquist) {
  const Biquad f = ButterworthHighPass(0.5, 100.0);
  EXPECT_NEAR(Gain(f, 0.5, 100.0), 1.0 / std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(Gain(f, 0.0, 100.0), 0.0, 1e-12);
  EXPECT_NEAR(Gain(f, 50.0, 100.0), 1.0, 1e-12);
  // Maximally flat: at 10 fc the gain of a 2nd-order Butterworth is 1/sqrt(1 + 1e-4).
  EXPECT_NEAR(Gain(f, 5.0, 100.0), 1.0 / std::sqrt(1.0 + 1e-4), 2e-4);
}

TEST(HighPass, MeanOfFilteredConstantIsNearZero) {
  // A minute of a constant 9.8 at 100 Hz from a zero state: the step response sums to zero
  // (double zero at DC), so the mean of the output is far below the constant.
  const std::vector<double> x(6000, 9.8);
  const std::vector<double> y = FilterForward(ButterworthHighPass(0.5, 100.0), x);
  double sum = 0.0;
  for (double v : y) sum += v;
  EXPECT_LT(std::abs(sum / y.size()), 1e-9);
  EXPECT_NEAR(y.front(), 9.8 * ButterworthHighPass(0.5, 100.0).b0, 1e-12);
}

TEST(HighPass, RejectsCutoffOutsideTheBand) {
  EXPECT_THROW(ButterworthHighPass(0.0, 100.0), Error);
  EXPECT_THROW(ButterworthHighPass(50.0, 100.0), Error);
  EXPECT_THROW(ButterworthHighPass(NAN, 100.0), Error);
}

}  // namespace
}  // namespace plumb::signal

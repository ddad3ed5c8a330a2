// plumb/signal/high_pass.h — a second-order Butterworth high-pass filter (one biquad).
//
// Design: the analog Butterworth high-pass H(s) = s^2 / (s^2 + s w0 / Q + w0^2), Q = 1/sqrt(2),
// mapped to discrete time by the bilinear transform with the cut-off pre-warped, in the form of
// R. Bristow-Johnson, "Cookbook formulae for audio EQ biquad filter coefficients" (the HPF
// entry), with w = 2 pi f_c / f_s and alpha = sin(w) / (2 Q):
//
//   b0 = (1 + cos w) / 2,  b1 = -(1 + cos w),  b2 = (1 + cos w) / 2,
//   a0 = 1 + alpha,        a1 = -2 cos w,      a2 = 1 - alpha,
//
// all divided by a0. The gain is 1/sqrt(2) (-3 dB) at f_c, and H(z) has a double zero at z = 1
// (DC): the sum of the response to a step is zero, so the mean of a filtered record of a
// constant-plus-noise signal tends to zero as the record grows, whatever the constant.
//
// FilterForward runs it once, forward (causal, as a real-time filter would), from a zero state,
// in transposed direct form II in double.
#pragma once

#include <vector>

namespace plumb::signal {

/// Coefficients of one biquad, normalised so that a0 = 1:
/// y[n] = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2 y[n-2].
struct Biquad {
  double b0 = 1.0;  ///< feed-forward coefficients, dimensionless
  double b1 = 0.0;
  double b2 = 0.0;
  double a1 = 0.0;  ///< feedback coefficients, dimensionless
  double a2 = 0.0;
};

/// Second-order Butterworth high-pass with cut-off `cutoff_hz` for samples at `rate_hz`.
/// Throws plumb::Error unless both are finite and 0 < cutoff_hz < rate_hz / 2.
Biquad ButterworthHighPass(double cutoff_hz, double rate_hz);

/// The filter applied once, forward, from a zero state; the output has x's length and units.
std::vector<double> FilterForward(const Biquad& filter, const std::vector<double>& x);

}  // namespace plumb::signal

// plumb/signal/high_pass.cc — see high_pass.h.
#include "plumb/signal/high_pass.h"

#include <cmath>
#include <string>

#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb::signal {

Biquad ButterworthHighPass(double cutoff_hz, double rate_hz) {
  if (!std::isfinite(cutoff_hz) || !std::isfinite(rate_hz) || !(cutoff_hz > 0.0) ||
      !(rate_hz > 0.0) || !(cutoff_hz < rate_hz / 2.0)) {
    throw Error("high-pass filter: need 0 < cutoff_hz < rate_hz / 2, got cutoff_hz " +
                Number(cutoff_hz) + ", rate_hz " + Number(rate_hz));
  }
  const double q = 1.0 / std::sqrt(2.0);
  const double w = units::kTwoPi * cutoff_hz / rate_hz;
  const double cos_w = std::cos(w);
  const double alpha = std::sin(w) / (2.0 * q);
  const double a0 = 1.0 + alpha;
  Biquad f;
  f.b0 = (1.0 + cos_w) / 2.0 / a0;
  f.b1 = -(1.0 + cos_w) / a0;
  f.b2 = (1.0 + cos_w) / 2.0 / a0;
  f.a1 = -2.0 * cos_w / a0;
  f.a2 = (1.0 - alpha) / a0;
  return f;
}

std::vector<double> FilterForward(const Biquad& filter, const std::vector<double>& x) {
  std::vector<double> y(x.size());
  double s1 = 0.0;  // transposed direct form II state
  double s2 = 0.0;
  for (std::size_t n = 0; n < x.size(); ++n) {
    const double out = filter.b0 * x[n] + s1;
    s1 = filter.b1 * x[n] - filter.a1 * out + s2;
    s2 = filter.b2 * x[n] - filter.a2 * out;
    y[n] = out;
  }
  return y;
}

}  // namespace plumb::signal

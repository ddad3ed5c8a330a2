// plumb/estimation/turn_noise.cc — see turn_noise.h.
#include "plumb/estimation/turn_noise.h"

#include <algorithm>
#include <cmath>

#include "plumb/core/so3.h"

namespace plumb::estimation {

namespace {

/// Variance of a broadband scatter from one second difference: E[d^2] = 6 sigma^2.
constexpr double kSecondDifferenceGain = 6.0;

}  // namespace

Vec3 TurnVelocityVariance(const residuals::MotionSamples& samples, const Mat3& E_inv,
                          const Mat3& F_inv, const TurnNoise& noise, const Vec3& down_b,
                          double g) {
  const std::size_t size = samples.size();
  const double steps = size > 1 ? static_cast<double>(size - 1) : 1.0;
  const double h = size > 1 ? (samples.dt_s.back() - samples.dt_s.front()) / steps : 0.0;

  // The white noise's share: the accelerometer summed over the steps, the gyroscope's
  // attitude random walk integrated to n^3 / 3 (tilting gravity only across it).
  Vec3 var_white_acc;
  for (int a = 0; a < 3; ++a) {
    var_white_acc[a] = noise.cov_f(a, a) * noise.tau_acc[a] * h * h * steps;
  }
  const double attitude_white = noise.var_rate * h * h * h * h * steps * steps * steps / 3.0;

  // The accelerometer's measured scatter, rotated into the frame of the turn's start (the
  // rotation integrated from the outputs through E^-1: a weight needs no better).
  Vec3 var_vib_acc = Vec3::Zero();
  Mat3 dR = Mat3::Identity();
  for (std::size_t i = 1; noise.measure_vibration && i + 1 < size; ++i) {
    dR = dR * so3::Exp(E_inv * samples.gyr[i - 1] * (samples.dt_s[i] - samples.dt_s[i - 1]));
    const Vec3 d_acc = F_inv * (samples.acc[i + 1] - 2.0 * samples.acc[i] + samples.acc[i - 1]);
    var_vib_acc += (dR * d_acc).cwiseAbs2() * (h * h / kSecondDifferenceGain);
  }

  Vec3 out;
  for (int a = 0; a < 3; ++a) {
    const double across = std::max(0.0, 1.0 - down_b[a] * down_b[a]);
    out[a] = std::max(var_white_acc[a], var_vib_acc[a]) + across * g * g * attitude_white;
  }
  return out;
}

}  // namespace plumb::estimation

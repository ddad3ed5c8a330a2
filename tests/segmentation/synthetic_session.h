// Deterministic still/rotation sessions for the segmentation tests (fixed seeds).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/types.h"

namespace plumb::segmentation::testing {

/// One phase of a session: still for `duration_s`, or turning by `angle_rad` about the NED
/// axis `axis_n` over `duration_s` with a smooth (1 - cos) rate profile, or at constant rate.
struct Phase {
  enum Kind { kStill, kSmoothTurn, kConstantTurn } kind = kStill;
  double duration_s = 0.0;
  Vec3 axis_n = Vec3::UnitX();
  double angle_rad = 0.0;
};

inline Phase Still(double duration_s) { return Phase{Phase::kStill, duration_s, Vec3::UnitX(), 0.0}; }
inline Phase SmoothTurn(double duration_s, const Vec3& axis_n, double angle_rad) {
  return Phase{Phase::kSmoothTurn, duration_s, axis_n.normalized(), angle_rad};
}
inline Phase ConstantTurn(double duration_s, const Vec3& axis_n, double rate_rad_s) {
  return Phase{Phase::kConstantTurn, duration_s, axis_n.normalized(), rate_rad_s * duration_s};
}

struct SessionSpec {
  double rate_hz = 100.0;
  double accel_sigma = 0.02;   ///< m/s^2, per-sample std of the accelerometer noise
  double accel_phi = 0.5;      ///< AR(1) coefficient of the accelerometer noise
  double gyro_sigma = 0.002;   ///< rad/s, white
  Vec3 gyro_bias = Vec3(0.003, -0.002, 0.001);  ///< rad/s
  std::uint64_t seed = 1;
};

/// Samples the session: specific force R_n_b^T (0, 0, -g) (rotation about the IMU's centre,
/// so no linear acceleration), rate R_n_b^T (omega_ie_n + turn rate) + bias, plus noise.
/// `still_s` receives the true still intervals [t0, t1) in seconds.
inline ImuSeries MakeSession(const std::vector<Phase>& phases, const SessionSpec& spec,
                             std::vector<std::pair<double, double>>* still_s = nullptr) {
  const double g = 9.80665;
  const double kPi = 3.14159265358979323846;
  const Vec3 omega_ie_n = 7.292115e-5 * Vec3(std::cos(0.8), 0.0, -std::sin(0.8));
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double dt = 1.0 / spec.rate_hz;
  const double innovation = spec.accel_sigma * std::sqrt(1.0 - spec.accel_phi * spec.accel_phi);
  Vec3 accel_noise(spec.accel_sigma * unit(rng), spec.accel_sigma * unit(rng),
                   spec.accel_sigma * unit(rng));

  ImuSeries series;
  Mat3 R_n_b = Mat3::Identity();
  double t0 = 0.0;
  for (const Phase& phase : phases) {
    const auto n = static_cast<std::size_t>(std::llround(phase.duration_s * spec.rate_hz));
    if (phase.kind == Phase::kStill && still_s) still_s->push_back({t0, t0 + n * dt});
    for (std::size_t k = 0; k < n; ++k) {
      const double tau = (static_cast<double>(k) + 0.5) / static_cast<double>(n);
      double rate = 0.0;
      if (phase.kind == Phase::kSmoothTurn) {
        rate = phase.angle_rad / phase.duration_s * (1.0 - std::cos(2.0 * kPi * tau));
      } else if (phase.kind == Phase::kConstantTurn) {
        rate = phase.angle_rad / phase.duration_s;
      }
      const Vec3 omega_n = omega_ie_n + rate * phase.axis_n;
      for (int a = 0; a < 3; ++a) {
        accel_noise[a] = spec.accel_phi * accel_noise[a] + innovation * unit(rng);
      }
      const Vec3 f_b = R_n_b.transpose() * Vec3(0.0, 0.0, -g) + accel_noise;
      const Vec3 w_b = R_n_b.transpose() * omega_n + spec.gyro_bias +
                       spec.gyro_sigma * Vec3(unit(rng), unit(rng), unit(rng));
      series.t_s.push_back(t0 + static_cast<double>(k) * dt);
      series.acc.push_back(f_b.cast<float>());
      series.gyr.push_back(w_b.cast<float>());
      // Turn relative to NED over one sample: R_n_b <- Rot(axis_n, rate dt) R_n_b.
      if (rate != 0.0) {
        R_n_b = Eigen::AngleAxisd(rate * dt, phase.axis_n).toRotationMatrix() * R_n_b;
      }
    }
    t0 += static_cast<double>(n) * dt;
  }
  return series;
}

}  // namespace plumb::segmentation::testing

#include "plumb/estimation/problem_imu.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <memory>

#include "plumb/estimation/turn_noise.h"
#include "plumb/model/board_mount.h"

namespace plumb::estimation {
namespace {

/// Adds the diagonal of M diag(v) M^T to the variances behind `sqrt_info` (1 / sigma).
void AddVariance(Vec3& sqrt_info, const Mat3& M, const Vec3& v) {
  const Mat3 cov = M * v.asDiagonal() * M.transpose();
  for (int i = 0; i < 3; ++i) {
    sqrt_info[i] = 1.0 / std::sqrt(1.0 / (sqrt_info[i] * sqrt_info[i]) + cov(i, i));
  }
}

}  // namespace

const model::EffectInfo& ProblemImu::TermInfo(int local) const {
  static const model::EffectInfo kMount = model::board_mount::Describe();
  if (local == model.num_terms()) return kMount;
  return model.terms()[static_cast<std::size_t>(local)].effect->info();
}

bool ProblemImu::Fixed(int local, int i) const {
  if (local == model.num_terms()) return !turns_compared && i >= model::board_mount::kLeverArm;
  return model.terms()[static_cast<std::size_t>(local)].fixed[static_cast<std::size_t>(i)];
}

std::string ProblemImu::ParameterName(int local, int i) const {
  const model::EffectInfo& info = TermInfo(local);
  const std::string& name = info.parameters[static_cast<std::size_t>(i)].name;
  return name_prefix + (info.prefix.empty() ? name : info.ParameterName(i));
}

std::vector<std::size_t> ProblemImu::WanderOf(model::Sensor sensor) const {
  std::vector<std::size_t> out;
  for (std::size_t p = 0; p < wander.size(); ++p) {
    if (wander[p].sensor == sensor) out.push_back(p);
  }
  return out;
}

void ProblemImu::SetMeasurements() {
  for (auto& s : still.poses) {
    const double n = static_cast<double>(s.stats.count);
    residuals::StillMeasurement m;
    m.dt_s = s.stats.t_mid_s - model.t_ref_s;
    m.dtemp_c = std::isfinite(s.stats.temp_mean_c) ? s.stats.temp_mean_c - model.temp_ref_c : 0.0;
    m.mean = s.stats.acc_mean;
    for (int i = 0; i < 3; ++i) m.sqrt_info[i] = std::sqrt(n / noise.tau_acc[i]) / noise.sigma_acc[i];
    // Each wander process has a state at both ends of the segment; its bridge between them
    // adds BridgeMeanVariance (the walk's K^2 T / 12) to the variance of the segment's mean.
    const double T = s.stats.t_end_s - s.stats.t_begin_s;
    // Quantisation (IEEE Q) adds 2 Q^2 / T^2 (noise_model.h).
    auto add_bridges = [&](Vec3& sqrt_info, model::Sensor sensor) {
      Vec3 var = sqrt_info.cwiseAbs2().cwiseInverse();
      for (const WanderProcess& w : wander) {
        if (w.sensor == sensor) var += w.BridgeMeanVariance(T);
      }
      const Vec3& Q = sensor == model::Sensor::kAccel ? noise.quantisation_acc : noise.quantisation_gyr;
      if (T > 0) var += Q.cwiseAbs2() * (2.0 / (T * T));
      sqrt_info = var.cwiseSqrt().cwiseInverse();
    };
    add_bridges(m.sqrt_info, model::Sensor::kAccel);
    s.acc_measurement = m;
    if (still_gyro) {
      m.mean = s.stats.gyr_mean;
      for (int i = 0; i < 3; ++i) m.sqrt_info[i] = std::sqrt(n / noise.tau_gyr[i]) / noise.sigma_gyr[i];
      add_bridges(m.sqrt_info, model::Sensor::kGyro);
      s.gyr_measurement = m;
    }
  }
}

void ProblemImu::SetMotionSamples() {
  const ImuSeries& s = *series;
  for (const auto& mo : still.motions) {
    residuals::MotionSamples ms;
    std::vector<Vec3> dy;
    const std::size_t n = mo.last + 1 - mo.first;
    ms.dt_s.reserve(n);
    ms.acc.reserve(n);
    ms.gyr.reserve(n);
    ms.dtemp_c.reserve(n);
    dy.reserve(n);
    for (std::size_t i = mo.first; i <= mo.last; ++i) {
      ms.dt_s.push_back(s.t_s[i] - model.t_ref_s);
      ms.acc.push_back(s.acc[i].cast<double>());
      ms.gyr.push_back(s.gyr[i].cast<double>());
      ms.dtemp_c.push_back(s.has_temperature() ? s.temp_c[i] - model.temp_ref_c : 0.0);
      const std::size_t a = i > 0 ? i - 1 : i, b = std::min(i + 1, s.size() - 1);
      const double h = s.t_s[b] - s.t_s[a];
      dy.push_back(h > 0 ? Vec3((s.gyr[b] - s.gyr[a]).cast<double>() / h) : Vec3::Zero());
    }
    ms.alpha_b.resize(dy.size());
    motion_samples.push_back(std::make_shared<residuals::MotionSamples>(std::move(ms)));
    output_rate.push_back(std::move(dy));
  }
  velocity_info.assign(still.motions.size(), Vec3::Ones());
}

// The angular acceleration input of the effects (time_offset, accel_size_effect) is the
// derivative of the corrected rate, E^-1 d y_g / dt (central differences). The velocity
// residual's variance: the accelerometer's white noise or the turn's measured vibration summed
// over the steps, and gravity tilted by the attitude random walk of the gyroscope's (mean over
// the axes), which moves the velocity only across gravity (turn_noise.h).
void ProblemImu::SetMotionWeights(const Mat3& E, const Mat3& F, double g, bool turn_vibration) {
  const auto& motions = still.motions;
  const Mat3 E_inv = E.inverse();
  const Mat3 F_inv = F.inverse();
  const Mat3 cov_f = F_inv * noise.sigma_acc.cwiseAbs2().asDiagonal() * F_inv.transpose();
  const Mat3 cov_rate = E_inv * noise.sigma_gyr.cwiseAbs2().asDiagonal() * E_inv.transpose();
  TurnNoise turn_noise;
  turn_noise.measure_vibration = turn_vibration;
  turn_noise.cov_f = cov_f;
  turn_noise.tau_acc = noise.tau_acc;
  turn_noise.var_rate = cov_rate.trace() / 3.0 * noise.tau_gyr.mean();
  const ImuSeries& s = *series;
  for (std::size_t k = 0; k < motions.size(); ++k) {
    // New samples (problems built before keep reading theirs).
    auto samples = std::make_shared<residuals::MotionSamples>(*motion_samples[k]);
    for (std::size_t i = 0; i < output_rate[k].size(); ++i) {
      samples->alpha_b[i] = E_inv * output_rate[k][i];
    }
    const auto& mo = motions[k];
    const double steps = static_cast<double>(mo.last - mo.first);
    const double dt = (s.t_s[mo.last] - s.t_s[mo.first]) / std::max(1.0, steps);
    for (int i = 0; i < 3; ++i) {
      const double sigma_rate = std::sqrt(cov_rate(i, i));  // rad/s per sample
      samples->sqrt_info[i] =
          1.0 / (sigma_rate * dt * std::sqrt(std::max(1.0, steps) * noise.tau_gyr[i]));
    }
    // Each gyroscope wander process about the line from e_k to s_k+1 integrates to an angle:
    // a Brownian bridge over the interval T to K^2 T^3 / 12 per sensor axis, through E^-1.
    // The instability is taken as the walk of equal short-time spread, K^2 = 2 s^2 / tau
    // (exact for T << tau; turns last seconds, correlation times tens of seconds and more).
    const double T = s.t_s[mo.last] - s.t_s[mo.first];
    for (std::size_t p : WanderOf(model::Sensor::kGyro)) {
      AddVariance(samples->sqrt_info, E_inv, wander[p].ShortTimeWalk2() * (T * T * T / 12.0));
    }
    // Quantisation: the integrated angle carries 2 Q^2 (noise_model.h).
    AddVariance(samples->sqrt_info, E_inv, 2.0 * noise.quantisation_gyr.cwiseAbs2());
    // The velocity residual, where the fit has one (a pass over the turn's samples): the white
    // noise or the turn's measured vibration (turn_noise.h), then each accelerometer wander
    // process about its line (the velocity residual takes the line off): its bridge's mean
    // over T, times T, through F^-1; the instability as the walk of equal short-time spread,
    // as for the rotation above.
    if (velocity_on) {
      const Vec3 var_v = TurnVelocityVariance(*samples, E_inv, F_inv, turn_noise,
                                              start.Down(still.poses[mo.from]), g);
      velocity_info[k] = var_v.cwiseSqrt().cwiseInverse();
      for (std::size_t p : WanderOf(model::Sensor::kAccel)) {
        AddVariance(velocity_info[k], F_inv, wander[p].ShortTimeWalk2() * (T * T * T / 12.0));
      }
    }
    motion_samples[k] = std::move(samples);
  }
}

}  // namespace plumb::estimation

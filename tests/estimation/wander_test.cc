// The bias wander's processes (estimation/noise_model.h): the Markov factors whiten simulated
// processes, and the bridge mean and variance of a segment match a Monte Carlo of the process
// between known ends; the Gauss-Markov bridge tends to the walk's for short segments.
// (The analysis that eliminates the wander states: elimination_test.cc.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/solve.h"
#include "plumb/estimation/still_set.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"
#include "support/sim_options.h"

namespace plumb::estimation {
namespace {

WanderProcess Instability(double sigma, double tau_s) {
  WanderProcess w;
  w.kind = WanderProcess::Kind::kInstability;
  w.level = Vec3::Constant(sigma);
  w.tau_s = tau_s;
  return w;
}

TEST(WanderProcess, GaussMarkovStepWhitensTheProcess) {
  // A stationary Gauss-Markov process sampled every dt: (x_to - phi x_from) / step_sigma is
  // N(0, 1), so its mean square over many steps is 1 within its spread.
  const WanderProcess w = Instability(3e-4, 20.0);
  const double dt = 1.7;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  const double phi_exact = std::exp(-dt / 20.0);
  double x = 3e-4 * n(rng), sum = 0;
  const int steps = 40000;
  for (int k = 0; k < steps; ++k) {
    const double next = phi_exact * x + 3e-4 * std::sqrt(1 - phi_exact * phi_exact) * n(rng);
    const double r = (next - w.Phi(dt) * x) / w.StepSigma(dt)[0];
    sum += r * r;
    x = next;
  }
  EXPECT_NEAR(sum / steps, 1.0, 3.0 * std::sqrt(2.0 / steps));
}

/// Monte Carlo of the mean over [0, T] of a process between its values at 0 and T: the
/// average of (mean - w (x_0 + x_T)) and of its square, from `runs` fine-grid paths.
void BridgeMonteCarlo(const WanderProcess& w, double T, double stationary_sigma, int runs,
                      double* bias, double* variance) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  const int steps = 2000;
  const double h = T / steps;
  const bool walk = w.kind == WanderProcess::Kind::kWalk;
  const double phi = walk ? 1.0 : std::exp(-h / w.tau_s);
  const double step = walk ? w.level[0] * std::sqrt(h) : w.level[0] * std::sqrt(1 - phi * phi);
  const double weight = w.BridgeMeanWeight(T);
  double sum = 0, sum_sq = 0;
  for (int r = 0; r < runs; ++r) {
    double x = stationary_sigma * n(rng);
    const double x0 = x;
    double integral = 0;
    for (int i = 0; i < steps; ++i) {
      const double next = phi * x + step * n(rng);
      integral += 0.5 * (x + next) * h;  // trapezoid
      x = next;
    }
    const double e = integral / T - weight * (x0 + x);
    sum += e;
    sum_sq += e * e;
  }
  *bias = sum / runs;
  *variance = sum_sq / runs;
}

TEST(WanderProcess, BridgeMatchesMonteCarlo) {
  // For a walk and for Gauss-Markov processes with T/tau from short to long, the weighted ends
  // are an unbiased prediction of the segment's mean and BridgeMeanVariance is the variance
  // about it (within 10%: 4000 paths give a relative spread of 2.2%).
  struct Case {
    WanderProcess w;
    double T, stationary;
  };
  WanderProcess walk;
  walk.level = Vec3::Constant(1e-3);
  const Case cases[] = {{walk, 30.0, 0.0},
                        {Instability(1e-3, 30.0), 5.0, 1e-3},
                        {Instability(1e-3, 30.0), 30.0, 1e-3},
                        {Instability(1e-3, 1.0), 20.0, 1e-3}};
  for (const Case& c : cases) {
    double bias = 0, variance = 0;
    BridgeMonteCarlo(c.w, c.T, c.stationary, 4000, &bias, &variance);
    const double predicted = c.w.BridgeMeanVariance(c.T)[0];
    EXPECT_NEAR(variance / predicted, 1.0, 0.1) << "T " << c.T << " tau " << c.w.tau_s;
    EXPECT_LT(std::abs(bias), 4.0 * std::sqrt(predicted / 4000)) << "T " << c.T;
  }
}

TEST(WanderProcess, ShortGaussMarkovBridgeIsTheWalks) {
  // T << tau: weight 1/2 and variance s^2 T / (6 tau), the walk's K^2 T / 12 with
  // K^2 = 2 s^2 / tau; continuous across the switch to the series.
  const WanderProcess w = Instability(2e-4, 100.0);
  for (double T : {1e-3, 0.0099, 0.0101, 0.5}) {
    EXPECT_NEAR(w.BridgeMeanWeight(T), 0.5, 1e-3 * T + 1e-12) << T;
    const double walk_like = 2e-4 * 2e-4 * T / (6.0 * 100.0);
    EXPECT_NEAR(w.BridgeMeanVariance(T)[0] / walk_like, 1.0, 2e-2) << T;
  }
}

TEST(NoiseModel, WanderListsTheProcessesInStateOrder) {
  NoiseModel noise;
  noise.walk_acc = Vec3::Constant(1e-4);
  noise.instability_gyr = Vec3::Constant(2e-5);
  noise.instability_time_s = 40.0;
  const auto with_gyro = noise.Wander(true);
  ASSERT_EQ(with_gyro.size(), 2u);
  EXPECT_EQ(with_gyro[0].sensor, model::Sensor::kAccel);
  EXPECT_EQ(with_gyro[0].kind, WanderProcess::Kind::kWalk);
  EXPECT_EQ(with_gyro[1].sensor, model::Sensor::kGyro);
  EXPECT_EQ(with_gyro[1].kind, WanderProcess::Kind::kInstability);
  EXPECT_EQ(with_gyro[1].tau_s, 40.0);
  EXPECT_EQ(noise.Wander(false).size(), 1u);
}


}  // namespace
}  // namespace plumb::estimation

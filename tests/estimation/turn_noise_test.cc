// The velocity residual's variance from what a turn carries (estimation/turn_noise.h): the
// white noise's on a quiet turn, the measured vibration's on a shaken one, rotated into the
// frame of the turn's start, blind to a smooth motion.
#include "plumb/estimation/turn_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "plumb/core/units.h"

namespace plumb::estimation {
namespace {

constexpr double kRateHz = 100.0;
constexpr double kH = 1.0 / kRateHz;
constexpr double kGravity = 9.80665;
constexpr int kSamples = 20001;  // a long turn: the measured scatter's own spread is ~1 %

/// A turn's samples: a smooth specific force (a hand's translation and gravity), a constant
/// rate `omega` (rad/s, body frame), and per sample per axis a scatter of `sigma` (m/s^2) along
/// `axes` (1 = that axis shakes), drawn from a fixed seed.
residuals::MotionSamples Turn(const Vec3& omega, double sigma, const Vec3& axes,
                              std::uint64_t seed = 5) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  residuals::MotionSamples s;
  for (int i = 0; i < kSamples; ++i) {
    const double t = i * kH;
    // Smooth: gravity and a slow swing of a few m/s^2 at 0.5 Hz.
    const Vec3 smooth(3.0 * std::sin(units::kPi * t), 0.5 * std::cos(units::kPi * t), -kGravity);
    const Vec3 shake(normal(rng), normal(rng), normal(rng));
    s.dt_s.push_back(t);
    s.acc.push_back(smooth + sigma * axes.cwiseProduct(shake));
    s.gyr.push_back(omega);
    s.dtemp_c.push_back(0.0);
    s.alpha_b.push_back(Vec3::Zero());
  }
  return s;
}

TurnNoise WhiteOf(double sigma_acc, double sigma_rate) {
  TurnNoise w;
  w.cov_f = Mat3::Identity() * sigma_acc * sigma_acc;
  w.tau_acc = Vec3::Ones();
  w.var_rate = sigma_rate * sigma_rate;
  return w;
}

const Vec3 kDown = Vec3::UnitZ();  // gravity along body z: the attitude term only on x and y

TEST(TurnVelocityVariance, AQuietTurnKeepsTheWhiteNoise) {
  // Samples as smooth as a hand's motion, white noise of 0.01 m/s^2 in them: the white
  // variance, whatever the measured scatter (the same noise) says.
  const auto samples = Turn(Vec3::Zero(), 0.01, Vec3::Ones());
  const TurnNoise white = WhiteOf(0.01, 0.0);
  const Vec3 var = TurnVelocityVariance(samples, Mat3::Identity(), Mat3::Identity(), white, kDown,
                                        kGravity);
  const double expected = 0.01 * 0.01 * kH * kH * (kSamples - 1);
  for (int a = 0; a < 3; ++a) {
    EXPECT_GE(var[a], expected) << a;
    EXPECT_NEAR(var[a], expected, 0.05 * expected) << a;  // at most the scatter's own spread
  }
}

TEST(TurnVelocityVariance, AShakenTurnTakesItsMeasuredVibration) {
  // A scatter of 1 m/s^2 per sample along x only, white noise of 0.01: x takes h^2 n sigma^2,
  // y and z keep the white noise's.
  const auto samples = Turn(Vec3::Zero(), 1.0, Vec3::UnitX());
  const Vec3 var = TurnVelocityVariance(samples, Mat3::Identity(), Mat3::Identity(),
                                        WhiteOf(0.01, 0.0), kDown, kGravity);
  const double shaken = kH * kH * (kSamples - 2);
  const double quiet = 0.01 * 0.01 * kH * kH * (kSamples - 1);
  EXPECT_NEAR(var.x(), shaken, 0.05 * shaken);
  EXPECT_NEAR(var.y(), quiet, 1e-12);
  EXPECT_NEAR(var.z(), quiet, 1e-12);
}

TEST(TurnVelocityVariance, WithoutTheVibrationAShakenTurnKeepsTheWhiteNoise) {
  // CalibrationOptions::turn_vibration false (--white-turns): the white noise alone.
  const auto samples = Turn(Vec3::Zero(), 1.0, Vec3::UnitX());
  TurnNoise noise = WhiteOf(0.01, 0.0);
  noise.measure_vibration = false;
  const Vec3 var = TurnVelocityVariance(samples, Mat3::Identity(), Mat3::Identity(), noise, kDown,
                                        kGravity);
  const double quiet = 0.01 * 0.01 * kH * kH * (kSamples - 1);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(var[a], quiet, 1e-12) << a;
}

TEST(TurnVelocityVariance, TheVibrationIsCountedInTheFrameOfTheTurnsStart) {
  // Shaken along body x while turning about z at a steady rate: over whole turns, x of the
  // body sweeps x and y of the start's frame evenly; z stays quiet.
  const double omega = 2.0 * units::kPi / 50.0;  // one turn per 50 s, four over the samples
  const auto samples = Turn(Vec3(0, 0, omega), 1.0, Vec3::UnitX());
  const Vec3 var = TurnVelocityVariance(samples, Mat3::Identity(), Mat3::Identity(),
                                        WhiteOf(0.01, 0.0), kDown, kGravity);
  const double shaken = kH * kH * (kSamples - 2);
  EXPECT_NEAR(var.x(), shaken / 2, 0.05 * shaken);
  EXPECT_NEAR(var.y(), shaken / 2, 0.05 * shaken);
  EXPECT_LT(var.z(), 1e-3 * shaken);
}

TEST(TurnVelocityVariance, TheGyroscopesNoiseTiltsGravityOnlyAcrossIt) {
  // White rate noise sigma_w: g^2 sigma_w^2 h^4 n^3 / 3 on x and y (across gravity), none on z.
  const int n = 300;
  residuals::MotionSamples s;
  for (int i = 0; i <= n; ++i) {
    s.dt_s.push_back(i * kH);
    s.acc.push_back(Vec3(0, 0, -kGravity));
    s.gyr.push_back(Vec3::Zero());
  }
  const double sigma_w = 1e-3;
  const Vec3 var = TurnVelocityVariance(s, Mat3::Identity(), Mat3::Identity(), WhiteOf(0.0, sigma_w),
                                        kDown, kGravity);
  const double tilt = kGravity * kGravity * sigma_w * sigma_w * std::pow(kH, 4) * n * n * n / 3.0;
  EXPECT_NEAR(var.x(), tilt, 1e-9 * tilt);
  EXPECT_NEAR(var.y(), tilt, 1e-9 * tilt);
  EXPECT_NEAR(var.z(), 0.0, 1e-15);
}

TEST(TurnVelocityVariance, TheScatterIsReadInTheCorrectedUnits) {
  // Outputs in counts (F = 1000 counts per m/s^2): the measured scatter is divided back.
  auto samples = Turn(Vec3::Zero(), 1.0, Vec3::UnitX());
  for (auto& a : samples.acc) a *= 1000.0;
  const Vec3 var = TurnVelocityVariance(samples, Mat3::Identity(), Mat3::Identity() / 1000.0,
                                        WhiteOf(0.01, 0.0), kDown, kGravity);
  const double shaken = kH * kH * (kSamples - 2);
  EXPECT_NEAR(var.x(), shaken, 0.05 * shaken);
}

}  // namespace
}  // namespace plumb::estimation

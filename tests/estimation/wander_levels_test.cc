// Stage 2a (estimation/wander_levels.h): where each level of the bias wander comes from —
// given, measured by the Allan deviation of still data, its bound, or the typical sensor —
// and the quantisation it resolves.
#include "plumb/estimation/wander_levels.h"

#include <gtest/gtest.h>

#include <random>

#include "plumb/core/typical_mems.h"

namespace plumb::estimation {
namespace {

constexpr double kDt = 0.01;

/// A still record at 100 Hz: white noise of `white` per sample on every axis, plus on the
/// accelerometer a random walk of density `walk` (m/s^3/sqrt(Hz)) and angle-like quantisation
/// (the output the difference of a white "angle" error of sigma `q_error`, per dt).
ImuSeries StillRecord(std::size_t samples, double white, double walk, double q_error,
                      std::uint64_t seed) {
  ImuSeries s;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> e(0.0, 1.0);
  Vec3 b = Vec3::Zero(), last = Vec3::Zero();
  for (std::size_t i = 0; i < samples; ++i) {
    const Vec3 phase(q_error * e(rng), q_error * e(rng), q_error * e(rng));
    const Vec3 acc = Vec3(0, 0, -9.8) + b + white * Vec3(e(rng), e(rng), e(rng)) + (phase - last) / kDt;
    last = phase;
    b += walk * std::sqrt(kDt) * Vec3(e(rng), e(rng), e(rng));
    s.t_s.push_back(kDt * static_cast<double>(i));
    s.acc.push_back(acc.cast<float>());
    s.gyr.push_back((1e-3 * Vec3(e(rng), e(rng), e(rng))).cast<float>());
  }
  return s;
}

signal::StillNoise Analyse(const ImuSeries& series) {
  StillSegment all;
  all.begin = 0;
  all.end = series.size();
  return signal::AnalyseStillNoise(series, {all});
}

TEST(WanderLevels, WithoutStillDataTheTypicalSensorIsAssumedAndSaid) {
  const NoiseModel noise;
  const WanderLevels out = AssignWanderLevels(noise, {}, StartingValues{}, true, 60.0, {});
  EXPECT_NEAR(out.noise.walk_acc[0], typical_mems::kAccelWalk, 1e-12);
  EXPECT_NEAR(out.noise.instability_gyr[2], typical_mems::kGyroInstability, 1e-12);
  EXPECT_EQ(out.noise.from.walk_acc[1], LevelSource::kTypical);
  ASSERT_EQ(out.notes.size(), 1U);
  EXPECT_EQ(out.notes[0].code, "wander_levels");
  EXPECT_NE(out.notes[0].message.find("no still data long enough"), std::string::npos)
      << out.notes[0].message;
  // The note points to the options that give the levels, in the order it names them.
  EXPECT_EQ(out.notes[0].options,
            (std::vector<Option>{Option::kAccelWalk, Option::kGyroWalk, Option::kAccelInstability,
                                 Option::kGyroInstability, Option::kNoiseFrom}));
}

TEST(WanderLevels, GivenLevelsAreKept) {
  NoiseModel noise;
  noise.walk_gyr.setConstant(5e-6);
  noise.from.walk_gyr.fill(LevelSource::kGiven);
  CalibrationOptions options;
  options.gyro_walk_density = 5e-6;
  const signal::StillNoise still = Analyse(StillRecord(60000, 0.01, 0.0, 0.0, 3));
  const WanderLevels out = AssignWanderLevels(noise, {&still}, StartingValues{}, true, 60.0, options);
  EXPECT_EQ(out.noise.walk_gyr, Vec3::Constant(5e-6));
  EXPECT_EQ(out.noise.from.walk_gyr[0], LevelSource::kGiven);
}

TEST(WanderLevels, AQuietSensorIsBoundedBelowTheTypicalLevel) {
  // 10 minutes of white noise 1e-4 per sample and no wander: the Allan deviation bounds the
  // walk and the instability far below the typical levels; the bounds are used.
  const signal::StillNoise still = Analyse(StillRecord(60000, 1e-4, 0.0, 0.0, 4));
  const WanderLevels out =
      AssignWanderLevels(NoiseModel{}, {&still}, StartingValues{}, true, 1e4, {});
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(out.noise.from.walk_acc[static_cast<std::size_t>(i)], LevelSource::kBounded);
    EXPECT_LT(out.noise.walk_acc[i], 0.5 * typical_mems::kAccelWalk);
    EXPECT_GT(out.noise.walk_acc[i], 0.0);
  }
}

TEST(WanderLevels, ARecordThatCoversTheSessionGivesItsFittedLevels) {
  // 30 minutes with an accelerometer walk of 5 times the typical one: a session of 5 minutes
  // takes the fitted walk (within 35 %), its source "allan".
  const double walk = 5.0 * typical_mems::kAccelWalk;
  const signal::StillNoise still = Analyse(StillRecord(180000, 0.01, walk, 0.0, 5));
  const WanderLevels out =
      AssignWanderLevels(NoiseModel{}, {&still}, StartingValues{}, true, 300.0, {});
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(out.noise.from.walk_acc[static_cast<std::size_t>(i)], LevelSource::kMeasured);
    EXPECT_NEAR(out.noise.walk_acc[i] / walk, 1.0, 0.35) << i;
  }
  EXPECT_NE(out.notes[0].message.find("accel walk"), std::string::npos) << out.notes[0].message;
}

TEST(WanderLevels, ResolvedQuantisationIsUsed) {
  // White "angle" errors of 2e-4 m/s behind the accelerometer's output: Allan's Q term,
  // resolved at the short taus, is carried to the fit (2 Q^2 / T^2 on a segment mean).
  const signal::StillNoise still = Analyse(StillRecord(30000, 1e-3, 0.0, 2e-4, 6));
  const WanderLevels out =
      AssignWanderLevels(NoiseModel{}, {&still}, StartingValues{}, true, 300.0, {});
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(out.noise.quantisation_acc[i] / 2e-4, 1.0, 0.2) << i;
  EXPECT_TRUE(out.noise.quantisation_gyr.isZero());
  EXPECT_NE(out.notes[0].message.find("accel quantisation"), std::string::npos) << out.notes[0].message;
}

}  // namespace
}  // namespace plumb::estimation

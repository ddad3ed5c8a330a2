#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/geo/site.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A known site (Toulouse-like latitude) so that Earth rate and local gravity are present.
geo::Site TestSite() { return geo::Site::At(43.6, 1.4, 150.0, "test"); }

/// Mean and standard deviation of one axis over [begin, end).
std::pair<double, double> MeanStd(const std::vector<Vec3f>& v, int axis, std::size_t begin,
                                  std::size_t end) {
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t k = begin; k < end; ++k) sum += v[k](axis);
  const double n = static_cast<double>(end - begin);
  const double mean = sum / n;
  for (std::size_t k = begin; k < end; ++k) sum2 += (v[k](axis) - mean) * (v[k](axis) - mean);
  return {mean, std::sqrt(sum2 / (n - 1.0))};
}

Vec3 SegmentMean(const std::vector<Vec3f>& v, const StillSegment& s) {
  Vec3 sum = Vec3::Zero();
  for (std::size_t k = s.begin; k < s.end; ++k) sum += v[k].cast<double>();
  return sum / static_cast<double>(s.count());
}

/// Rotation angle between two attitudes, rad.
double AngleBetween(const Quat& a, const Quat& b) {
  return Eigen::AngleAxisd(a.conjugate() * b).angle();
}

TEST(Simulate, NoiselessLevelStillReadsGravityAndEarthRate) {
  SimulationOptions options;
  options.site = TestSite();
  const Simulation sim = Simulate(PaperStatic(10.0), options);
  const auto& s = sim.session.series;
  ASSERT_EQ(s.size(), 4000u);
  ASSERT_EQ(sim.truth_segments.size(), 1u);
  EXPECT_EQ(sim.truth_segments[0].begin, 0u);
  EXPECT_EQ(sim.truth_segments[0].end, 4000u);
  const Vec3f expected_acc = (-options.site.g_n).cast<float>();
  const Vec3f expected_gyr = options.site.omega_ie_n.cast<float>();
  for (std::size_t k = 0; k < s.size(); k += 97) {
    ASSERT_EQ(s.acc[k], expected_acc) << "sample " << k;
    ASSERT_EQ(s.gyr[k], expected_gyr) << "sample " << k;
  }
  // Level: (0, 0, -g) up to the tiny northward component of normal gravity at 150 m.
  EXPECT_NEAR(s.acc[0].z(), -options.site.gravity(), 1e-5);
  EXPECT_LT(std::hypot(s.acc[0].x(), s.acc[0].y()), 1e-4);
  // Earth rate in NED: Omega (cos lat, 0, -sin lat).
  const double lat = 43.6 * kPi / 180.0;
  EXPECT_NEAR(s.gyr[0].x(), geo::EarthRate() * std::cos(lat), 1e-9);
  EXPECT_NEAR(s.gyr[0].y(), 0.0, 1e-12);
  EXPECT_NEAR(s.gyr[0].z(), -geo::EarthRate() * std::sin(lat), 1e-9);
  EXPECT_DOUBLE_EQ(s.t_s[1] - s.t_s[0], 1.0 / 400.0);
}

TEST(Simulate, NoiselessTurnIntegratesToTheCommandedAngle) {
  const Vec3 axis = Vec3(1.0, 2.0, -0.5).normalized();
  const double angle = 1.7;
  Schedule schedule;
  schedule.Hold(1.0).Turn(axis, angle, 2.0).Hold(1.0);
  SimulationOptions options;  // Site::Unknown: no Earth rate
  options.rate_hz = 400.0;
  const Simulation sim = Simulate(schedule, options);
  const auto& s = sim.session.series;
  // Rectangle rule over the turn's samples (the rate is zero at both ends and smooth, so this
  // is the trapezoid rule, exact for the profile's trigonometric terms).
  Vec3 integrated = Vec3::Zero();
  for (std::size_t k = 400; k < 1200; ++k) integrated += s.gyr[k].cast<double>() / 400.0;
  EXPECT_LT((integrated - axis * angle).norm(), 1e-6);
  // The still after the turn knows the turned attitude.
  ASSERT_EQ(sim.true_R_n_b.size(), 2u);
  const Quat expected = Quat(Eigen::AngleAxisd(angle, axis));
  EXPECT_LT(AngleBetween(sim.true_R_n_b[1], expected), 1e-12);
  EXPECT_EQ(sim.truth_segments[1].begin, 1200u);
}

/// A board IMU (SPEC 6) at `R_b_i`, `lever_arm_m` and `time_offset_s`, ideal unless `truth`.
BoardImuTruth BoardImuAt(const Quat& R_b_i, const Vec3& lever_arm_m, double time_offset_s) {
  BoardImuTruth b;
  b.R_b_i = R_b_i;
  b.lever_arm_m = lever_arm_m;
  b.time_offset_s = time_offset_s;
  return b;
}

TEST(SimulateBoard, AnotherImuSeesTheBodyThroughItsMount) {
  // Noiseless and ideal: a still pose's specific force and Earth rate in IMU i's frame are
  // R_b_i^T of IMU 0's, whatever its lever arm and time offset (nothing moves).
  Schedule schedule;
  schedule.Hold(1.0).Turn(Vec3(1, 1, 0).normalized(), 2.0, 2.0).Hold(1.0);
  SimulationOptions options;
  options.site = TestSite();
  const Quat R_b_i(Eigen::AngleAxisd(0.03, Vec3(1, -2, 0.5).normalized()));
  options.board = {BoardImuAt(R_b_i, Vec3(0.03, -0.02, 0.01), 0.004)};
  const Simulation sim = Simulate(schedule, options);
  ASSERT_EQ(sim.session.other_imus.size(), 1u);
  const BoardImu& imu = sim.session.other_imus[0];
  EXPECT_EQ(imu.instance, 1);
  EXPECT_EQ(imu.series.t_s, sim.session.series.t_s);  // IMU 0's stamps
  const Mat3 R_i_b = R_b_i.toRotationMatrix().transpose();
  for (const StillSegment& segment : sim.truth_segments) {
    for (std::size_t k = segment.begin + 10; k + 10 < segment.end; k += 37) {
      const Vec3 acc0 = sim.session.series.acc[k].cast<double>();
      const Vec3 gyr0 = sim.session.series.gyr[k].cast<double>();
      EXPECT_LT((imu.series.acc[k].cast<double>() - R_i_b * acc0).norm(), 1e-5) << k;
      EXPECT_LT((imu.series.gyr[k].cast<double>() - R_i_b * gyr0).norm(), 1e-11) << k;
    }
  }
}

TEST(SimulateBoard, ALeverArmAddsTheCentripetalAndEulerAccelerations) {
  // Noiseless, ideal, no Earth rate: in a turn the IMU at r sees f_b + alpha x r +
  // omega x (omega x r), the body's motion taken from the truth at the same instant.
  Schedule schedule;
  schedule.Hold(0.5).Turn(Vec3(0.2, -0.5, 1).normalized(), 3.0, 1.5).Hold(0.5);
  SimulationOptions options;
  const Vec3 r(0.04, -0.03, 0.02);
  options.board = {BoardImuAt(Quat::Identity(), r, 0.0)};
  const Simulation sim = Simulate(schedule, options);
  const ImuSeries& imu = sim.session.other_imus[0].series;
  double largest = 0.0;
  for (std::size_t k = 200; k < 800; k += 13) {
    const model::SensorInput<double> in = TrueInput(sim, sim.session.series.t_s[k]);
    const Vec3 expected = in.f_b + in.alpha_b.cross(r) + in.omega_b.cross(in.omega_b.cross(r));
    EXPECT_LT((imu.acc[k].cast<double>() - expected).norm(), 2e-5) << k;
    largest = std::max(largest, (expected - in.f_b).norm());
  }
  EXPECT_GT(largest, 0.1);  // the lever arm's accelerations are there to see (m/s^2)
}

TEST(SimulateBoard, ATimeOffsetShiftsWhatTheSamplesSee) {
  // Ideal IMUs at the same place: IMU 1's sample stamped t measured the motion at t + dt, so
  // with dt one sample interval it reads IMU 0's next sample.
  Schedule schedule;
  schedule.Hold(0.5).Turn(Vec3(1, 0, 0), 1.5, 1.0).Hold(0.5);
  SimulationOptions options;
  options.board = {BoardImuAt(Quat::Identity(), Vec3::Zero(), 1.0 / options.rate_hz)};
  const Simulation sim = Simulate(schedule, options);
  const ImuSeries& imu0 = sim.session.series;
  const ImuSeries& imu1 = sim.session.other_imus[0].series;
  double moved = 0.0;
  for (std::size_t k = 150; k < 650; k += 7) {
    EXPECT_LT((imu1.gyr[k] - imu0.gyr[k + 1]).norm(), 1e-6) << k;
    moved = std::max(moved, static_cast<double>((imu0.gyr[k] - imu0.gyr[k + 1]).norm()));
  }
  EXPECT_GT(moved, 1e-3);  // one sample apart is measurably apart
}

TEST(SimulateBoard, ImuZeroIsTheSameWithOrWithoutABoard) {
  // Each IMU draws from its own generator: adding IMUs changes no bit of IMU 0, and the board
  // IMUs' noise is their own.
  SimulationOptions options = SimulationOptions::TypicalMems();
  options.hand.translation_m = 0.1;
  options.hand.vibration_accel = 0.3;
  const Schedule schedule = MultiPose(4, 2.0, 1.0, 5);
  const Simulation alone = Simulate(schedule, options);
  options.board = {BoardImuAt(Quat::Identity(), Vec3::Zero(), 0.0),
                   BoardImuAt(Quat::Identity(), Vec3::Zero(), 0.0)};
  const Simulation board = Simulate(schedule, options);
  EXPECT_EQ(board.session.series.acc, alone.session.series.acc);
  EXPECT_EQ(board.session.series.gyr, alone.session.series.gyr);
  EXPECT_EQ(board.session.series.temp_c, alone.session.series.temp_c);
  ASSERT_EQ(board.session.other_imus.size(), 2u);
  EXPECT_NE(board.session.other_imus[0].series.acc, board.session.series.acc);
  EXPECT_NE(board.session.other_imus[0].series.acc, board.session.other_imus[1].series.acc);
  EXPECT_EQ(board.session.other_imus[1].series.temp_c, board.session.series.temp_c);
}

TEST(SimulateBoard, ItsOwnModelAndTruthApply) {
  // A board IMU's own error model: the still mean of its accelerometer is F_i f_i + b_i.
  SimulationOptions options;
  BoardImuTruth b = BoardImuAt(Quat(Eigen::AngleAxisd(0.02, Vec3::UnitX())), Vec3::Zero(), 0.0);
  SetParameter(b.model, b.truth, "accel.bias.y", 0.2);
  SetParameter(b.model, b.truth, "accel.matrix.zz", 1.01);
  options.board = {b};
  const Simulation sim = Simulate(PaperStatic(1.0), options);
  const Vec3 f_i = b.R_b_i.toRotationMatrix().transpose() * Vec3(0, 0, -units::kStandardGravity);
  const Vec3 expected(f_i.x(), f_i.y() + 0.2, 1.01 * f_i.z());
  EXPECT_LT((sim.session.other_imus[0].series.acc[100].cast<double>() - expected).norm(), 1e-5);
  EXPECT_EQ(sim.board[0].model.t_ref_s, options.t0_s);
}

TEST(Simulate, WhiteNoiseSigmaMatchesTheDensity) {
  SimulationOptions options;
  options.rate_hz = 200.0;
  options.accel_noise_density = 1e-3;
  options.gyro_noise_density = 7e-5;
  options.seed = 4242;
  const Simulation sim = Simulate(PaperStatic(100.0), options);
  const double sigma_a = 1e-3 * std::sqrt(200.0);
  const double sigma_g = 7e-5 * std::sqrt(200.0);
  EXPECT_DOUBLE_EQ(sim.accel_sigma, sigma_a);
  for (int axis = 0; axis < 3; ++axis) {
    const auto [mean_a, std_a] = MeanStd(sim.session.series.acc, axis, 0, 20000);
    const auto [mean_g, std_g] = MeanStd(sim.session.series.gyr, axis, 0, 20000);
    EXPECT_NEAR(std_a / sigma_a, 1.0, 0.03) << "accel axis " << axis;
    EXPECT_NEAR(std_g / sigma_g, 1.0, 0.03) << "gyro axis " << axis;
  }
}

TEST(Simulate, BiasWalkStepsMatchTheDensity) {
  SimulationOptions options;
  options.rate_hz = 100.0;
  options.accel_bias_walk_density = 2e-3;
  options.gyro_bias_walk_density = 5e-5;
  options.seed = 99;
  const Simulation sim = Simulate(PaperStatic(200.0), options);
  const auto& s = sim.session.series;
  // Without white noise, successive differences are the walk's steps, sigma density/sqrt(rate).
  std::vector<Vec3f> diff_a, diff_g;
  for (std::size_t k = 1; k < s.size(); ++k) {
    diff_a.push_back(s.acc[k] - s.acc[k - 1]);
    diff_g.push_back(s.gyr[k] - s.gyr[k - 1]);
  }
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(MeanStd(diff_a, axis, 0, diff_a.size()).second / (2e-3 / 10.0), 1.0, 0.05);
    EXPECT_NEAR(MeanStd(diff_g, axis, 0, diff_g.size()).second / (5e-5 / 10.0), 1.0, 0.05);
  }
}

TEST(Simulate, QuantisedOutputsAreMultiplesOfTheStep) {
  SimulationOptions options;
  options.accel_noise_density = 1e-3;
  options.accel_quantum = 0.01;
  options.gyro_quantum = 1e-3;
  const Simulation sim = Simulate(PaperStatic(1.0), options);
  for (const Vec3f& a : sim.session.series.acc) {
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(a(i) / 0.01, std::round(a(i) / 0.01), 1e-4);
    }
  }
  EXPECT_EQ(sim.session.series.gyr[0], Vec3f::Zero());
}

TEST(Simulate, SameSeedSameSessionOtherSeedDiffers) {
  SimulationOptions options = SimulationOptions::TypicalMems();
  options.site = TestSite();
  options.seed = 7;
  const Schedule schedule = MultiPose(8, 2.0, 1.0, 3);
  const Simulation a = Simulate(schedule, options);
  const Simulation b = Simulate(schedule, options);
  options.seed = 8;
  const Simulation c = Simulate(schedule, options);
  ASSERT_EQ(a.session.series.size(), b.session.series.size());
  EXPECT_EQ(a.session.series.t_s, b.session.series.t_s);
  EXPECT_EQ(a.session.series.acc, b.session.series.acc);
  EXPECT_EQ(a.session.series.gyr, b.session.series.gyr);
  EXPECT_EQ(a.session.series.temp_c, b.session.series.temp_c);
  EXPECT_NE(a.session.series.acc, c.session.series.acc);
  EXPECT_NE(a.session.series.gyr, c.session.series.gyr);
}

TEST(Simulate, GSensitivityShowsInTheStillGyroMeans) {
  SimulationOptions options;
  options.site = TestSite();
  options.model = model::Model::Parse("base+gyro_g_sensitivity");
  const Mat3 G = (Mat3() << 1e-3, -2e-3, 5e-4, 0.0, 1.5e-3, -1e-3, 2e-3, 0.0, -5e-4).finished();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      SetParameter(options.model, options.truth,
                   std::string("gyro_g_sensitivity.G.") + kAxisName[r] + kAxisName[c], G(r, c));
    }
  }
  const Simulation sim = Simulate(MultiPose(9, 2.0, 1.5, 11), options);
  ASSERT_EQ(sim.truth_segments.size(), 9u);
  for (std::size_t j = 0; j < sim.truth_segments.size(); ++j) {
    const Mat3 R_b_n = sim.true_R_n_b[j].toRotationMatrix().transpose();
    const Vec3 f_b = -(R_b_n * options.site.g_n);
    const Vec3 expected = R_b_n * options.site.omega_ie_n + G * f_b;
    const Vec3 measured = SegmentMean(sim.session.series.gyr, sim.truth_segments[j]);
    EXPECT_LT((measured - expected).norm(), 1e-7) << sim.truth_segments[j].label;
    // And the effect is far from negligible: about |G| g.
    EXPECT_GT((expected - R_b_n * options.site.omega_ie_n).norm(), 1e-3);
  }
}

TEST(Simulate, SamplesFollowTheModelAtTheTrueInputs) {
  SimulationOptions options;
  options.site = TestSite();
  options.model = model::Model::Parse(
      "base+time_offset+accel_size_effect+gyro_scale_nonlinearity+accel_temperature_bias:2+"
      "gyro_bias_drift");
  options.truth = RandomParameters(options.model, 1.0, 5);
  options.temperature = TemperatureProfile::Ramp(20.0, 40.0);
  options.t0_s = 1000.0;
  Schedule schedule;
  schedule.Hold(1.0).Turn(Vec3(0.3, -1.0, 0.4), 2.5, 1.5).Hold(1.0);
  const Simulation sim = Simulate(schedule, options);
  EXPECT_EQ(sim.model.t_ref_s, 1000.0);
  const auto& s = sim.session.series;
  for (std::size_t k = 0; k < s.size(); k += 13) {
    const auto in = TrueInput(sim, s.t_s[k]);
    const auto out = sim.model.Predict(sim.truth, in);
    ASSERT_LT((s.acc[k].cast<double>() - out.acc).norm(), 1e-5) << "sample " << k;
    ASSERT_LT((s.gyr[k].cast<double>() - out.gyr).norm(), 1e-6) << "sample " << k;
  }
  // The temperature column follows the ramp.
  EXPECT_FLOAT_EQ(s.temp_c.front(), 20.0f);
  EXPECT_NEAR(s.temp_c.back(), 40.0, 20.0 / 3.5 / 400.0 + 1e-5);
}

TEST(Schedule, MotionIsKinematicallyConsistent) {
  Schedule schedule(Quat(Eigen::AngleAxisd(0.4, Vec3(1, 1, 0).normalized())));
  schedule.Hold(0.5).Turn(Vec3(0.2, -0.7, 1.0), -2.0, 1.3).Hold(0.5);
  const double h = 1e-5;
  for (double t : {0.6, 0.9, 1.2, 1.55, 1.79}) {
    const Motion m = schedule.At(t);
    const Motion plus = schedule.At(t + h), minus = schedule.At(t - h);
    // omega_nb_b = Log(R(t-h)^T R(t+h)) / 2h; alpha = (omega(t+h) - omega(t-h)) / 2h.
    const Eigen::AngleAxisd d(minus.R_n_b.conjugate() * plus.R_n_b);
    EXPECT_LT((d.axis() * d.angle() / (2 * h) - m.omega_nb_b).norm(), 1e-6) << "t " << t;
    EXPECT_LT(((plus.omega_nb_b - minus.omega_nb_b) / (2 * h) - m.alpha_nb_b).norm(), 1e-5)
        << "t " << t;
  }
  EXPECT_EQ(schedule.At(0.2).omega_nb_b, Vec3::Zero());
  EXPECT_LT(AngleBetween(schedule.At(2.3).R_n_b, schedule.end_R_n_b()), 1e-12);
}

TEST(Simulate, TrueAngularAccelerationIsTheDerivativeOfTheTrueRate) {
  SimulationOptions options;
  options.site = TestSite();  // Earth rate seen from the turning body adds to alpha_b
  Schedule schedule;
  schedule.Hold(0.5).Turn(Vec3(1.0, 0.5, -0.3), 3.0, 1.0).Hold(0.5);
  const Simulation sim = Simulate(schedule, options);
  const double h = 1e-6;
  for (double t : {0.7, 1.0, 1.3}) {
    const auto in = TrueInput(sim, t);
    const Vec3 numeric = (TrueInput(sim, t + h).omega_b - TrueInput(sim, t - h).omega_b) / (2 * h);
    EXPECT_LT((in.alpha_b - numeric).norm(), 3e-9) << "t " << t;
  }
}

TEST(Schedule, MultiPoseIsSpreadDistinctAndDeterministic) {
  const Schedule a = MultiPose(24, 3.0, 2.0, 17);
  const Schedule b = MultiPose(24, 3.0, 2.0, 17);
  const Schedule c = MultiPose(24, 3.0, 2.0, 18);
  std::vector<Quat> poses;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.step_start_R_n_b(i).coeffs(), b.step_start_R_n_b(i).coeffs());
    if (a.is_still(i)) poses.push_back(a.step_start_R_n_b(i));
  }
  ASSERT_EQ(poses.size(), 24u);
  EXPECT_LT(AngleBetween(poses[0], Quat::Identity()), 1e-12);  // starts level, x north
  // Every pose distinct by more than 10 deg.
  for (std::size_t i = 0; i < poses.size(); ++i) {
    for (std::size_t j = i + 1; j < poses.size(); ++j) {
      EXPECT_GT(AngleBetween(poses[i], poses[j]), 10.0 * kPi / 180.0) << i << " " << j;
    }
  }
  // All six faces: some pose has each body axis pointing down and up.
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      bool found = false;
      for (const Quat& q : poses) {
        const Vec3 down_b = q.conjugate() * Vec3::UnitZ();
        found = found || std::abs(down_b(axis) - sign) < 1e-9;
      }
      EXPECT_TRUE(found) << "axis " << axis << " sign " << sign;
    }
  }
  // Tilts in between: the down directions beyond the faces are far from every face.
  int tilted = 0;
  for (const Quat& q : poses) {
    const Vec3 down_b = q.conjugate() * Vec3::UnitZ();
    tilted += down_b.cwiseAbs().maxCoeff() < std::cos(20.0 * kPi / 180.0) ? 1 : 0;
  }
  EXPECT_GE(tilted, 10);
  // Stills and single-axis turns alternate; another seed gives other poses.
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a.is_still(i), i % 2 == 0);
  EXPECT_GT(AngleBetween(a.step_start_R_n_b(2), c.step_start_R_n_b(2)), 1e-3);
}

TEST(Schedule, PaperStaticIsOneLevelNorthHold) {
  const Schedule s = PaperStatic();
  ASSERT_EQ(s.size(), 1u);
  EXPECT_TRUE(s.is_still(0));
  EXPECT_DOUBLE_EQ(s.duration_s(), 60.0);
  EXPECT_EQ(s.start_R_n_b().coeffs(), Quat::Identity().coeffs());
}

TEST(Schedule, PaperBenchmarkFollowsSection31) {
  const Schedule s = PaperBenchmark(20.0, 3.0);
  std::vector<std::size_t> stills;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.is_still(i)) stills.push_back(i);
  }
  ASSERT_EQ(stills.size(), 25u);
  auto down_b = [&](std::size_t still) {
    return Vec3(s.step_start_R_n_b(stills[still]).conjugate() * Vec3::UnitZ());
  };
  // 1. The six faces: z, x, y each down then up.
  const Vec3 faces[6] = {Vec3::UnitZ(), -Vec3::UnitZ(), Vec3::UnitX(),
                         -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY()};
  for (int f = 0; f < 6; ++f) EXPECT_LT((down_b(f) - faces[f]).norm(), 1e-9) << f;
  // 2. z parallel then perpendicular to gravity.
  EXPECT_LT((down_b(6) - Vec3::UnitZ()).norm(), 1e-9);
  EXPECT_NEAR(down_b(7).z(), 0.0, 1e-9);
  // 3. Each axis up, then four +90 deg turns about it, a still after each.
  for (int axis = 0; axis < 3; ++axis) {
    const std::size_t first = 8 + 5 * static_cast<std::size_t>(axis);
    for (std::size_t j = first; j < first + 5; ++j) {
      EXPECT_LT((down_b(j) + Vec3::Unit(axis)).norm(), 1e-9) << j;
    }
    for (std::size_t j = first + 1; j < first + 5; ++j) {
      const std::size_t turn = stills[j] - 1;
      const auto& r = std::get<Rotate>(s.steps()[turn]);
      EXPECT_LT((r.axis_b - Vec3::Unit(axis)).norm(), 1e-12);
      EXPECT_DOUBLE_EQ(r.angle_rad, kPi / 2.0);
    }
  }
  // 4. z parallel and perpendicular again.
  EXPECT_LT((down_b(23) - Vec3::UnitZ()).norm(), 1e-9);
  EXPECT_NEAR(down_b(24).z(), 0.0, 1e-9);
  for (std::size_t j : stills) EXPECT_DOUBLE_EQ(s.step_duration_s(j), 20.0);
}

// Turns made by hand (SimulationOptions::hand): the holds stay bit for bit as without a hand
// (its draws come from a generator of its own), the turns carry the vibration, and the hand's
// displacement ends at rest: the specific force integrated over a turn with the true attitude
// gives back gravity's velocity change, as a turntable's turn does.
TEST(Simulate, HandHeldTurnsLeaveTheHoldsAsTheyWere) {
  SimulationOptions options = SimulationOptions::TypicalMems();
  options.rate_hz = 100.0;
  options.seed = 21;
  const Schedule schedule = MultiPose(6, 2.0, 2.0, 21);
  const Simulation table = Simulate(schedule, options);
  options.hand.vibration_accel = 1.0;
  options.hand.translation_m = 0.1;
  const Simulation hand = Simulate(schedule, options);
  ASSERT_EQ(table.session.series.size(), hand.session.series.size());
  std::size_t turn_samples = 0, differing = 0;
  for (std::size_t k = 0; k < hand.session.series.size(); ++k) {
    const bool still = std::any_of(hand.truth_segments.begin(), hand.truth_segments.end(),
                                   [&](const StillSegment& s) { return s.begin <= k && k < s.end; });
    if (still) {
      ASSERT_EQ(hand.session.series.acc[k], table.session.series.acc[k]) << "sample " << k;
    } else {
      ++turn_samples;
      differing += hand.session.series.acc[k] != table.session.series.acc[k] ? 1 : 0;
    }
    ASSERT_EQ(hand.session.series.gyr[k], table.session.series.gyr[k]) << "sample " << k;
  }
  EXPECT_GT(turn_samples, 0u);
  EXPECT_GT(differing, turn_samples * 9 / 10);
}

TEST(Simulate, AHandsTranslationEndsAtRest) {
  Schedule schedule;
  schedule.Hold(1.0).Turn(Vec3(1.0, 2.0, -0.5).normalized(), 1.7, 2.0).Hold(1.0);
  SimulationOptions options;  // noiseless, Site::Unknown
  options.rate_hz = 400.0;
  options.hand.translation_m = 0.3;
  const Simulation sim = Simulate(schedule, options);
  const auto& s = sim.session.series;
  // Over the turn's samples (400 .. 1200): sum h R_n_b f_b + g_n T = the velocity change, 0.
  Vec3 dv = Vec3::Zero();
  double largest = 0.0;
  for (std::size_t k = 400; k < 1200; ++k) {
    const Motion m = schedule.At(static_cast<double>(k) / 400.0);
    const Vec3 f_n = m.R_n_b * s.acc[k].cast<double>();
    dv += (f_n + options.site.g_n) / 400.0;
    largest = std::max(largest, (f_n + options.site.g_n).norm());
  }
  EXPECT_LT(dv.norm(), 1e-5);
  // It moved: 0.3 m over 2 s peaks at 0.3 (2 pi / 4) = 0.47 m/s^2.
  EXPECT_NEAR(largest, 0.3 * 2.0 * kPi / 4.0, 1e-3);
}

TEST(Simulate, BadOptionsThrowNamingTheField) {
  SimulationOptions options;
  options.rate_hz = 0.0;
  EXPECT_THROW(Simulate(PaperStatic(1.0), options), Error);
  options = SimulationOptions();
  options.gyro_noise_density = -1.0;
  EXPECT_THROW(Simulate(PaperStatic(1.0), options), Error);
  options = SimulationOptions();
  options.truth = {{1.0}};
  try {
    Simulate(PaperStatic(1.0), options);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("blocks"), std::string::npos);
  }
  options = SimulationOptions();
  options.hand.vibration_accel = -1.0;
  try {
    Simulate(PaperStatic(1.0), options);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("hand.vibration_accel"), std::string::npos);
  }
  EXPECT_THROW(Simulate(Schedule(), SimulationOptions()), Error);
  EXPECT_THROW(Schedule().Turn(Vec3::Zero(), 1.0, 1.0), Error);
  EXPECT_THROW(Schedule().Hold(-1.0), Error);
  EXPECT_THROW(MultiPose(0, 1.0, 1.0, 1), Error);
  SimulationOptions board;
  board.board = {BoardImuAt(Quat::Identity(), Vec3::Zero(), 2.0)};
  try {
    Simulate(PaperStatic(1.0), board);
    ADD_FAILURE() << "a time offset of 2 s was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("board IMU 1: time offset 2"), std::string::npos) << e.what();
  }
}

TEST(TemperatureProfile, RampAndUpDownValues) {
  const auto ramp = TemperatureProfile::Ramp(20.0, 40.0);
  EXPECT_DOUBLE_EQ(ramp.At(50.0, 100.0), 30.0);
  const auto updown = TemperatureProfile::UpDown(20.0, 50.0, 100.0);
  EXPECT_DOUBLE_EQ(updown.At(0.0, 1000.0), 20.0);
  EXPECT_DOUBLE_EQ(updown.At(25.0, 1000.0), 35.0);
  EXPECT_DOUBLE_EQ(updown.At(50.0, 1000.0), 50.0);
  EXPECT_DOUBLE_EQ(updown.At(175.0, 1000.0), 35.0);
  EXPECT_THROW(TemperatureProfile::UpDown(20.0, 50.0, 0.0).Validate(), Error);
}

}  // namespace
}  // namespace plumb::sim

namespace plumb::sim {
namespace {

const ScheduleOptionNames kNames{"KIND", "POSES", "TURN"};

TEST(NamedSchedule, DefaultsAreTheFrontEndsDefaults) {
  ScheduleRequest r;
  r.seed = 7;
  const Schedule multipose = NamedSchedule(r, kNames);
  const Schedule expected = MultiPose(12, 5.0, 2.0, 7);
  EXPECT_EQ(multipose.size(), expected.size());
  EXPECT_DOUBLE_EQ(multipose.duration_s(), expected.duration_s());
  EXPECT_DOUBLE_EQ(multipose.step_duration_s(0), 5.0);
  r.kind = "paper-static";
  EXPECT_DOUBLE_EQ(NamedSchedule(r, kNames).duration_s(), 60.0);
  r.kind = "paper-benchmark";
  EXPECT_DOUBLE_EQ(NamedSchedule(r, kNames).duration_s(), PaperBenchmark(20.0, 3.0).duration_s());
  r.still_s = 4.0;
  r.turn_s = 1.5;
  EXPECT_DOUBLE_EQ(NamedSchedule(r, kNames).duration_s(), PaperBenchmark(4.0, 1.5).duration_s());
}

TEST(NamedSchedule, ErrorsNameTheOptionsAsTheFrontEndDoes) {
  const auto message = [](const ScheduleRequest& r) -> std::string {
    try {
      NamedSchedule(r, kNames);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  ScheduleRequest r;
  r.kind = "paper-static";
  r.poses = 3;
  EXPECT_EQ(message(r), "POSES applies to KIND multipose only");
  r.poses.reset();
  r.turn_s = 1.0;
  EXPECT_EQ(message(r), "TURN does not apply to KIND paper-static");
  r.kind = "spin";
  EXPECT_EQ(message(r), "KIND must be multipose, paper-static or paper-benchmark (got 'spin')");
}

}  // namespace
}  // namespace plumb::sim

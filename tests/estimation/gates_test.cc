// The gates (estimation/gates.h) on made series and simulated sessions, and the covariance as
// reported (estimation/uncertainty.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "plumb/core/notice.h"
#include "plumb/core/option_name.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/gates.h"
#include "plumb/estimation/uncertainty.h"
#include "plumb/report/calibration_text.h"
#include "plumb/report/summary.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb::estimation {
namespace {

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The gate called `name`, or nullptr.
const Gate* Find(const std::vector<Gate>& gates, const std::string& name) {
  for (const auto& g : gates) {
    if (g.name == name) return &g;
  }
  return nullptr;
}

std::string Names(const std::vector<Gate>& gates) {
  std::string out;
  for (const auto& g : gates) out += g.name + " ";
  return out;
}

/// `n` samples at 100 Hz of a still, level IMU with white noise.
ImuSeries Level(std::size_t n) {
  std::mt19937_64 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  ImuSeries s;
  for (std::size_t i = 0; i < n; ++i) {
    s.t_s.push_back(0.01 * static_cast<double>(i));
    s.acc.emplace_back(noise(rng), noise(rng), -9.81f + noise(rng));
    s.gyr.emplace_back(0.001f * noise(rng), 0.001f * noise(rng), 0.001f * noise(rng));
  }
  return s;
}

TEST(Gates, OutOfRangeNamesTheFirstSampleAndTheCount) {
  ImuSeries s = Level(1000);
  s.acc[300].z() = 4.7e21f;                                    // flipped bytes
  s.gyr[500].x() = std::numeric_limits<float>::quiet_NaN();    // a bad record
  const std::vector<StillSegment> still = {{400, 600, "still #1"}};
  const std::vector<Gate> gates = CheckSamples(s, still);
  const Gate* g = Find(gates, "out_of_range");
  ASSERT_NE(g, nullptr) << Names(gates);
  EXPECT_TRUE(Contains(g->message, "2 samples outside any IMU's range (an axis beyond 313.8 m/s^2 "
                                   "(32 g) or 69.81 rad/s (4000 deg/s), or not finite), 1 of them "
                                   "inside the still segments; the first at t = 3 s (sample 300)"))
      << g->message;
}

// Issue 35 item 7: a temperature no MEMS IMU operates at (1e6 degC was taken) is out of range.
TEST(Gates, ATemperatureNoImuOperatesAtIsOutOfRange) {
  ImuSeries s = Level(1000);
  s.temp_c.assign(s.size(), 31.5f);
  EXPECT_EQ(Find(CheckSamples(s, {}), "out_of_range"), nullptr);
  s.temp_c[250] = 1e6f;
  s.temp_c[700] = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Gate> gates = CheckSamples(s, {});
  const Gate* g = Find(gates, "out_of_range");
  ASSERT_NE(g, nullptr) << Names(gates);
  EXPECT_EQ(g->message, "2 temperatures outside any MEMS IMU's operating range (beyond -60 .. 150 "
                        "degC, or not finite); the first at t = 2.5 s (sample 250): 1000000 degC. "
                        "A corrupt log or a column that is not degC: cut them out "
                        "(FlightLogSelection::from_s/to_s) "
                        "or fix the input before trusting a temperature model");
  s.acc[300].z() = 4.7e21f;  // with a sample out of range too: one gate, both said
  const std::vector<Gate> both = CheckSamples(s, {});
  ASSERT_EQ(std::count_if(both.begin(), both.end(),
                          [](const Gate& x) { return x.name == "out_of_range"; }),
            1);
  EXPECT_TRUE(Contains(Find(both, "out_of_range")->message, "; and 2 temperatures outside"));
}

TEST(Gates, CountsHaveTheirOwnRange) {
  ImuSeries s = Level(200);
  for (auto& a : s.acc) a *= -16384.0f / 9.81f;  // a 2 g MPU-6050 in counts
  s.acc_unit = "counts";
  EXPECT_EQ(Find(CheckSamples(s, {}), "out_of_range"), nullptr);
  s.acc[10].x() = 3e6f;
  EXPECT_NE(Find(CheckSamples(s, {}), "out_of_range"), nullptr);
}

TEST(Gates, ARunAtTheExtremeOutsideTheStillSegmentsIsSaturation) {
  ImuSeries s = Level(1000);
  // A turn about z from sample 400 to 600 whose peak the gyroscope clips at 250 deg/s.
  const float clip = static_cast<float>(250.0 * units::kRadPerDeg);
  for (std::size_t i = 400; i < 600; ++i) {
    const double x = static_cast<double>(i - 400) / 200.0;
    s.gyr[i].z() = std::min(clip, static_cast<float>(6.0 * std::sin(units::kPi * x)));
  }
  const std::vector<StillSegment> still = {{0, 400, "before"}, {600, 1000, "after"}};
  const std::vector<Gate> gates = CheckSamples(s, still);
  const Gate* g = Find(gates, "saturated");
  ASSERT_NE(g, nullptr);
  EXPECT_TRUE(Contains(g->message, "gyro z sits at 4.363323 rad/s for ")) << g->message;
  // The same flat top inside a still segment is a pose, not a clipped turn.
  const std::vector<StillSegment> covering = {{0, 1000, "all"}};
  EXPECT_EQ(Find(CheckSamples(s, covering), "saturated"), nullptr);
  // A reading that sits still at a constant value (coarse quantisation) is no saturation.
  ImuSeries flat = Level(500);
  for (auto& a : flat.acc) a = Vec3f(0, 0, -9.81f);
  EXPECT_EQ(Find(CheckSamples(flat, {}), "saturated"), nullptr);
}

/// A multi-pose session as calibrate_sim_test.cc makes it.
sim::Simulation MultiPose(std::uint64_t seed, int poses = 12, double still_s = 6.0) {
  sim::SimulationOptions opt = sim::SimulationOptions::WhiteMems();
  opt.rate_hz = 100.0;
  opt.model = model::Model::Parse("base");
  opt.truth = sim::RandomParameters(opt.model, 1.0, seed);
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
  opt.seed = seed;
  return sim::Simulate(sim::MultiPose(poses, still_s, 2.0, seed), opt);
}

std::vector<StillSegment> FreeAttitudes(std::vector<StillSegment> segments) {
  for (auto& s : segments) s.known_R_n_b.reset();
  return segments;
}

TEST(Gates, AGoodSessionPassesEveryGate) {
  const sim::Simulation s = MultiPose(31);
  const CalibrationResult r =
      Calibrate(s.session.series, FreeAttitudes(s.truth_segments), s.model, s.site);
  EXPECT_TRUE(r.fit.gates.empty()) << Names(r.fit.gates) << report::FullReport(r);
  EXPECT_EQ(r.fit.distinct_poses, 12);
  EXPECT_TRUE(Contains(report::FitVerdict(r.fit), "consistent with the noise"))
      << report::FitVerdict(r.fit);
}

/// The warning with `code`, or nullptr.
const Notice* FindWarning(const std::vector<Notice>& warnings, const std::string& code) {
  for (const Notice& w : warnings) {
    if (w.code == code) return &w;
  }
  return nullptr;
}

// Issue 36 item 3: the fit's warnings carry their code and the options their advice names.
TEST(FitWarnings, TheSiteAndTheHeadingAreSaidWithTheirCodeAndOptions) {
  const sim::Simulation s = MultiPose(31);
  const std::vector<StillSegment> segments = FreeAttitudes(s.truth_segments);
  const CalibrationResult at_site = Calibrate(s.session.series, segments, s.model, s.site);
  EXPECT_EQ(FindWarning(at_site.fit.warnings, "site_unknown"), nullptr);
  const Notice* heading = FindWarning(at_site.fit.warnings, "heading_assumed");
  ASSERT_NE(heading, nullptr) << report::FullReport(at_site);
  EXPECT_TRUE(Contains(heading->message, "the heading of the first still pose is held at 0"))
      << heading->message;
  EXPECT_EQ(heading->options, (std::vector<Option>{Option::kHeading, Option::kLevelNorth}));

  const CalibrationResult nowhere =
      Calibrate(s.session.series, segments, s.model, geo::Site::Unknown());
  EXPECT_EQ(FindWarning(nowhere.fit.warnings, "heading_assumed"), nullptr);
  const Notice* site = FindWarning(nowhere.fit.warnings, "site_unknown");
  ASSERT_NE(site, nullptr) << report::FullReport(nowhere);
  EXPECT_TRUE(Contains(site->message, "no site given: gravity fixed at ")) << site->message;
  EXPECT_TRUE(Contains(site->message, "(give " + OptionText(Option::kSite) + ")"))
      << site->message;
  EXPECT_EQ(site->options, std::vector<Option>{Option::kSite});

  ImuSeries accel_only = s.session.series;
  accel_only.gyr.clear();
  const CalibrationResult no_gyro =
      Calibrate(accel_only, segments, s.model, geo::Site::Unknown());
  const Notice* gyro = FindWarning(no_gyro.fit.warnings, "no_gyroscope");
  ASSERT_NE(gyro, nullptr) << report::FullReport(no_gyro);
  EXPECT_EQ(gyro->message, "the input has no gyroscope: calibrating the accelerometer only");
  EXPECT_TRUE(gyro->options.empty());
}

TEST(Gates, PiecesOfOnePoseAreOnePose) {
  const sim::Simulation s = MultiPose(32);
  const StillSegment first = FreeAttitudes(s.truth_segments).front();
  std::vector<StillSegment> pieces;
  const std::size_t step = first.count() / 12;
  for (std::size_t k = 0; k < 12; ++k) {
    pieces.push_back({first.begin + k * step + 2, first.begin + (k + 1) * step, "piece"});
  }
  const CalibrationResult r = Calibrate(s.session.series, pieces, s.model, s.site);
  EXPECT_EQ(r.fit.distinct_poses, 1);
  const Gate* g = Find(r.fit.gates, "one_pose");
  ASSERT_NE(g, nullptr) << Names(r.fit.gates);
  EXPECT_TRUE(Contains(g->message, "the 12 still segments lie in 1 distinct pose (segments 1-12 "
                                   "have the same gravity direction within the noise and no turn "
                                   "between them): the rank ("))
      << g->message;
  EXPECT_FALSE(Contains(report::FitVerdict(r.fit), "consistent with the noise"));
}

// Issue 34 item 4: motion longer than CalibrationOptions::max_motion_s is left out of the fit,
// named in a note and in FitReport::not_turns; not_a_turn fires only where that leaves the
// gyroscope's matrix undetermined.
TEST(Gates, MotionLeftOutAsNoTurnIsNamedAndGatedWhereTheGyroscopeNeedsIt) {
  const sim::Simulation s = MultiPose(35);
  std::vector<StillSegment> segments = FreeAttitudes(s.truth_segments);
  // Without hold 6 the motion from hold 5 to hold 7 lasts 10 s, every other one 2 s.
  segments.erase(segments.begin() + 5);
  CalibrationOptions options;
  options.max_motion_s = 8.0;
  const CalibrationResult one = Calibrate(s.session.series, segments, s.model, s.site, options);
  ASSERT_EQ(one.fit.not_turns.size(), 1u);
  EXPECT_EQ(one.fit.not_turns[0].from, 4u);
  EXPECT_EQ(one.fit.not_turns[0].to, 5u);
  EXPECT_EQ(one.fit.motion_segments, 9);
  EXPECT_EQ(Find(one.fit.gates, "not_a_turn"), nullptr) << Names(one.fit.gates);
  const std::string note = "between '" + segments[4].label + "' and '" + segments[5].label +
                           "' is left out of the fit, not a turn: longer than 8 s";
  EXPECT_EQ(std::count_if(one.fit.notes.begin(), one.fit.notes.end(),
                          [&](const Notice& n) { return n.code == "not_a_turn" && Contains(n.message, note); }),
            1)
      << report::FullReport(one);
  // Every turn longer than allowed: no turn determines the gyroscope's matrix.
  options.max_motion_s = 1.0;
  const CalibrationResult none = Calibrate(s.session.series, segments, s.model, s.site, options);
  EXPECT_EQ(none.fit.not_turns.size(), 10u);
  EXPECT_EQ(none.fit.motion_segments, 0);
  const Gate* g = Find(none.fit.gates, "not_a_turn");
  ASSERT_NE(g, nullptr) << Names(none.fit.gates) << report::FullReport(none);
  EXPECT_TRUE(Contains(g->message, "without it the turns left (0) leave 9 parameters of the "
                                   "gyroscope's matrix undetermined or known only to more than "
                                   "0.03 (gyro.matrix.xx, ...)"))
      << g->message;
  EXPECT_FALSE(Contains(report::FitVerdict(none.fit), "consistent with the noise"));
}

// Issue 37: a turn whose samples stop for longer than CalibrationOptions::max_turn_gap_s (the
// ROS AR.Drone bag's link dropped for 1 s inside a hand turn) is left out as no turn: the
// integration would hold the last rate across the gap and miss the turn.
TEST(Gates, ATurnWhoseSamplesStopIsNotIntegrated) {
  const sim::Simulation s = MultiPose(35);
  const std::vector<StillSegment> segments = FreeAttitudes(s.truth_segments);
  // Drop 0.8 s of samples in the middle of the motion from hold 3 to hold 4.
  ImuSeries dropped = s.session.series;
  const std::vector<double>& t = dropped.t_s;
  const std::size_t middle = (segments[2].end + segments[3].begin) / 2;
  const double from = t[middle];
  const auto a = static_cast<std::ptrdiff_t>(middle + 1);
  const auto b = std::lower_bound(t.begin(), t.end(), from + 0.8) - t.begin();
  dropped.t_s.erase(dropped.t_s.begin() + a, dropped.t_s.begin() + b);
  dropped.acc.erase(dropped.acc.begin() + a, dropped.acc.begin() + b);
  dropped.gyr.erase(dropped.gyr.begin() + a, dropped.gyr.begin() + b);
  if (!dropped.temp_c.empty()) dropped.temp_c.erase(dropped.temp_c.begin() + a, dropped.temp_c.begin() + b);
  std::vector<StillSegment> shifted = segments;
  for (StillSegment& g : shifted) {
    if (g.begin >= static_cast<std::size_t>(b)) {
      g.begin -= static_cast<std::size_t>(b - a);
      g.end -= static_cast<std::size_t>(b - a);
    }
  }
  const CalibrationResult r = Calibrate(dropped, shifted, s.model, s.site);
  ASSERT_EQ(r.fit.not_turns.size(), 1u) << report::FullReport(r);
  const NotATurn& m = r.fit.not_turns[0];
  EXPECT_EQ(m.from, 2u);
  ASSERT_TRUE(m.gap.has_value());
  EXPECT_NEAR(m.gap->length_s, 0.8, 0.05);
  EXPECT_NEAR(m.gap->t_s, from, 0.02);
  EXPECT_EQ(r.fit.motion_segments, 10);  // of 11
  const std::string note = "is left out of the fit, not a turn: its samples stop for ";
  EXPECT_EQ(std::count_if(r.fit.notes.begin(), r.fit.notes.end(),
                          [&](const Notice& n) { return n.code == "not_a_turn" && Contains(n.message, note); }),
            1)
      << report::FullReport(r);
  // A gap within the limit is integrated.
  CalibrationOptions lenient;
  lenient.max_turn_gap_s = 1.0;
  EXPECT_TRUE(Calibrate(dropped, shifted, s.model, s.site, lenient).fit.not_turns.empty());
}

// Issue 34 item 4: what the log says the vehicle did (CalibrationOptions::log_motion, from
// its land detector or GPS) makes a quiet hold not still and a short motion no turn, whatever
// the samples say: a smooth cruise or a hover logged at tens of hertz can look still.
TEST(Gates, WhereTheLogSaysTheVehicleFlewNothingIsStillAndNothingATurn) {
  const sim::Simulation s = MultiPose(35);
  const std::vector<StillSegment> segments = FreeAttitudes(s.truth_segments);
  const std::vector<double>& t = s.session.series.t_s;
  const CalibrationResult clean = Calibrate(s.session.series, segments, s.model, s.site);
  ASSERT_TRUE(clean.fit.gates.empty()) << Names(clean.fit.gates);
  CalibrationOptions options;
  // Airborne over the motion from hold 5 to hold 6 only (it ends before hold 6 begins).
  LogMotion air;
  air.t_begin_s = t[segments[4].end - 1] + 0.1;
  air.t_end_s = t[segments[5].begin] - 0.1;
  air.source = "EV NOT_LANDED .. LAND_COMPLETE";
  // Moving by GPS in the middle of hold 9: a vehicle driven, its IMU quiet.
  LogMotion gps;
  gps.evidence = LogMotion::Evidence::kGpsMoving;
  gps.t_begin_s = t[(segments[8].begin + segments[8].end) / 2];
  gps.t_end_s = gps.t_begin_s + 1.5;
  gps.source = "GPS";
  gps.max_ground_speed_m_s = 4.0;
  gps.ground_distance_m = 2.0;
  options.log_motion = {air, gps};
  const CalibrationResult r = Calibrate(s.session.series, segments, s.model, s.site, options);
  ASSERT_EQ(r.fit.not_turns.size(), 1u);  // into hold 6 (the GPS's run lies inside hold 9)
  EXPECT_EQ(r.fit.not_turns[0].from, 4u);
  ASSERT_TRUE(r.fit.not_turns[0].flown.has_value());
  EXPECT_EQ(r.fit.not_turns[0].flown->source, air.source);
  const std::string note = "between '" + segments[4].label + "' and '" + segments[5].label +
                           "' is left out of the fit, not a turn: the log says the vehicle was "
                           "airborne ";
  EXPECT_EQ(std::count_if(r.fit.notes.begin(), r.fit.notes.end(),
                          [&](const Notice& n) { return n.code == "not_a_turn" && Contains(n.message, note); }),
            1)
      << report::FullReport(r);
  const Gate* g = Find(r.fit.gates, "not_still");
  ASSERT_NE(g, nullptr) << Names(r.fit.gates);
  EXPECT_TRUE(Contains(g->message, "1 of 12 still segments scatter far beyond an IMU at rest, "
                                   "per sample, or fall where the log says the vehicle flew or "
                                   "moved: '" + segments[8].label + "' ("))
      << g->message;
  EXPECT_TRUE(Contains(g->message, "the log says the vehicle was moving ")) << g->message;
  EXPECT_TRUE(Contains(g->message, " by GPS (up to 4.0 m/s over ground, 2 m)")) << g->message;
  EXPECT_FALSE(Contains(report::FitVerdict(r.fit), "consistent with the noise"));
}

TEST(Gates, TheIterationLimitFailsNotConverged) {
  const sim::Simulation s = MultiPose(33);
  CalibrationOptions options;
  options.max_iterations = 1;
  const CalibrationResult r =
      Calibrate(s.session.series, FreeAttitudes(s.truth_segments), s.model, s.site, options);
  EXPECT_FALSE(r.fit.converged);
  const Gate* g = Find(r.fit.gates, "not_converged");
  ASSERT_NE(g, nullptr) << Names(r.fit.gates);
  EXPECT_TRUE(Contains(g->message, "the solver did not converge: its last solve stopped after ")) << g->message;
  EXPECT_TRUE(Contains(g->message, "Termination: NO_CONVERGENCE")) << g->message;
  // The option its advice names, as data (Gate::options).
  EXPECT_EQ(g->options, std::vector<Option>{Option::kMaxIterations});
  const std::string verdict = report::FitVerdict(r.fit);
  EXPECT_FALSE(Contains(verdict, "consistent with the noise")) << verdict;
  EXPECT_TRUE(Contains(verdict, "the fit failed a gate (not_converged)")) << verdict;
}

TEST(Gates, TimeStampsTenTimesTooFarApartShowAsAGyroScaleOfTen) {
  sim::Simulation s = MultiPose(34);
  for (auto& t : s.session.series.t_s) t *= 10.0;  // --rate 10 on 100 Hz data
  const CalibrationResult r =
      Calibrate(s.session.series, FreeAttitudes(s.truth_segments), s.model, s.site);
  const Gate* g = Find(r.fit.gates, "unit_or_rate");
  ASSERT_NE(g, nullptr) << Names(r.fit.gates);
  EXPECT_TRUE(Contains(g->message, "the samples are 0.1 s apart (10 Hz), the turns say about 10"))
      << g->message;
  EXPECT_NEAR(r.calibration.GyroMatrix().diagonal().mean(), 10.0, 0.5);
}

TEST(Gates, AccelerometerInGUnitsIsNamed) {
  sim::Simulation s = MultiPose(35);
  for (auto& a : s.session.series.acc) a /= static_cast<float>(units::kStandardGravity);
  const CalibrationResult r =
      Calibrate(s.session.series, FreeAttitudes(s.truth_segments), s.model, s.site);
  const Gate* g = Find(r.fit.gates, "unit_or_rate");
  ASSERT_NE(g, nullptr) << Names(r.fit.gates);
  EXPECT_TRUE(Contains(g->message, "the samples look like g, not m/s^2: give InputOptions::acc.unit = g"))
      << g->message;
}

TEST(Gates, GyroscopeInDegreesIsNamed) {
  sim::Simulation s = MultiPose(36);
  for (auto& w : s.session.series.gyr) w *= static_cast<float>(units::kDegPerRad);
  const CalibrationResult r =
      Calibrate(s.session.series, FreeAttitudes(s.truth_segments), s.model, s.site);
  const Gate* g = Find(r.fit.gates, "unit_or_rate");
  ASSERT_NE(g, nullptr) << Names(r.fit.gates);
  EXPECT_TRUE(Contains(g->message, "InputOptions::gyr.unit = deg/s")) << g->message;
}

TEST(Uncertainty, ParameterCovarianceHoldsTheSigmasInOrder) {
  const sim::Simulation s = MultiPose(37);
  const CalibrationResult r =
      Calibrate(s.session.series, FreeAttitudes(s.truth_segments), s.model, s.site);
  const NamedCovariance c = ParameterCovariance(r.calibration);
  ASSERT_EQ(c.names.size(), 21u);
  ASSERT_EQ(c.matrix.rows(), 21);
  EXPECT_LT((c.matrix - c.matrix.transpose()).norm(), 1e-12 * c.matrix.norm());
  for (std::size_t i = 0; i < c.names.size(); ++i) {
    EXPECT_EQ(c.names[i], r.calibration.parameters[i].name);
    EXPECT_NEAR(std::sqrt(c.matrix(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i))),
                r.calibration.parameters[i].sigma, 1e-9 * r.calibration.parameters[i].sigma);
  }
}

TEST(Uncertainty, DeterminedCovarianceHoldsTheCombinationSigmas) {
  // The paper's one level pose: singular, with determined combinations.
  sim::SimulationOptions opt = sim::SimulationOptions::TypicalMems();
  opt.rate_hz = 100.0;
  opt.truth = sim::RandomParameters(opt.model, 1.0, 5);
  opt.site = geo::Site::At(6.67, -1.57, 250.0, "flags");
  opt.seed = 5;
  const sim::Simulation s = sim::Simulate(sim::PaperStatic(60.0), opt);
  for (const bool ceres : {true, false}) {
    CalibrationOptions options;
    options.use_ceres_covariance = ceres;
    const CalibrationResult r = Calibrate(s.session.series, s.truth_segments, s.model, s.site, options);
    const auto& determined = r.calibration.observability.determined;
    ASSERT_GE(determined.size(), 3u);
    const NamedCovariance c = DeterminedCovariance(r.calibration);
    ASSERT_EQ(c.matrix.rows(), static_cast<Eigen::Index>(determined.size()));
    for (std::size_t i = 0; i < determined.size(); ++i) {
      EXPECT_EQ(c.names[i], determined[i].text);
      const auto ii = static_cast<Eigen::Index>(i);
      EXPECT_NEAR(std::sqrt(c.matrix(ii, ii)), determined[i].sigma, 1e-6 * determined[i].sigma)
          << determined[i].text << (ceres ? " (ceres)" : " (pseudo-inverse)");
    }
    EXPECT_LT((c.matrix - c.matrix.transpose()).norm(), 1e-9 * c.matrix.norm());
  }
}

TEST(Uncertainty, SigmasAreScaledOnlyAboveTheBand) {
  FitReport fit;
  fit.dof = 200;  // band: 1 + 3 sqrt(2 / 200) = 1.3
  fit.chi2 = 1.25 * fit.dof;
  EXPECT_FALSE(Chi2AboveBand(fit));
  EXPECT_EQ(SigmaScale(fit), 1.0);
  fit.chi2 = 4.0 * fit.dof;
  EXPECT_TRUE(Chi2AboveBand(fit));
  EXPECT_DOUBLE_EQ(SigmaScale(fit), 2.0);
  fit.dof = 0;
  EXPECT_FALSE(Chi2AboveBand(fit));
}

}  // namespace
}  // namespace plumb::estimation

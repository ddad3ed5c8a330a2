// Diagnosing the board's IMUs each alone and together (diagnostics/board_diagnosis.h): on
// simulated boards with known truth, an IMU whose own error model misses an effect is named and
// its candidates find the effect, the others are not blamed; an IMU that turns on its board
// within a turn (a mount that sags, its own gyroscope seeing the turn) fits alone and fails the
// rigid-board test; a rigid board passes it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "plumb/core/so3.h"
#include "plumb/core/units.h"
#include "plumb/diagnostics/board_diagnosis.h"
#include "plumb/estimation/uncertainty.h"
#include "plumb/geo/site.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb::diagnostics {
namespace {

constexpr double kRateHz = 100.0;

/// A 16-pose session (5 s holds, 2 s turns) of a board of `imus` IMUs of random base
/// parameters, white noise, true segments given with their attitudes unknown.
struct BoardSession {
  sim::Simulation sim;
  std::vector<StillSegment> segments;
  DiagnoseOptions options;
};

/// `board_truth`: the scale of the other IMUs' random parameters (0: ideal IMUs).
sim::SimulationOptions BoardOptions(int imus, std::uint64_t seed, double board_truth = 1.0) {
  sim::SimulationOptions opt = sim::SimulationOptions::WhiteMems();
  opt.rate_hz = kRateHz;
  opt.model = model::Model::Parse("base");
  opt.truth = sim::RandomParameters(opt.model, 1.0, seed);
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "test");
  opt.seed = seed;
  opt.board = sim::RandomBoard(imus, opt.model, board_truth, seed + 1);
  return opt;
}

BoardSession Simulate(const sim::SimulationOptions& opt, std::uint64_t seed) {
  BoardSession s;
  s.sim = sim::Simulate(sim::MultiPose(16, 5.0, 2.0, seed), opt);
  s.segments = s.sim.truth_segments;
  for (auto& seg : s.segments) seg.known_R_n_b.reset();
  s.options.calibration.constant_bias = true;  // white noise: one constant bias matches
  // The test is of the board, not the catalogue: the one candidate planted, and earth_rate,
  // which these data determine and no IMU misses.
  s.options.candidates = {"gyro_g_sensitivity", "earth_rate"};
  return s;
}

BoardDiagnosis DiagnoseIt(const BoardSession& s) {
  return DiagnoseBoard(s.sim.session.series, s.sim.session.other_imus, s.segments,
                       model::Model::Parse("base"), s.sim.site, s.options);
}

TEST(BoardDiagnosis, AnImuWhoseModelMissesAnEffectIsNamedAndTheOthersAreNot) {
  sim::SimulationOptions opt = BoardOptions(3, 11);
  // IMU 2 alone has a g-sensitive gyroscope: its base blocks as drawn, G's planted.
  sim::BoardImuTruth& imu2 = opt.board[1];
  const model::ParameterBlocks base = imu2.truth;
  imu2.model = model::Model::Parse("base+gyro_g_sensitivity");
  imu2.truth = imu2.model.ZeroParameters();
  std::copy(base.begin(), base.end(), imu2.truth.begin());
  sim::SetParameter(imu2.model, imu2.truth, "gyro_g_sensitivity.G.xy", 1e-3);
  sim::SetParameter(imu2.model, imu2.truth, "gyro_g_sensitivity.G.zx", -7e-4);
  const BoardDiagnosis d = DiagnoseIt(Simulate(opt, 11));

  ASSERT_EQ(d.imus.size(), 3u);
  EXPECT_FALSE(d.imus[0].own_misfit) << d.imus[0].diagnosis.fit.fit.chi2_dof();
  EXPECT_FALSE(d.imus[1].own_misfit) << d.imus[1].diagnosis.fit.fit.chi2_dof();
  EXPECT_TRUE(d.imus[2].own_misfit) << d.imus[2].diagnosis.fit.fit.chi2_dof();
  EXPECT_EQ(d.imus[2].instance, 2);
  const Candidate* advised = Recommended(d.imus[2].diagnosis);
  ASSERT_NE(advised, nullptr);
  EXPECT_EQ(advised->effect, "gyro_g_sensitivity");
  EXPECT_EQ(Recommended(d.imus[0].diagnosis), nullptr);
  EXPECT_EQ(Recommended(d.imus[1].diagnosis), nullptr);
  // The rigidity is tested on IMUs 0 and 1, refitted together without IMU 2's misfit.
  ASSERT_TRUE(d.rigid.untested.empty()) << d.rigid.untested;
  EXPECT_EQ(d.rigid.imus, (std::vector<std::size_t>{0, 1}));
  ASSERT_TRUE(d.rigid_board.has_value());
  EXPECT_EQ(d.rigid_board->calibration.board.size(), 1u);
  EXPECT_TRUE(d.rigid.holds()) << d.rigid.difference() << " on " << d.rigid.constraints();
  // The board refitted with IMU 2's advice: the misfit gone, the advice given.
  ASSERT_TRUE(d.next.has_value());
  EXPECT_EQ(d.next->models[0].spec(), "base");
  EXPECT_EQ(d.next->models[1].spec(), "base");
  EXPECT_EQ(d.next->models[2].spec(), "base+gyro_g_sensitivity");
  EXPECT_TRUE(d.next->advised);
  EXPECT_TRUE(estimation::Chi2AboveBand(d.board.fit));
  EXPECT_FALSE(estimation::Chi2AboveBand(d.next->board.fit)) << d.next->board.fit.chi2_dof();
}

TEST(BoardDiagnosis, ARigidBoardPassesAndAMountThatTurnsInATurnFailsTheRigidTest) {
  // IMU 1 ideal, so that turning its output turns what it senses (its bias and scale would
  // not turn with it on a real board).
  const sim::SimulationOptions opt = BoardOptions(2, 5, 0.0);
  BoardSession s = Simulate(opt, 5);
  const BoardDiagnosis rigid = DiagnoseIt(s);
  ASSERT_TRUE(rigid.rigid.untested.empty()) << rigid.rigid.untested;
  EXPECT_GT(rigid.rigid.constraints(), 20);
  EXPECT_TRUE(rigid.rigid.holds()) << rigid.rigid.difference() << " on " << rigid.rigid.constraints();
  EXPECT_FALSE(rigid.rigid_board.has_value());

  // IMU 1 turns 0.5 deg about its x axis on the board during the turn after the eighth hold,
  // its gyroscope measuring that turn: alone it is a consistent IMU, on the board it is not.
  const double t0 = s.sim.session.series.t_s[s.segments[7].end - 1] + 0.5;
  const double t1 = t0 + 1.0;
  const double angle = 0.5 * units::kRadPerDeg;
  ImuSeries& imu1 = s.sim.session.other_imus[0].series;
  for (std::size_t i = 0; i < imu1.size(); ++i) {
    const double t = imu1.t_s[i];
    const double turned = angle * std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
    const Mat3 R_old_new = Eigen::AngleAxisd(turned, Vec3::UnitX()).toRotationMatrix();
    imu1.acc[i] = (R_old_new.transpose() * imu1.acc[i].cast<double>()).cast<float>();
    Vec3 w = R_old_new.transpose() * imu1.gyr[i].cast<double>();
    if (t > t0 && t < t1) w.x() += angle / (t1 - t0);
    imu1.gyr[i] = w.cast<float>();
  }
  const BoardDiagnosis sagged = DiagnoseIt(s);
  EXPECT_FALSE(sagged.imus[0].own_misfit);
  EXPECT_FALSE(sagged.imus[1].own_misfit) << sagged.imus[1].diagnosis.fit.fit.chi2_dof();
  ASSERT_TRUE(sagged.rigid.untested.empty()) << sagged.rigid.untested;
  EXPECT_FALSE(sagged.rigid.holds());
  EXPECT_GT(sagged.rigid.difference(), 10.0 * sagged.rigid.limit);
}

// D is chi^2 on its constraints when the board is rigid: over 12 seeded boards of random IMUs,
// the mean of D / constraints is 1 within what 12 draws allow (its sd sqrt(2 / (12 c))).
TEST(BoardDiagnosis, TheRigidTestsDifferenceIsChiSquareOnARigidBoard) {
  double sum = 0.0;
  int constraints = 0;
  constexpr int kBoards = 12;
  for (std::uint64_t seed = 1; seed <= kBoards; ++seed) {
    BoardSession s = Simulate(BoardOptions(2, 100 + seed), 100 + seed);
    s.options.candidates = {"earth_rate"};
    const BoardDiagnosis d = DiagnoseIt(s);
    ASSERT_TRUE(d.rigid.untested.empty()) << d.rigid.untested;
    sum += d.rigid.difference() / d.rigid.constraints();
    constraints = d.rigid.constraints();
  }
  const double mean = sum / kBoards;
  const double sd = std::sqrt(2.0 / (kBoards * constraints));
  RecordProperty("mean_difference_per_constraint", std::to_string(mean));
  EXPECT_NEAR(mean, 1.0, 3.0 * sd) << "over " << constraints << " constraints";
}

TEST(BoardDiagnosis, NothingIsTestedAcrossWhenImuZeroMissesAnEffect) {
  std::vector<ImuDiagnosis> imus(2);
  imus[0].own_misfit = true;
  const RigidBoardTest t = TestRigidBoard(imus, estimation::FitReport{});
  EXPECT_FALSE(t.untested.empty());
  EXPECT_TRUE(t.imus.empty());
  EXPECT_FALSE(t.holds());
}

}  // namespace
}  // namespace plumb::diagnostics

// The board's other IMUs in one fit with IMU 0 (SPEC 6, "Several IMUs of one board";
// estimation/board.h, problem_imu.h): on simulated three-IMU boards with known truth, every
// IMU's parameters and each mount's rotation R_b_i lie within a few sigma of the truth, with
// the attitudes shared.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <utility>
#include <map>
#include <set>
#include <string>

#include "plumb/core/so3.h"
#include "plumb/estimation/board_agreement.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/fitted_problem.h"
#include "plumb/geo/site.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/segmentation/still_detector.h"
#include "plumb/model/board_mount.h"
#include "plumb/report/calibration_text.h"
#include "plumb/report/json_report.h"
#include "plumb/estimation/solve.h"
#include "plumb/estimation/uncertainty.h"
#include "plumb/signal/chi_square.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb::estimation {
namespace {

/// A fitted board: the simulation and the analysis at the fit's solution (every unknown free).
struct BoardOutcome {
  sim::Simulation sim;
  CalibrationResult result;
  FittedProblem fitted;
  AnalysedSolution at;
};

/// A 16-pose session of a board of `imus` IMUs at 100 Hz, each IMU with random true
/// parameters, rotations of 0.5-2 degrees, lever arms of 1-5 cm and time offsets within 2 ms
/// (sim::RandomBoard), with `realistic` noise (white, bias instability and walk, a temperature
/// ramp) or white noise; `wander` scales the bias walk and instability of both sensors of every
/// IMU.
sim::Simulation SimulateBoard(std::uint64_t seed, int imus, bool realistic, double wander = 1.0) {
  sim::SimulationOptions opt = realistic ? sim::SimulationOptions::TypicalMems()
                                         : sim::SimulationOptions::WhiteMems();
  opt.accel_bias_walk_density *= wander;
  opt.gyro_bias_walk_density *= wander;
  opt.accel_bias_instability *= wander;
  opt.gyro_bias_instability *= wander;
  opt.rate_hz = 100.0;
  opt.model = model::Model::Parse("base");
  opt.truth = sim::RandomParameters(opt.model, 1.0, seed);
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
  opt.seed = seed;
  opt.board = sim::RandomBoard(imus, opt.model, 1.0, seed + 1);
  return sim::Simulate(sim::MultiPose(16, 5.0, 2.0, seed), opt);
}

/// SimulateBoard's session fitted with the true still segments given (attitudes unknown): with
/// `realistic` noise the fit models the wander (its default); with white noise it takes a
/// constant bias.
BoardOutcome FitBoard(std::uint64_t seed, int imus, bool realistic = false) {
  BoardOutcome o;
  o.sim = SimulateBoard(seed, imus, realistic);
  std::vector<StillSegment> segments = o.sim.truth_segments;
  for (auto& s : segments) s.known_R_n_b.reset();
  CalibrationOptions options;
  options.constant_bias = !realistic;
  o.fitted = FitProblem(o.sim.session.series, segments, o.sim.model, o.sim.site, options,
                        o.result, o.sim.session.other_imus);
  o.at = AnalyseSolution(*o.fitted.problem, *o.fitted.solution.all_free.problem, options);
  return o;
}

/// The true value of every model parameter of the fit, by its column's name: IMU 0's, then
/// each other IMU's ("imuK." prefixed) and its mount's rotation vector ("imuK.rotation.x"),
/// lever arm ("imuK.lever_arm.x") and time offset ("imuK.time_offset").
std::map<std::string, double> Truth(const sim::Simulation& s) {
  std::map<std::string, double> truth;
  auto add = [&](const std::string& prefix, const model::Model& m, const model::ParameterBlocks& theta) {
    const std::vector<std::string> names = m.ParameterNames();
    const std::vector<double> values = model::ReportedValues(m, theta);
    for (std::size_t i = 0; i < names.size(); ++i) truth[prefix + names[i]] = values[i];
  };
  add("", s.model, s.truth);
  for (std::size_t i = 0; i < s.board.size(); ++i) {
    const std::string prefix = "imu" + std::to_string(i + 1) + ".";
    add(prefix, s.board[i].model, s.board[i].truth);
    const Vec3 rho = so3::Log(s.board[i].R_b_i.toRotationMatrix());
    for (int a = 0; a < 3; ++a) {
      truth[prefix + "rotation." + kAxisName[a]] = rho[a];
      truth[prefix + "lever_arm." + kAxisName[a]] = s.board[i].lever_arm_m[a];
    }
    truth[prefix + "time_offset"] = s.board[i].time_offset_s;
  }
  return truth;
}

/// The NEES of `o` over every model parameter of every IMU and mount, with the full covariance,
/// and their number.
std::pair<double, int> BoardNees(const BoardOutcome& o) {
  const UnknownColumns& columns = o.at.columns;
  const std::map<std::string, double> truth = Truth(o.sim);
  std::vector<Eigen::Index> model_columns;
  for (std::size_t c = 0; c < columns.names.size(); ++c) {
    if (columns.is_model[c]) model_columns.push_back(static_cast<Eigen::Index>(c));
  }
  const auto n = static_cast<Eigen::Index>(model_columns.size());
  Eigen::VectorXd e(n);
  Eigen::MatrixXd P(n, n);
  for (Eigen::Index a = 0; a < n; ++a) {
    const auto c = static_cast<std::size_t>(model_columns[static_cast<std::size_t>(a)]);
    e[a] = columns.values[c] - truth.at(columns.names[c]);
    for (Eigen::Index b = 0; b < n; ++b) {
      P(a, b) = o.at.analysis.covariance(model_columns[static_cast<std::size_t>(a)],
                                         model_columns[static_cast<std::size_t>(b)]);
    }
  }
  return {e.dot(P.ldlt().solve(e)), static_cast<int>(n)};
}

/// Checks every IMU's parameters and mounts of `o` against the truth: within 4 sigma each, NEES
/// within its 99.9 % bound.
void ExpectTruthWithin4Sigma(const BoardOutcome& o) {
  ASSERT_TRUE(o.result.fit.converged) << o.result.fit.solver_report;
  const UnknownColumns& columns = o.at.columns;
  const std::map<std::string, double> truth = Truth(o.sim);
  std::vector<Eigen::Index> model_columns;
  int mounts = 0;
  for (std::size_t c = 0; c < columns.names.size(); ++c) {
    if (!columns.is_model[c]) continue;
    model_columns.push_back(static_cast<Eigen::Index>(c));
    mounts += columns.names[c].find(".rotation.") != std::string::npos;
  }
  EXPECT_EQ(mounts, 6);  // two other IMUs, three rotation components each
  EXPECT_EQ(o.at.analysis.summary.rank, o.at.analysis.summary.num_unknowns)
      << "16 poses with turns determine every IMU and mount";
  // Each parameter within 4 sigma, and the NEES over all of them within its 99.9 % bound.
  const auto n = static_cast<Eigen::Index>(model_columns.size());
  Eigen::VectorXd e(n);
  Eigen::MatrixXd P(n, n);
  double worst = 0.0;
  std::string worst_name;
  for (Eigen::Index a = 0; a < n; ++a) {
    const auto c = static_cast<std::size_t>(model_columns[static_cast<std::size_t>(a)]);
    ASSERT_TRUE(truth.count(columns.names[c])) << columns.names[c];
    e[a] = columns.values[c] - truth.at(columns.names[c]);
    for (Eigen::Index b = 0; b < n; ++b) {
      P(a, b) = o.at.analysis.covariance(model_columns[static_cast<std::size_t>(a)],
                                         model_columns[static_cast<std::size_t>(b)]);
    }
    const double z = std::abs(e[a]) / std::sqrt(P(a, a));
    if (z > worst) {
      worst = z;
      worst_name = columns.names[c];
    }
  }
  EXPECT_LT(worst, 4.0) << worst_name;
  const double nees = e.dot(P.ldlt().solve(e));
  // chi^2 with n dof: its 99.9 % point is below n + 3.1 sqrt(2 n) + 10 for n of tens.
  EXPECT_LT(nees, static_cast<double>(n) + 3.1 * std::sqrt(2.0 * static_cast<double>(n)) + 10.0)
      << "NEES " << nees << " over " << n;
}

TEST(BoardFit, ThreeImusRecoverTheirParametersAndMountsWithin4Sigma) {
  ExpectTruthWithin4Sigma(FitBoard(31, 3));
}

TEST(BoardFit, ThreeImusWithRealisticNoise) {
  ExpectTruthWithin4Sigma(FitBoard(32, 3, true));
}

// As CalibrateSimulated's NEES tests: the average NEES per degree of freedom with the full
// covariance over every IMU's parameters and the mounts' rotations, over seeded three-IMU
// sessions with realistic noise (the wander modelled at its typical levels), lies in the 95 %
// band of chi^2.
TEST(BoardFit, CovarianceIsHonestWithThreeImus) {
  constexpr int kRuns = 40;
  double nees = 0.0;
  int dof = 0;
  for (int run = 0; run < kRuns; ++run) {
    const BoardOutcome o = FitBoard(9100 + static_cast<std::uint64_t>(run), 3, true);
    ASSERT_TRUE(o.result.fit.converged) << run;
    const auto [value, n] = BoardNees(o);
    nees += value;
    dof += n;
  }
  const double lo = signal::ChiSquareQuantileExact(0.025, dof) / dof;
  const double hi = signal::ChiSquareQuantileExact(0.975, dof) / dof;
  EXPECT_GT(nees / dof, lo);
  EXPECT_LT(nees / dof, hi);
  std::cout << "three IMUs, realistic noise: NEES/dof " << nees / dof << " (95% band " << lo
            << " .. " << hi << ")\n";
}

// Sessions from five times quieter to five times noisier than the typical MEMS sensor (walk
// and instability of both sensors of every IMU scaled), calibrated as a user would
// (CalibrateBoard) with the typical levels assumed (the default): as for one IMU
// (calibrate_sim_test.cc), the formal sigmas are then conservative when the sensors are quiet,
// and too small when they wander more, where every fit's chi2/dof above its band says so (it
// is never called consistent).
TEST(BoardFit, WanderFromQuietToNoisyIsConservativeOrFlagged) {
  constexpr int kRuns = 12;
  for (double wander : {0.2, 5.0}) {
    double nees = 0.0;
    int dof = 0, flagged = 0;
    for (int run = 0; run < kRuns; ++run) {
      const std::uint64_t seed = 9400 + static_cast<std::uint64_t>(run);
      const sim::Simulation s = SimulateBoard(seed, 3, true, wander);
      std::vector<StillSegment> segments = s.truth_segments;
      for (auto& seg : segments) seg.known_R_n_b.reset();
      const CalibrationResult r = CalibrateBoard(s.session.series, s.session.other_imus, segments,
                                                 s.model, s.site, CalibrationOptions());
      ASSERT_TRUE(r.fit.converged) << run;
      flagged += Chi2AboveBand(r.fit);
      // The NEES over every determined parameter of every IMU, with the one covariance.
      const std::map<std::string, double> truth = Truth(s);
      std::vector<const ParameterEstimate*> all;
      for (const auto& p : r.calibration.parameters) all.push_back(&p);
      for (const auto& b : r.calibration.board) {
        for (const auto& p : b.parameters) all.push_back(&p);
      }
      std::vector<Eigen::Index> used;
      for (std::size_t i = 0; i < all.size(); ++i) {
        if (!all[i]->fixed && all[i]->observable) used.push_back(static_cast<Eigen::Index>(i));
      }
      const auto n = static_cast<Eigen::Index>(used.size());
      Eigen::VectorXd e(n);
      Eigen::MatrixXd P(n, n);
      for (Eigen::Index a = 0; a < n; ++a) {
        const auto i = static_cast<std::size_t>(used[static_cast<std::size_t>(a)]);
        const ParameterEstimate& p = *all[i];
        e[a] = p.value - truth.at(p.name);
        for (Eigen::Index b = 0; b < n; ++b) {
          P(a, b) = r.calibration.board_covariance(used[static_cast<std::size_t>(a)],
                                                   used[static_cast<std::size_t>(b)]);
        }
      }
      nees += e.dot(P.ldlt().solve(e));
      dof += static_cast<int>(n);
    }
    const double lo = signal::ChiSquareQuantileExact(0.025, dof) / dof;
    const double hi = signal::ChiSquareQuantileExact(0.975, dof) / dof;
    if (wander < 1.0) {
      EXPECT_LT(nees / dof, hi) << "quiet sensors";
    } else {
      EXPECT_GT(nees / dof, hi) << "noisy sensors";
      EXPECT_EQ(flagged, kRuns) << "every fit of noisy sensors is flagged";
    }
    std::cout << wander << " x the typical wander, typical levels assumed: NEES/dof " << nees / dof
              << " (95% band " << lo << " .. " << hi << "), chi2/dof above its band in "
              << flagged << " of " << kRuns << "\n";
  }
}

// CalibrateBoard reports every IMU: each board IMU's parameters (its model's and its mount's)
// with sigmas, the one covariance over every IMU's, and the JSON's "imus" (SPEC 6: IMU 0 first
// at the identity) and "imus_covariance"; the text report shows each IMU's rotation.
TEST(BoardFit, CalibrateBoardReportsEveryImu) {
  sim::SimulationOptions opt = sim::SimulationOptions::WhiteMems();
  opt.rate_hz = 100.0;
  opt.truth = sim::RandomParameters(opt.model, 1.0, 41);
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
  opt.seed = 41;
  opt.board = sim::RandomBoard(3, opt.model, 1.0, 42);
  const sim::Simulation s = sim::Simulate(sim::MultiPose(12, 5.0, 2.0, 41), opt);
  std::vector<StillSegment> segments = s.truth_segments;
  for (auto& seg : segments) seg.known_R_n_b.reset();
  CalibrationOptions options;
  options.constant_bias = true;
  const CalibrationResult r =
      CalibrateBoard(s.session.series, s.session.other_imus, segments, s.model, s.site, options);
  const Calibration& c = r.calibration;
  ASSERT_EQ(c.board.size(), 2u);
  std::size_t n = c.parameters.size();
  for (std::size_t i = 0; i < c.board.size(); ++i) {
    const BoardImuCalibration& b = c.board[i];
    EXPECT_EQ(b.instance, static_cast<int>(i) + 1);
    ASSERT_EQ(b.parameters.size(), c.parameters.size() + model::board_mount::kSize);
    n += b.parameters.size();
    const std::size_t m = c.parameters.size();  // the mount's first
    EXPECT_EQ(b.parameters[m].name, "imu" + std::to_string(i + 1) + ".rotation.x");
    EXPECT_EQ(b.parameters[m].unit, "rad");
    // The recovered rotation, lever arm and time offset within 4 sigma of the truth.
    const Vec3 rho = so3::Log(s.board[i].R_b_i.toRotationMatrix());
    std::vector<double> truth(rho.data(), rho.data() + 3);
    truth.insert(truth.end(), s.board[i].lever_arm_m.data(), s.board[i].lever_arm_m.data() + 3);
    truth.push_back(s.board[i].time_offset_s);
    for (int a = 0; a < model::board_mount::kSize; ++a) {
      const ParameterEstimate& p = b.parameters[m + static_cast<std::size_t>(a)];
      EXPECT_FALSE(p.fixed) << p.name;
      ASSERT_TRUE(std::isfinite(p.sigma)) << p.name;
      EXPECT_LT(std::abs(p.value - truth[static_cast<std::size_t>(a)]), 4.0 * p.sigma) << p.name;
    }
    EXPECT_LT(b.R_b_i().angularDistance(s.board[i].R_b_i), 1e-3);
  }
  ASSERT_EQ(static_cast<std::size_t>(c.board_covariance.rows()), n);
  EXPECT_EQ(c.board_covariance.topLeftCorner(c.covariance.rows(), c.covariance.cols()),
            c.covariance);
  const nlohmann::json doc = report::ToJson(r);
  ASSERT_EQ(doc["imus"].size(), 3u);
  EXPECT_EQ(doc["imus"][0]["instance"], 0);
  EXPECT_EQ(doc["imus"][0]["rotation"]["vector"], nlohmann::json::array({0.0, 0.0, 0.0}));
  EXPECT_EQ(doc["imus"][2]["instance"], 2);
  EXPECT_TRUE(doc["imus"][1]["rotation"]["sigma"][2].is_number());
  EXPECT_TRUE(doc["imus"][1]["lever_arm"]["sigma"][0].is_number());
  EXPECT_TRUE(doc["imus"][1]["time_offset"]["sigma"].is_number());
  EXPECT_EQ(doc["imus_covariance"]["parameters"].size(), n);
  EXPECT_EQ(doc["imus_covariance"]["matrix"].size(), n);
  const std::string text = report::FullReport(r);
  EXPECT_NE(text.find("imu2, fitted with IMU 0"), std::string::npos) << text;
  EXPECT_NE(text.find("imu2.rotation.z"), std::string::npos) << text;

  // At rest, once each IMU is corrected, what separates it from IMU 0 is its turn: g 2 sin(a/2)
  // at most (ArduPilot's z halved can only shrink it), reached within a third over 12 poses;
  // taken out, the noise of two poses' means is left (5 sigma of their difference's norm).
  const std::vector<ImuAgreement> agreement =
      BoardAgreement(r, s.session.series, s.session.other_imus);
  const double per_mean = std::sqrt(2.0 / static_cast<double>(r.fit.still.front().count));
  ASSERT_EQ(agreement.size(), 2u);
  for (std::size_t i = 0; i < agreement.size(); ++i) {
    const ImuAgreement& a = agreement[i];
    EXPECT_EQ(a.instance, static_cast<int>(i) + 1);
    EXPECT_EQ(a.poses, 12);
    const double turn = s.site.gravity() * 2.0 * std::sin(0.5 * Eigen::AngleAxisd(s.board[i].R_b_i).angle());
    EXPECT_LT(a.accel_after, turn + 0.005) << i;
    EXPECT_GT(a.accel_after, turn / 3.0) << i;
    EXPECT_LT(a.accel_in_body, 5.0 * per_mean * c.noise.acc.maxCoeff()) << i;
    EXPECT_LT(a.gyro_in_body, 5.0 * per_mean * c.noise.gyr.maxCoeff()) << i;
    EXPECT_DOUBLE_EQ(a.accel_limit, i == 0 ? kArduPilotAccelThreshold_m_s2
                                           : 3.0 * kArduPilotAccelThreshold_m_s2);
  }
}

// A real board (SPEC 6's check): plane408's IMU and IMU2 still on the bench, one pose. Gravity
// alone cannot show a turn about itself, so the analysis names IMU2's rotation about the
// vertical among what the data cannot determine.
TEST(BoardFit, ARealBoardStillInOnePoseCannotShowItsYaw) {
  const std::string path = std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/plane408_centre_point.BIN";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  const io::FlightLog log = io::FlightLog::Open(path);
  io::FlightLogSelection pick;
  pick.other_imus = {1};
  const Session s = log.Select(pick);
  ASSERT_EQ(s.other_imus.size(), 1u);
  const auto segments = segmentation::DetectStillSegments(s.series, {}).segments;
  model::Model m = model::Model::Parse("base");
  m.t_ref_s = s.series.t_s.front();
  const geo::Site site = geo::ResolveSite(std::nullopt, s.site, std::nullopt);
  const CalibrationResult r = CalibrateBoard(s.series, s.other_imus, segments, m, site);
  if (std::getenv("PLUMB_PRINT")) std::cout << report::FullReport(r);
  ASSERT_EQ(r.calibration.board.size(), 1u);
  // The mount the data cannot determine is held where it starts, at the square mount, by its
  // own rotation as the gauge: the fit neither turns it along a null direction of its
  // gyroscope's matrix nor fails a gate.
  for (const Gate& g : r.fit.gates) ADD_FAILURE() << g.name << ": " << g.message;
  EXPECT_LT(Eigen::AngleAxisd(r.calibration.board[0].R_b_i()).angle(), 1e-9);
  // One pose: IMU2's tilt (rotation.x, .y) is determined only with the accelerometers' bias
  // difference, to a hundredth of a degree; its turn about gravity (rotation.z) not at all.
  std::set<std::string> leading;
  for (const Combination& d : r.calibration.observability.determined) {
    std::size_t lead = 0;
    for (std::size_t i = 1; i < d.names.size(); ++i) {
      if (std::abs(d.coefficients[i]) > std::abs(d.coefficients[lead])) lead = i;
    }
    if (d.names[lead].rfind("imu1.rotation.", 0) != 0) continue;
    leading.insert(d.names[lead]);
    EXPECT_LT(d.sigma / std::abs(d.coefficients[lead]), 1e-3) << d.text;
  }
  EXPECT_EQ(leading, (std::set<std::string>{"imu1.rotation.x", "imu1.rotation.y"}))
      << report::FullReport(r);
  bool yaw_named = false;
  for (const std::string& u : r.calibration.observability.unobservable) {
    yaw_named = yaw_named || u.find("imu1.rotation.z") != std::string::npos;
  }
  EXPECT_TRUE(yaw_named) << report::FullReport(r);
}

}  // namespace
}  // namespace plumb::estimation

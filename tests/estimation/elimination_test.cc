// The analysis with the attitudes and bias-wander states eliminated (solve.cc, a Schur
// complement on the model parameters) against the dense analysis over every unknown: the same
// rank, covariance of the model parameters, null directions (with their attitude components)
// and determined combinations, on well-posed and rank-deficient sessions, with and without
// the wandering bias.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/elimination.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/solve.h"
#include "plumb/estimation/still_set.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "support/sim_options.h"

namespace plumb::estimation {
namespace {

struct Analyses {
  ObservabilityAnalysis eliminated, dense;
  UnknownColumns columns;
};

/// A simulated session of `poses` poses (attitudes unknown), solved, analysed both ways.
Analyses AnalyseBothWays(int poses, bool wander, std::uint64_t seed) {
  const sim::SimulationOptions opt =
      testing::TypicalMemsAt(geo::Site::At(51.64, -1.2, 100.0, "flags"), seed);
  const sim::Simulation s = sim::Simulate(sim::MultiPose(poses, 5.0, 2.0, seed), opt);
  std::vector<StillSegment> segments = s.truth_segments;
  for (auto& seg : segments) seg.known_R_n_b.reset();
  CalibrationOptions options;
  options.constant_bias = !wander;
  StillSet still = MakeStillSet(s.session.series, segments, true, true, options);
  NoiseModel noise = EstimateNoise(s.session.series, still, true, options);
  if (wander) {
    noise.walk_acc.setConstant(1e-4);
    noise.walk_gyr.setConstant(2e-6);
    noise.instability_acc.setConstant(4e-4);
    noise.instability_gyr.setConstant(2e-5);
  }
  model::ParameterBlocks theta = s.model.ZeroParameters();
  const StartingValues start = Initialize(s.session.series, s.model, s.site.gravity(), true,
                                          options.first_heading_deg, still, theta);
  AssignHeadingGauge(still, true);
  CalibrationProblem problem(s.session.series, s.model, s.site, std::move(still), std::move(theta),
                             noise, start, options);
  FitReport fit;
  Solution solution = SolveWithGauge(problem, options, fit);
  Analyses out;
  AnalysedSolution eliminated = AnalyseAt(problem, *solution.all_free.problem, options);
  AnalysisOptions dense;
  dense.dense = true;
  AnalysedSolution analysed = AnalyseAt(problem, *solution.all_free.problem, options, dense);
  out.eliminated = std::move(eliminated.analysis);
  out.dense = std::move(analysed.analysis);
  out.columns = std::move(analysed.columns);
  return out;
}

void ExpectSameAnalysis(const Analyses& a) {
  const Eigen::Index n_m = LeadingModelColumns(a.columns.is_model);
  const auto n_w = static_cast<int>(a.columns.names.size() - a.columns.first_wander);
  EXPECT_EQ(a.eliminated.summary.wander_states, n_w);
  EXPECT_EQ(a.eliminated.summary.rank + n_w, a.dense.summary.rank);
  EXPECT_EQ(a.eliminated.summary.num_unknowns + n_w, a.dense.summary.num_unknowns);
  // The model parameters' covariance (the eliminated analysis's covers them only), between
  // observable ones: what a pseudo-inverse gives along null directions depends on the
  // unknowns it minimises the norm over, the covariance of estimable combinations does not.
  ASSERT_EQ(a.eliminated.covariance.rows(), n_m);
  const Eigen::MatrixXd& e = a.eliminated.covariance;
  const Eigen::MatrixXd d = a.dense.covariance.topLeftCorner(n_m, n_m);
  const auto observable = [&](Eigen::Index i) { return a.dense.observable[static_cast<std::size_t>(i)]; };
  for (Eigen::Index i = 0; i < n_m; ++i) {
    EXPECT_EQ(a.eliminated.observable[static_cast<std::size_t>(i)], observable(i))
        << a.columns.names[static_cast<std::size_t>(i)];
    for (Eigen::Index j = 0; j < n_m; ++j) {
      if (!observable(i) || !observable(j)) continue;
      EXPECT_NEAR(e(i, j), d(i, j), 1e-6 * std::sqrt(d(i, i) * d(j, j)))
          << a.columns.names[static_cast<std::size_t>(i)] << ", "
          << a.columns.names[static_cast<std::size_t>(j)];
    }
  }
  // Null directions, attitude components included, and the pivots held for them.
  EXPECT_EQ(a.eliminated.summary.unobservable, a.dense.summary.unobservable);
  EXPECT_EQ(a.eliminated.pivots, a.dense.pivots);
  ASSERT_EQ(a.eliminated.summary.determined.size(), a.dense.summary.determined.size());
  for (std::size_t k = 0; k < a.dense.summary.determined.size(); ++k) {
    const Combination& x = a.eliminated.summary.determined[k];
    const Combination& y = a.dense.summary.determined[k];
    EXPECT_EQ(x.text, y.text);
    EXPECT_NEAR(x.value, y.value, 1e-9 * std::max(1.0, std::abs(y.value)));
    EXPECT_NEAR(x.sigma, y.sigma, 1e-6 * y.sigma);
  }
}

TEST(Elimination, WanderingBiasTenPosesGivesTheDenseAnalysis) {
  const Analyses a = AnalyseBothWays(10, true, 31);
  ASSERT_GT(a.columns.names.size(), a.columns.first_wander);  // there are wander states
  EXPECT_TRUE(a.dense.summary.unobservable.empty());
  ExpectSameAnalysis(a);
}

TEST(Elimination, ConstantBiasTenPosesGivesTheDenseAnalysis) {
  const Analyses a = AnalyseBothWays(10, false, 32);
  EXPECT_EQ(a.columns.names.size(), a.columns.first_wander);  // no wander states
  ExpectSameAnalysis(a);
}

TEST(Elimination, ThreePosesNullDirectionsShowTheirAttitudes) {
  // Three faces cannot determine the base model: null directions over model parameters and
  // the poses' attitudes, found from the reduced system and the attitudes' response.
  for (const bool wander : {false, true}) {
    SCOPED_TRACE(wander ? "wandering bias" : "constant bias");
    const Analyses a = AnalyseBothWays(3, wander, 33);
    ASSERT_FALSE(a.dense.summary.unobservable.empty());
    bool attitude_shown = false;
    for (const std::string& u : a.eliminated.summary.unobservable) {
      attitude_shown = attitude_shown || u.find("attitude[") != std::string::npos;
    }
    EXPECT_TRUE(attitude_shown);
    ExpectSameAnalysis(a);
  }
}

}  // namespace
}  // namespace plumb::estimation

// The residual analysis on simulated sessions with known truth: its predictions reproduce the
// backend's, a hidden effect shows up in its signature (and nothing shows up when nothing is
// hidden), and the residual's Allan deviation leaves the white-noise line only when a slow
// effect is left.
#include "plumb/diagnostics/residual_analysis.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb::diagnostics {
namespace {

struct Scenario {
  sim::Simulation sim;
  estimation::CalibrationResult fit;
};

/// What to simulate: the true model is base plus `effect` (if any) with only the `hidden`
/// parameters of that effect nonzero; the fit is always base, attitudes unknown.
struct Truth {
  std::string effect;                                   // "" = base only
  std::vector<std::pair<std::string, double>> hidden;   // (parameter, reported value)
  std::uint64_t seed = 1;
  sim::TemperatureProfile temperature;
  double rate_hz = 100.0;
};

Scenario SimulateAndFit(const Truth& setup, const sim::Schedule& schedule) {
  sim::SimulationOptions opt = sim::SimulationOptions::WhiteMems();
  opt.rate_hz = setup.rate_hz;
  opt.model = model::Model::Parse(setup.effect.empty() ? "base" : "base+" + setup.effect);
  opt.truth = sim::RandomParameters(opt.model, 1.0, setup.seed);
  for (int t = 0; t < opt.model.num_terms(); ++t) {
    auto& block = opt.truth[static_cast<std::size_t>(t)];
    if (!opt.model.terms()[static_cast<std::size_t>(t)].effect->info().linear_stage) {
      std::fill(block.begin(), block.end(), 0.0);
    }
  }
  for (const auto& [name, value] : setup.hidden) {
    sim::SetParameter(opt.model, opt.truth, name, value);
  }
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
  opt.temperature = setup.temperature;
  opt.seed = setup.seed;
  Scenario s;
  s.sim = sim::Simulate(schedule, opt);
  std::vector<StillSegment> segments = s.sim.truth_segments;
  for (auto& seg : segments) seg.known_R_n_b.reset();
  model::Model base = model::Model::Parse("base");
  base.t_ref_s = s.sim.model.t_ref_s;
  base.temp_ref_c = s.sim.model.temp_ref_c;
  estimation::CalibrationOptions white;  // white noise: one constant bias matches
  white.constant_bias = true;
  s.fit = estimation::Calibrate(s.sim.session.series, segments, base, s.sim.site, white);
  return s;
}

const Signature* Find(const ResidualAnalysis& a, ResidualKind kind, int axis,
                      const std::string& regressor) {
  for (const auto& s : a.signatures) {
    if (s.residual == kind && s.axis == axis && s.regressor == regressor) return &s;
  }
  return nullptr;
}

std::string Flagged(const ResidualAnalysis& a) {
  std::string out;
  for (const auto& s : a.signatures) {
    if (s.significant) {
      out += std::string(ResidualKindName(s.residual)) + "." + kAxisName[s.axis] + " vs " +
             s.regressor + " r=" + std::to_string(s.correlation) +
             " p=" + std::to_string(s.p_value) + "\n";
    }
  }
  return out;
}

TEST(ResidualAnalysis, PredictionsReproduceTheBackend) {
  Truth setup;
  setup.seed = 7;
  const Scenario s = SimulateAndFit(setup, sim::MultiPose(16, 5.0, 2.0, 7));
  const ImuSeries& series = s.sim.session.series;
  const ResidualAnalysis a = AnalyseResiduals(series, s.fit);
  ASSERT_EQ(a.still.size(), s.fit.fit.still.size());
  ASSERT_EQ(a.motion.size(), s.fit.fit.motion.size());
  std::size_t samples = 0, strided = 0;
  for (const auto& c : a.still) {
    ASSERT_TRUE(c.has_acc && c.has_gyr);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(c.acc_predicted[i] + c.acc_residual[i], c.acc_measured[i], 1e-9) << c.label;
      EXPECT_NEAR(c.gyr_predicted[i] + c.gyr_residual[i], c.gyr_measured[i], 1e-12) << c.label;
    }
    const StillSegment& seg = s.fit.fit.still[c.index].segment;
    samples += seg.count();
    strided += (seg.count() + 9) / 10;
    // The per-sample residuals average to the segment's residual (base model: the prediction
    // is constant over a still segment).
    Vec3 acc = Vec3::Zero(), gyr = Vec3::Zero();
    for (std::size_t i = 0; i < a.samples.size(); ++i) {
      if (a.samples.segment[i] != c.index) continue;
      acc += a.samples.acc_residual[i] / static_cast<double>(seg.count());
      gyr += a.samples.gyr_residual[i] / static_cast<double>(seg.count());
    }
    EXPECT_LT((acc - c.acc_residual).norm(), 1e-9) << c.label;
    EXPECT_LT((gyr - c.gyr_residual).norm(), 1e-12) << c.label;
  }
  EXPECT_EQ(a.samples.size(), samples);
  ResidualAnalysisOptions every10;
  every10.sample_stride = 10;
  EXPECT_EQ(AnalyseResiduals(series, s.fit, every10).samples.size(), strided);
  // Ranked worst first; worst ranges sorted and named.
  for (std::size_t i = 1; i < a.still_rank.size(); ++i) {
    EXPECT_GE(a.still[a.still_rank[i - 1]].whitened_norm, a.still[a.still_rank[i]].whitened_norm);
  }
  ASSERT_EQ(a.worst.size(), 5u);
  EXPECT_GE(a.worst[0].score, a.worst[4].score);
  EXPECT_FALSE(a.worst[0].name.empty());
}

TEST(ResidualAnalysis, HiddenGSensitivityShowsAgainstSpecificForce) {
  Truth setup;
  setup.effect = "gyro_g_sensitivity";
  setup.hidden = {{"gyro_g_sensitivity.G.xz", 5e-4}};
  setup.seed = 8;
  const Scenario s = SimulateAndFit(setup, sim::MultiPose(24, 5.0, 2.0, 8));
  const ResidualAnalysis a = AnalyseResiduals(s.sim.session.series, s.fit);
  const Signature* sig = Find(a, ResidualKind::kStillGyro, 0, "f_b.z");
  ASSERT_NE(sig, nullptr);
  EXPECT_TRUE(sig->significant) << Flagged(a);
  EXPECT_NEAR(sig->slope_residual, 5e-4, 1.5e-4);
  // The worst still segment is a gyroscope one.
  const SegmentComparison& worst = a.still[a.still_rank.front()];
  EXPECT_GT(worst.gyr_whitened.norm(), worst.acc_whitened.norm());
  EXPECT_NE(a.worst.front().residual, ResidualKind::kStillAccel);
}

TEST(ResidualAnalysis, HiddenTemperatureBiasShowsAgainstTemperature) {
  Truth setup;
  setup.effect = "accel_temperature_bias";
  setup.hidden = {{"accel_temperature_bias.c1.x", 2e-3}};
  setup.seed = 9;
  const sim::Schedule schedule = sim::MultiPose(24, 5.0, 2.0, 9);
  setup.temperature = sim::TemperatureProfile::UpDown(15.0, 45.0, schedule.duration_s());
  const Scenario s = SimulateAndFit(setup, schedule);
  const ResidualAnalysis a = AnalyseResiduals(s.sim.session.series, s.fit);
  const Signature* sig = Find(a, ResidualKind::kStillAccel, 0, "temperature");
  ASSERT_NE(sig, nullptr);
  EXPECT_TRUE(sig->significant) << Flagged(a);
  // The free attitudes absorb the part of c1 dT across gravity: about c1 times the mean of
  // f_x^2 / g^2 is left (a third for evenly spread poses; 0.39-0.47 over five seeds).
  EXPECT_GT(sig->slope_residual, 0.2 * 2e-3);
  EXPECT_LT(sig->slope_residual, 0.6 * 2e-3);
  for (const auto& other : a.signatures) {
    if (other.residual == ResidualKind::kStillAccel && other.axis == 0) {
      EXPECT_LE(sig->p_value, other.p_value) << other.regressor;
    }
  }
}

TEST(ResidualAnalysis, NothingHiddenNothingFlagged) {
  for (std::uint64_t seed : {31u, 32u, 33u}) {
    Truth setup;
    setup.seed = seed;
    setup.temperature = sim::TemperatureProfile::Ramp(20.0, 30.0);
    const Scenario s = SimulateAndFit(setup, sim::MultiPose(24, 5.0, 2.0, seed));
    const ResidualAnalysis a = AnalyseResiduals(s.sim.session.series, s.fit);
    // time, temperature, f_b (3), f_b^2 (3) for 6 still axes; 3 rate regressors x 3 motion axes.
    EXPECT_EQ(a.num_tests, 8 * 6 + 3 * 3) << "seed " << seed;
    EXPECT_EQ(Flagged(a), "") << "seed " << seed;
  }
}

/// Poses, then one long still: the Allan deviation runs over the long one.
sim::Schedule LongStill(std::uint64_t seed, double long_s) {
  sim::Schedule schedule = sim::MultiPose(12, 5.0, 2.0, seed);
  schedule.Turn(Vec3::UnitZ(), 1.0, 2.0).Hold(long_s, "long");
  return schedule;
}

TEST(ResidualAnalysis, AllanRatioNearOneOnWhiteNoise) {
  Truth setup;
  setup.seed = 41;
  setup.rate_hz = 50.0;
  const Scenario s = SimulateAndFit(setup, LongStill(41, 900.0));
  const ResidualAnalysis a = AnalyseResiduals(s.sim.session.series, s.fit);
  ASSERT_EQ(a.allan_segments.size(), 1u);
  EXPECT_EQ(s.fit.fit.still[a.allan_segments[0]].segment.label, "long");
  ASSERT_EQ(a.allan.size(), 6u);
  // At m_max = n / 8 the estimate has about 10 degrees of freedom: single ratios spread over
  // 0.6-1.6 (six seeds), their mean over 0.97-1.11.
  double mean = 0;
  for (const auto& x : a.allan) {
    EXPECT_GT(x.ratio, 0.5) << ResidualKindName(x.residual) << kAxisName[x.axis];
    EXPECT_LT(x.ratio, 1.8) << ResidualKindName(x.residual) << kAxisName[x.axis];
    EXPECT_NEAR(x.adev.front(), x.white.front(), 0.05 * x.white.front());  // m = 1
    mean += x.ratio / 6.0;
  }
  EXPECT_NEAR(mean, 1.0, 0.25);
}

TEST(ResidualAnalysis, AllanRatioHighWithHiddenGyroDrift) {
  Truth setup;
  setup.effect = "gyro_bias_drift";
  setup.hidden = {{"gyro_bias_drift.d.x", 1e-6}, {"gyro_bias_drift.d.y", -1e-6},
                  {"gyro_bias_drift.d.z", 1e-6}};
  setup.seed = 42;
  setup.rate_hz = 50.0;
  const Scenario s = SimulateAndFit(setup, LongStill(42, 900.0));
  const ResidualAnalysis a = AnalyseResiduals(s.sim.session.series, s.fit);
  ASSERT_EQ(a.allan.size(), 6u);
  for (const auto& x : a.allan) {
    if (x.residual == ResidualKind::kStillGyro) {
      EXPECT_GT(x.ratio, 3.0) << kAxisName[x.axis];  // about 12 (four seeds)
    } else {
      EXPECT_LT(x.ratio, 1.8) << kAxisName[x.axis];
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    const Signature* time = Find(a, ResidualKind::kStillGyro, axis, "time");
    ASSERT_NE(time, nullptr);
    EXPECT_TRUE(time->significant) << kAxisName[axis];
  }
  // The worst stretches are gyroscope stretches of the long still.
  EXPECT_EQ(a.worst.front().kind, WorstRange::Kind::kStretch) << a.worst.front().name;
  EXPECT_EQ(a.worst.front().residual, ResidualKind::kStillGyro);
}

TEST(ResidualAnalysis, RejectsBadOptionsAndSegments) {
  Truth setup;
  setup.seed = 5;
  const Scenario s = SimulateAndFit(setup, sim::MultiPose(10, 3.0, 2.0, 5));
  ResidualAnalysisOptions bad;
  bad.sample_stride = 0;
  EXPECT_THROW(AnalyseResiduals(s.sim.session.series, s.fit, bad), plumb::Error);
  ImuSeries shorter = s.sim.session.series;
  shorter.t_s.resize(10);
  shorter.acc.resize(10);
  shorter.gyr.resize(10);
  shorter.temp_c.resize(10);
  EXPECT_THROW(AnalyseResiduals(shorter, s.fit), plumb::Error);
}

}  // namespace
}  // namespace plumb::diagnostics

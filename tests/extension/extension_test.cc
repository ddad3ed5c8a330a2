// An effect of one's own, added without touching the library (docs/extending.md, way (a)):
// accel_scale_temperature.h is included in this program and registered with one line at
// the top of main(). Then
//   - the invariant battery of every built-in effect (tests/support/effect_battery.h) runs on
//     it;
//   - its term is checked by hand and the model spec "base+accel_scale_temperature" parses;
//   - a simulated multi-pose session with a temperature cycle and a true scale drift is
//     calibrated with "base" (chi^2/dof well above 1: the drift is left in the residuals) and
//     with "base+accel_scale_temperature" (chi^2/dof near 1, the drift recovered within
//     3 sigma). A one-line summary is always printed; PLUMB_PRINT=1 prints both full reports;
//   - diagnose on the base fit ranks it first among the whole catalogue (built-in effects and
//     this one), significant, and confirms it by refitting.
//
// Run: build/tests/extension/plumb_extension_test --gtest_filter='ScaleTemperatureSession.*'
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "accel_scale_temperature.h"
#include "plumb/autodiff/differentiable_effect.h"
#include "plumb/core/error.h"
#include "plumb/diagnostics/diagnose.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/model/model.h"
#include "plumb/model/registry.h"
#include "plumb/report/catalogue.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"
#include "plumb/report/calibration_text.h"
#include "plumb/report/diagnosis_text.h"
#include "support/effect_battery.h"


namespace plumb {
namespace {

using ::plumb::testing::EffectCase;
using ::plumb::testing::EffectCaseName;
using ::plumb::testing::EffectInvariants;

// The same five invariants as every built-in effect (tests/model/effects_test.cc).
INSTANTIATE_TEST_SUITE_P(Extension, EffectInvariants,
                         ::testing::Values(EffectCase{"accel_scale_temperature", ""}),
                         EffectCaseName);

constexpr const char* kSpec = "base+accel_scale_temperature";

TEST(AccelScaleTemperature, IsInTheRegistryAndInModelSpecs) {
  const auto& registry = model::Registry::Global();
  EXPECT_TRUE(registry.Contains("accel_scale_temperature"));
  const auto names = registry.CatalogueNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "accel_scale_temperature"), names.end());
  const model::Model m = model::Model::Parse(kSpec);
  EXPECT_EQ(m.spec(), kSpec);
  const auto params = m.ParameterNames();
  EXPECT_EQ(params.back(), "accel_scale_temperature.s.z");
  EXPECT_THROW(registry.Make("accel_scale_temperature", "2"), Error);  // takes no option
  EXPECT_THROW(autodiff::RegisterEffect<model::AccelScaleTemperature>("accel_scale_temperature"),
               Error);  // a name is registered once
}

TEST(AccelScaleTemperature, AppearsInTheCatalogueText) {
  // What `plumb effects accel_scale_temperature` prints once the effect is a built-in; a
  // program of its own gets the same text from the registry it registered it in.
  const std::string text =
      report::CatalogueText(model::Registry::Global(), "accel_scale_temperature");
  if (std::getenv("PLUMB_PRINT")) std::cout << text;
  EXPECT_NE(text.find("accel_scale_temperature [accelerometer]"), std::string::npos) << text;
  EXPECT_NE(text.find("y_a,i += s_i (T - T_ref) (F f_b)_i"), std::string::npos) << text;
  EXPECT_NE(text.find("a varying temperature"), std::string::npos) << text;
  EXPECT_NE(text.find("accel_scale_temperature.s.y"), std::string::npos) << text;
  EXPECT_NE(text.find("1/degC"), std::string::npos) << text;
}

/// Predicted accelerometer output of `spec` with accel.matrix.xx = 0.01 and
/// accel_scale_temperature.s.x = 2e-4 /degC, for specific force f_b at dtemp_c.
Vec3 PredictAccel(const Vec3& f_b, double dtemp_c) {
  const model::Model m = model::Model::Parse(kSpec);
  model::ParameterBlocks theta;
  sim::SetParameter(m, theta, "accel.matrix.xx", 1.01);
  sim::SetParameter(m, theta, "accel_scale_temperature.s.x", 2e-4);
  model::SensorInput<double> in;
  in.f_b = f_b;
  in.dtemp_c = dtemp_c;
  return m.Predict(theta, in).acc;
}

TEST(AccelScaleTemperature, ScalesTheSensedInputWithTheTemperatureOffset) {
  const double sensed = 1.01 * 9.8;  // (F f_b)_x
  // 10 degC above T_ref: the x reading grows by s.x dT = 0.2 %, with the sign of the input.
  EXPECT_NEAR(PredictAccel(Vec3(9.8, 0, 0), 10.0).x(), sensed * (1 + 2e-3), 1e-12);
  EXPECT_NEAR(PredictAccel(Vec3(-9.8, 0, 0), 10.0).x(), -sensed * (1 + 2e-3), 1e-12);
  // At T_ref, nothing; other axes untouched.
  EXPECT_EQ(PredictAccel(Vec3(9.8, 0, 0), 0.0).x(), sensed);
  EXPECT_EQ(PredictAccel(Vec3(0, 9.8, 0), 10.0).y(), 9.8);
}

/// True temperature drift of the scale factors in the simulated session, 1/degC.
const Vec3 kTrueScaleDrift(3e-4, -2e-4, 3e-4);

/// The simulated session calibrated with both models.
struct Demonstration {
  sim::Simulation sim;
  estimation::CalibrationResult base;      ///< fitted with "base"
  estimation::CalibrationResult extended;  ///< fitted with "base+accel_scale_temperature"
};

estimation::CalibrationResult Fit(const sim::Simulation& s, const std::string& spec) {
  std::vector<StillSegment> segments = s.truth_segments;
  for (auto& segment : segments) segment.known_R_n_b.reset();  // attitudes are unknowns
  estimation::CalibrationOptions white;  // white noise: one constant bias matches
  white.constant_bias = true;
  return estimation::Calibrate(s.session.series, segments, model::Model::Parse(spec), s.site,
                               white);
}

/// 24 still poses of 5 s joined by 2 s turns at 100 Hz (about 170 s), typical MEMS noise,
/// random base parameters, the sensor warming from 15 to 45 degC and cooling back once
/// (T_ref = 25 degC), and the scale drift kTrueScaleDrift. Simulated and fitted once.
const Demonstration& WarmingSession() {
  static const Demonstration demo = [] {
    constexpr std::uint64_t kSeed = 4242;
    sim::SimulationOptions opt = sim::SimulationOptions::WhiteMems();
    opt.rate_hz = 100.0;
    opt.model = model::Model::Parse(kSpec);
    opt.truth = sim::RandomParameters(opt.model, 1.0, kSeed);
    for (int i = 0; i < 3; ++i) {
      sim::SetParameter(opt.model, opt.truth,
                        std::string("accel_scale_temperature.s.") + "xyz"[i],
                        kTrueScaleDrift[i]);
    }
    opt.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
    opt.seed = kSeed;
    const sim::Schedule schedule = sim::MultiPose(24, 5.0, 2.0, kSeed);
    opt.temperature = sim::TemperatureProfile::UpDown(15.0, 45.0, schedule.duration_s());
    Demonstration d;
    d.sim = sim::Simulate(schedule, opt);
    d.base = Fit(d.sim, "base");
    d.extended = Fit(d.sim, kSpec);
    return d;
  }();
  return demo;
}

/// Estimate of `name` in a result (fails the test when absent).
estimation::ParameterEstimate Find(const estimation::CalibrationResult& r,
                                   const std::string& name) {
  for (const auto& p : r.calibration.parameters) {
    if (p.name == name) return p;
  }
  ADD_FAILURE() << "no parameter " << name;
  return {};
}

/// One line: chi^2/dof of both fits and the recovered drift against the truth.
std::string Summary(const Demonstration& d) {
  char line[512];
  std::string s;
  std::snprintf(line, sizeof line, "chi2/dof base %.2f (dof %d), %s %.2f (dof %d); s =",
                d.base.fit.chi2_dof(), d.base.fit.dof, kSpec, d.extended.fit.chi2_dof(),
                d.extended.fit.dof);
  s += line;
  for (int i = 0; i < 3; ++i) {
    const auto p = Find(d.extended, std::string("accel_scale_temperature.s.") + "xyz"[i]);
    std::snprintf(line, sizeof line, " %.3g +- %.2g (true %.3g)", p.value, p.sigma,
                  kTrueScaleDrift[i]);
    s += line;
  }
  return s + " 1/degC";
}

TEST(ScaleTemperatureSession, PrintsTheDemonstration) {
  const Demonstration& d = WarmingSession();
  std::cout << "[ summary  ] " << Summary(d) << "\n";
  if (std::getenv("PLUMB_PRINT")) {
    std::cout << "--- base ---\n" << report::FullReport(d.base) << "--- " << kSpec << " ---\n"
              << report::FullReport(d.extended);
  }
  EXPECT_TRUE(d.base.fit.converged) << d.base.fit.solver_report;
  EXPECT_TRUE(d.extended.fit.converged) << d.extended.fit.solver_report;
}

TEST(ScaleTemperatureSession, BaseModelLeavesTheDriftInTheResiduals) {
  const Demonstration& d = WarmingSession();
  EXPECT_GT(d.base.fit.chi2_dof(), 3.0) << Summary(d);
}

TEST(ScaleTemperatureSession, ExtendedModelFitsToTheNoise) {
  const Demonstration& d = WarmingSession();
  EXPECT_GT(d.extended.fit.chi2_dof(), 0.5) << Summary(d);
  EXPECT_LT(d.extended.fit.chi2_dof(), 1.6) << Summary(d);
  EXPECT_EQ(d.extended.calibration.observability.rank, d.extended.calibration.observability.num_unknowns)
      << report::FullReport(d.extended);
}

TEST(ScaleTemperatureSession, ExtendedModelRecoversTheDriftWithin3Sigma) {
  const Demonstration& d = WarmingSession();
  for (int i = 0; i < 3; ++i) {
    const auto p = Find(d.extended, std::string("accel_scale_temperature.s.") + "xyz"[i]);
    EXPECT_TRUE(p.observable) << p.name;
    EXPECT_EQ(p.unit, "1/degC");
    EXPECT_LT(std::abs(p.value - kTrueScaleDrift[i]), 3.0 * p.sigma) << p.name << "\n"
                                                                        << Summary(d);
    // Clearly detected: the truth is many sigma away from zero.
    EXPECT_GT(std::abs(kTrueScaleDrift[i]) / p.sigma, 10.0) << p.name;
  }
}

TEST(ScaleTemperatureSession, ExtendedModelRecoversTheBaseParametersWithin3Point5Sigma) {
  const Demonstration& d = WarmingSession();
  const auto truth = model::ReportedValues(d.sim.model, d.sim.truth);
  ASSERT_EQ(truth.size(), d.extended.calibration.parameters.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const auto& p = d.extended.calibration.parameters[i];
    if (p.fixed || !p.observable) continue;
    EXPECT_LT(std::abs(p.value - truth[i]), 3.5 * p.sigma) << p.name;
  }
}

TEST(ScaleTemperatureSession, DiagnoseRanksTheUserEffectFirst) {
  // The registered effect is a catalogue candidate like any built-in one: diagnose on the base
  // fit ranks it first and significant, and its refit confirms the fall of chi^2.
  const Demonstration& d = WarmingSession();
  std::vector<StillSegment> segments = d.sim.truth_segments;
  for (auto& segment : segments) segment.known_R_n_b.reset();
  diagnostics::DiagnoseOptions options;
  options.confirm = 1;
  options.calibration.constant_bias = true;  // white noise: one constant bias matches
  const diagnostics::Diagnosis dx = diagnostics::Diagnose(
      d.sim.session.series, segments, model::Model::Parse("base"), d.sim.site, options);
  if (std::getenv("PLUMB_PRINT")) std::cout << report::DiagnosisText(dx);
  ASSERT_FALSE(dx.candidates.empty());
  const diagnostics::Candidate& best = dx.candidates.front();
  EXPECT_EQ(best.effect, "accel_scale_temperature") << report::DiagnosisText(dx);
  EXPECT_TRUE(best.significant);
  ASSERT_TRUE(best.refit_drop.has_value());
  EXPECT_NEAR(*best.refit_drop, d.base.fit.chi2 - d.extended.fit.chi2, 1e-6 * d.base.fit.chi2);
}

}  // namespace
}  // namespace plumb

int main(int argc, char** argv) {
  // The one registration line of way (a): a program of your own adds its effect to the
  // process-wide catalogue before it parses a model spec.
  plumb::autodiff::RegisterEffect<plumb::model::AccelScaleTemperature>("accel_scale_temperature");
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

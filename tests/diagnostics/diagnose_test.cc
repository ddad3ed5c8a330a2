// Acceptance battery of plumb diagnose (diagnostics/diagnose.h, issue 4, SPEC section 5) on
// simulated sessions with known truth:
//  1. every catalogue effect that multi-pose still-and-rotation data can excite, hidden in the
//     truth, is ranked first and significant by the score test on the base model; the refit
//     with it brings chi^2/dof back into the 99% band around 1 and recovers its parameters
//     within 3 sigma;
//  2. nothing hidden: the false-alarm rate over many sessions agrees with the stated level;
//  3. two hidden effects are found in two rounds;
//  4. effects that the data cannot excite, or determines only to more than their typical size,
//     are reported as not identifiable (never absent);
//  5. the score statistic (the predicted fall of chi^2) agrees with the refit's actual fall
//     for effects of the order of the noise.
//
// Sessions: a typical MEMS IMU (sim::SimulationOptions::TypicalMems) at 100 Hz without bias
// random walks (the backend does not model them yet), at a known site, on MultiPose schedules
// with the true still segments given (attitudes unknown) and the first pose's true heading
// stated (the Earth-rate gauge). The temperature goes up and down (a triangle of 1 degC
// around the reference, two periods per session) so that time and temperature are separable.
// The swing is kept small on purpose: the backend's noise level is the scatter of the still
// samples about each segment's mean (not detrended) and their correlation time, so a bias
// that moves within a segment by more than a fraction of the white noise inflates both (with
// accel_temperature_bias at 3 x typical and a 15 degC swing: tau 47 samples, chi^2/dof of
// the right model 0.69, below its 99% band; with 1 degC: tau 1, chi^2/dof 1.05).
#include "plumb/diagnostics/diagnose.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>
#include <vector>

#include "plumb/estimation/calibrator.h"
#include "plumb/model/registry.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"
#include "plumb/signal/chi_square.h"
#include "plumb/report/calibration_text.h"
#include "plumb/report/diagnosis_text.h"
#include "support/reverse_jobs.h"

namespace plumb::diagnostics {
namespace {

constexpr double kRateHz = 100.0;
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
/// Signs and relative sizes of a hidden effect's parameters (cycled), times its scale.
constexpr std::array<double, 9> kPattern = {1.0, -0.7, 0.5, -1.0, 0.8, -0.6, 0.9, -0.5, 0.7};

/// One hidden effect: every parameter set to scale * typical * kPattern[i].
struct Hidden {
  std::string effect;
  double scale = 3.0;  ///< multiple of the catalogue's typical size
};

/// What to simulate.
struct SessionSpec {
  std::vector<Hidden> hidden;
  int poses = 24;
  double still_s = 4.0;
  double turn_s = 2.0;
  std::uint64_t seed = 1;
};

/// A simulated session and everything Diagnose needs for it.
struct Session {
  sim::Simulation sim;
  std::vector<StillSegment> segments;  ///< the true still segments, attitudes unknown
  model::Model base;                   ///< "base" with the simulation's t_ref and temp_ref
  DiagnoseOptions options;             ///< first heading stated
};

/// Full name and true reported value of every parameter of the hidden effects.
std::vector<std::pair<std::string, double>> TrueValues(const std::vector<Hidden>& hidden) {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& h : hidden) {
    const auto effect = model::Registry::Global().Make(h.effect);
    const auto& info = effect->info();
    for (int i = 0; i < info.size(); ++i) {
      const double typical = info.parameters[static_cast<std::size_t>(i)].typical;
      out.emplace_back(info.ParameterName(i),
                       h.scale * typical * kPattern[static_cast<std::size_t>(i) % kPattern.size()]);
    }
  }
  return out;
}

model::Model WithReferences(const std::string& spec, const model::Model& truth) {
  model::Model m = model::Model::Parse(spec);
  m.t_ref_s = truth.t_ref_s;
  m.temp_ref_c = truth.temp_ref_c;
  return m;
}

/// `schedule` simulated with `opt`: the true segments with their attitudes unknown, the base
/// model with the simulation's references, the first heading stated.
Session SessionOf(const sim::Schedule& schedule, const sim::SimulationOptions& opt) {
  Session s;
  s.sim = sim::Simulate(schedule, opt);
  s.segments = s.sim.truth_segments;
  for (auto& seg : s.segments) seg.known_R_n_b.reset();
  s.base = WithReferences("base", s.sim.model);
  const Mat3 R0 = s.sim.true_R_n_b.front().toRotationMatrix();
  s.options.calibration.first_heading_deg = std::atan2(R0(1, 0), R0(0, 0)) * kRadToDeg;
  return s;
}

Session Simulate(const SessionSpec& spec) {
  const sim::Schedule schedule = sim::MultiPose(spec.poses, spec.still_s, spec.turn_s, spec.seed);
  std::string model_spec = "base";
  for (const auto& h : spec.hidden) model_spec += "+" + h.effect;
  sim::SimulationOptions opt = sim::SimulationOptions::WhiteMems();
  opt.rate_hz = kRateHz;
  opt.model = model::Model::Parse(model_spec);
  // The base at typical random values, the hidden effects at their stated sizes.
  opt.truth = sim::RandomParameters(opt.model, 1.0, spec.seed);
  for (int t = 0; t < opt.model.num_terms(); ++t) {
    if (!opt.model.terms()[static_cast<std::size_t>(t)].effect->info().linear_stage) {
      auto& block = opt.truth[static_cast<std::size_t>(t)];
      std::fill(block.begin(), block.end(), 0.0);
    }
  }
  for (const auto& [name, value] : TrueValues(spec.hidden)) {
    sim::SetParameter(opt.model, opt.truth, name, value);
  }
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "test");
  opt.temperature = sim::TemperatureProfile::UpDown(24.5, 25.5, schedule.duration_s() / 2.0);
  opt.seed = spec.seed;

  Session s = SessionOf(schedule, opt);
  s.options.calibration.constant_bias = true;  // white noise: one constant bias matches
  return s;
}

Diagnosis DiagnoseSession(const Session& s, const model::Model& model) {
  return Diagnose(s.sim.session.series, s.segments, model, s.sim.site, s.options);
}

const estimation::ParameterEstimate* FindParameter(const estimation::CalibrationResult& r,
                                                   const std::string& name) {
  for (const auto& p : r.calibration.parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

/// The 99% band of chi^2/dof around 1 for `dof` degrees of freedom.
std::pair<double, double> Chi2DofBand(int dof) {
  return {signal::ChiSquareQuantileExact(0.005, dof) / dof, signal::ChiSquareQuantileExact(0.995, dof) / dof};
}

// --- 1. one hidden effect ------------------------------------------------------------------

struct OneEffect {
  std::string effect;
  std::uint64_t seed;
};

class HiddenEffect : public ::testing::TestWithParam<OneEffect> {};

TEST_P(HiddenEffect, RankedFirstSignificantAndRecoveredByTheRefit) {
  SessionSpec spec;
  spec.hidden = {{GetParam().effect, 3.0}};
  spec.seed = GetParam().seed;
  const Session s = Simulate(spec);
  const Diagnosis d = DiagnoseSession(s, s.base);
  ASSERT_FALSE(d.candidates.empty());
  const Candidate& best = d.candidates.front();
  EXPECT_EQ(best.effect, GetParam().effect) << report::DiagnosisText(d);
  EXPECT_TRUE(best.significant) << report::DiagnosisText(d);
  const auto it = std::find_if(d.candidates.begin(), d.candidates.end(),
                               [&](const Candidate& c) { return c.effect == GetParam().effect; });
  ASSERT_NE(it, d.candidates.end()) << report::DiagnosisText(d);
  for (const auto& n : it->not_identifiable) {
    ADD_FAILURE() << n.parameter << " not identifiable (ratio " << n.ratio << ", excited "
                  << n.excited << ")";
  }
  // Like with like: an effect the user's own fit sees is advised; one scored in the velocity
  // residuals, which the user's fit does not hold, only when its refit lowers that fit's
  // chi^2/dof (VelocityCandidateAdvisedOnAFitThatHoldsItsResiduals).
  if (!best.with_velocity) {
    EXPECT_TRUE(best.recommended) << report::DiagnosisText(d);
    EXPECT_EQ(NextModelSpec(d), "base+" + GetParam().effect) << report::DiagnosisText(d);
  }
  if (best.recommended) {
    ASSERT_TRUE(best.refit.has_value());
    EXPECT_LT(best.refit->fit.chi2_dof(), d.fit.fit.chi2_dof());
  }
  // The refit with the effect (Diagnose's own when it confirmed it, else a fresh one).
  const estimation::CalibrationResult refit =
      it->refit ? *it->refit
                : estimation::Calibrate(s.sim.session.series, s.segments,
                                        WithReferences("base+" + GetParam().effect, s.sim.model),
                                        s.sim.site, s.options.calibration);
  const auto [lo, hi] = Chi2DofBand(refit.fit.dof);
  std::cout << GetParam().effect << ": base chi2/dof " << d.fit.fit.chi2_dof()
            << ", LM " << it->lm << ", refit chi2/dof " << refit.fit.chi2_dof() << " on "
            << refit.fit.dof << " dof (99% band " << lo << " .. " << hi << ")\n";
  EXPECT_GT(refit.fit.chi2_dof(), lo) << report::FullReport(refit);
  EXPECT_LT(refit.fit.chi2_dof(), hi) << report::FullReport(refit);
  for (const auto& [name, truth] : TrueValues(spec.hidden)) {
    const estimation::ParameterEstimate* p = FindParameter(refit, name);
    ASSERT_NE(p, nullptr) << name;
    ASSERT_TRUE(p->observable) << name << "\n" << report::FullReport(refit);
    EXPECT_LT(std::abs(p->value - truth), 3.0 * p->sigma)
        << name << ": truth " << truth << ", estimate " << p->value << " +- " << p->sigma;
  }
}

std::string EffectName(const ::testing::TestParamInfo<OneEffect>& info) {
  return info.param.effect;
}

// The effects that the backend's residuals see on multi-pose data: still accelerometer and
// gyroscope means (time, temperature, pose) and the gyroscope integrated over the turns.
INSTANTIATE_TEST_SUITE_P(
    Catalogue, HiddenEffect,
    ::testing::Values(OneEffect{"accel_bias_drift", 101}, OneEffect{"gyro_bias_drift", 102},
                      OneEffect{"accel_temperature_bias", 103},
                      OneEffect{"gyro_temperature_bias", 104},
                      OneEffect{"gyro_g_sensitivity", 105},
                      OneEffect{"accel_scale_nonlinearity", 106},
                      OneEffect{"gyro_scale_nonlinearity", 107},
                      // Seen through the velocity residuals (the accelerometer during the
                      // turns), which diagnose adds for them:
                      OneEffect{"accel_size_effect", 108}, OneEffect{"time_offset", 109}),
    EffectName);

// Like with like (issue 34): when the user's fit holds the velocity residuals, a hidden time
// offset is scored and its refit compared on the same residuals, and it is advised; the fit
// diagnosed is the user's (velocity residuals kept in the refits of the other candidates).
TEST(Diagnose, VelocityCandidateAdvisedOnAFitThatHoldsItsResiduals) {
  SessionSpec spec;
  spec.hidden = {{"time_offset", 3.0}};
  spec.seed = 109;
  Session s = Simulate(spec);
  s.options.calibration.accel_in_motion = true;
  const Diagnosis d = DiagnoseSession(s, s.base);
  EXPECT_GT(d.fit.fit.velocity_segments, 0);
  ASSERT_FALSE(d.candidates.empty());
  const Candidate& best = d.candidates.front();
  EXPECT_EQ(best.effect, "time_offset") << report::DiagnosisText(d);
  EXPECT_TRUE(best.recommended) << report::DiagnosisText(d);
  EXPECT_EQ(NextModelSpec(d), "base+time_offset") << report::DiagnosisText(d);
  for (const Candidate& c : d.candidates) {
    if (c.refit) EXPECT_GT(c.refit->fit.velocity_segments, 0) << c.effect;
  }
}

// The time base (issue 34 item 3): stamps a host wrote on arrival (late by 0.25 ms more each
// sample, back every 25: the pattern of the ChanghyeonKim93 sessions) make the brisk turns'
// integration misfit; the refit on the uniform clock is ranked first and advised; on the
// sensor's own clock the time base is skipped, never a candidate.
TEST(Diagnose, AHostArrivalClockIsFoundAndTheUniformClockAdvised) {
  SessionSpec spec;
  spec.seed = 110;
  spec.turn_s = 0.3;  // brisk hand-held turns, ~5 rad/s: the stamps' errors show in them
  Session s = Simulate(spec);
  const Diagnosis on_sensor_clock = DiagnoseSession(s, s.base);
  for (const Candidate& c : on_sensor_clock.candidates) EXPECT_NE(c.effect, kTimeBaseCandidate);
  const auto skipped = std::find_if(on_sensor_clock.skipped.begin(), on_sensor_clock.skipped.end(),
                                    [](const Skipped& k) { return k.effect == kTimeBaseCandidate; });
  ASSERT_NE(skipped, on_sensor_clock.skipped.end());
  EXPECT_EQ(skipped->reason, "the stamps are a uniform sample clock already");

  std::vector<double>& t = s.sim.session.series.t_s;
  for (std::size_t k = 0; k < t.size(); ++k) t[k] += 3e-4 * static_cast<double>(k % 25);
  const Diagnosis d = DiagnoseSession(s, s.base);
  ASSERT_FALSE(d.candidates.empty());
  const Candidate& best = d.candidates.front();
  EXPECT_EQ(best.kind, CandidateKind::kTimeBase) << report::DiagnosisText(d);
  EXPECT_TRUE(best.significant) << report::DiagnosisText(d);
  EXPECT_TRUE(best.recommended) << report::DiagnosisText(d);
  EXPECT_TRUE(UniformClockNext(d));
  EXPECT_EQ(NextModelSpec(d), "base");
  // Back to the noise on the uniform clock.
  ASSERT_TRUE(best.refit.has_value());
  const auto [lo, hi] = Chi2DofBand(best.refit->fit.dof);
  EXPECT_LT(best.refit->fit.chi2_dof(), hi) << report::DiagnosisText(d);
  std::cout << "host clock: chi2/dof " << d.fit.fit.chi2_dof() << " on the stamps, "
            << best.refit->fit.chi2_dof() << " on the uniform clock (99% band " << lo << " .. "
            << hi << ")\n";
}

/// A session of the simulator's default sensor (white noise, walk, instability, warming), its
/// walk and instability times `wander`, 12 holds of 30 s, with `hidden` at 3 times its
/// typical size; fitted as a user would (the bias wandering at the levels the still data give
/// or the typical ones).
Session SimulateWandering(double wander, const std::string& hidden, std::uint64_t seed) {
  const sim::Schedule schedule = sim::MultiPose(12, 30.0, 2.0, seed);
  sim::SimulationOptions opt = sim::SimulationOptions::TypicalMems();
  opt.rate_hz = kRateHz;
  opt.accel_bias_walk_density *= wander;
  opt.gyro_bias_walk_density *= wander;
  opt.accel_bias_instability *= wander;
  opt.gyro_bias_instability *= wander;
  opt.model = model::Model::Parse(hidden.empty() ? "base" : "base+" + hidden);
  opt.truth = sim::RandomParameters(model::Model::Parse(opt.model.spec()), 1.0, seed);
  if (!hidden.empty()) {
    for (const auto& [name, value] : TrueValues({{hidden, 3.0}})) {
      sim::SetParameter(opt.model, opt.truth, name, value);
    }
  }
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "test");
  opt.seed = seed;
  return SessionOf(schedule, opt);
}

TEST(Diagnose, ASensorWanderingMoreThanTypicalIsTheWanderNotAnEffect) {
  // Five times the typical wander and no effect missing: the holds disagree far beyond the
  // typical levels the fit assumes (chi2/dof about 16), which the score tests pin on catalogue
  // effects (g-sensitivity, scale nonlinearity: "significant"). The bias-wander candidate, the
  // same model with the levels estimated from the session, explains it and is advised.
  const Session s = SimulateWandering(5.0, "", 120);
  const Diagnosis d = DiagnoseSession(s, s.base);
  ASSERT_FALSE(d.candidates.empty());
  const Candidate& best = d.candidates.front();
  EXPECT_EQ(best.kind, CandidateKind::kWander) << report::DiagnosisText(d);
  EXPECT_EQ(best.effect, kWanderCandidate);
  EXPECT_EQ(best.dof, 2);
  EXPECT_TRUE(best.recommended) << report::DiagnosisText(d);
  EXPECT_EQ(Recommended(d), &best);
  EXPECT_TRUE(EstimateWanderNext(d));
  EXPECT_FALSE(UniformClockNext(d));
  EXPECT_EQ(NextModelSpec(d), "base");
  ASSERT_TRUE(best.refit.has_value());
  const auto [lo, hi] = Chi2DofBand(best.refit->fit.dof);
  EXPECT_GT(d.fit.fit.chi2_dof(), 5.0);
  EXPECT_LT(best.refit->fit.chi2_dof(), hi) << report::DiagnosisText(d);
  EXPECT_TRUE(best.refit->fit.gates.empty());
  EXPECT_NE(report::DiagnosisText(d).find("best: bias_wander (its refit: chi2/dof "),
            std::string::npos) << report::DiagnosisText(d);
  std::cout << "5 x the typical wander: chi2/dof " << d.fit.fit.chi2_dof()
            << " with the typical levels, " << best.refit->fit.chi2_dof()
            << " with the levels from the session\n";

  // The typical wander and a g-sensitivity three times its typical size: the effect is
  // advised, not the wander.
  const Session g = SimulateWandering(1.0, "gyro_g_sensitivity", 121);
  const Diagnosis dg = DiagnoseSession(g, g.base);
  const Candidate* advised = Recommended(dg);
  ASSERT_NE(advised, nullptr) << report::DiagnosisText(dg);
  EXPECT_EQ(advised->effect, "gyro_g_sensitivity") << report::DiagnosisText(dg);
  EXPECT_FALSE(EstimateWanderNext(dg));

  // A fit that estimates the levels already has no such candidate.
  Session held = s;
  held.options.calibration.estimate_walk = true;
  const Diagnosis dh = DiagnoseSession(held, held.base);
  for (const Candidate& c : dh.candidates) EXPECT_NE(c.kind, CandidateKind::kWander);
  const auto skipped = std::find_if(dh.skipped.begin(), dh.skipped.end(),
                                    [](const Skipped& k) { return k.effect == kWanderCandidate; });
  ASSERT_NE(skipped, dh.skipped.end());
  EXPECT_EQ(skipped->reason, "the wander levels are estimated from the session already");
}

using ::plumb::testing::ReverseOnTwoThreads;

TEST(Diagnose, TheSameBitForBitWhetherItsFitsRunInTurnOrAtOnce) {
  // DiagnoseOptions::run_jobs runs the two probe fits (its own residuals, and with velocity
  // residuals for accel_size_effect) and the refits: each writes only its own result. At once,
  // the first probe fit refits its best candidates (gyro_g_sensitivity) while the second runs;
  // the refits of both fits' candidates are the same as in turn.
  SessionSpec spec;
  spec.hidden = {{"accel_size_effect", 3.0}, {"gyro_g_sensitivity", 3.0}};
  spec.seed = 108;
  Session s = Simulate(spec);
  s.options.confirm = 10;  // every significant candidate, of both probe fits
  const Diagnosis in_turn = DiagnoseSession(s, s.base);
  s.options.run_jobs = ReverseOnTwoThreads;
  const Diagnosis at_once = DiagnoseSession(s, s.base);
  ASSERT_TRUE(in_turn.fit_with_velocity.has_value());
  ASSERT_TRUE(at_once.fit_with_velocity.has_value());
  EXPECT_EQ(in_turn.fit.fit.chi2, at_once.fit.fit.chi2);
  EXPECT_EQ(in_turn.fit_with_velocity->fit.chi2, at_once.fit_with_velocity->fit.chi2);
  ASSERT_EQ(in_turn.candidates.size(), at_once.candidates.size());
  int refits = 0, with_velocity = 0;
  for (std::size_t i = 0; i < in_turn.candidates.size(); ++i) {
    const Candidate& a = in_turn.candidates[i];
    const Candidate& b = at_once.candidates[i];
    EXPECT_EQ(a.effect, b.effect);
    EXPECT_EQ(a.lm, b.lm) << a.effect;
    EXPECT_EQ(a.evidence, b.evidence) << a.effect;
    EXPECT_EQ(a.refit_drop, b.refit_drop) << a.effect;
    ASSERT_EQ(a.refit.has_value(), b.refit.has_value()) << a.effect;
    if (!a.refit) continue;
    ++refits;
    if (a.with_velocity) ++with_velocity;
    EXPECT_EQ(a.refit->fit.chi2, b.refit->fit.chi2) << a.effect;
    EXPECT_EQ(a.refit->calibration.covariance, b.refit->calibration.covariance) << a.effect;
  }
  EXPECT_GE(refits, 2);
  EXPECT_GE(with_velocity, 1);
  EXPECT_LT(with_velocity, refits);
}

// --- 2. nothing hidden ---------------------------------------------------------------------

/// Smallest k with P(X > k) <= tail for X ~ Binomial(n, p).
int BinomialUpperBound(int n, double p, double tail) {
  double term = std::pow(1.0 - p, n);  // P(X = 0)
  double cdf = term;
  int k = 0;
  while (1.0 - cdf > tail && k < n) {
    term *= static_cast<double>(n - k) / static_cast<double>(k + 1) * p / (1.0 - p);
    cdf += term;
    ++k;
  }
  return k;
}

TEST(Diagnose, NothingHiddenFalseAlarmRateMatchesTheLevel) {
  // 24 sessions without any catalogue effect. Every identifiable candidate with q > 0 is one
  // test at level alpha = DiagnoseOptions::significance. If the tests were independent the
  // number of false alarms would be Binomial(tests, alpha); the bound is its upper 0.1% point
  // (the candidates of one session share the residuals and are positively correlated, which
  // spreads the count but leaves its mean alone; the 0.1% tail leaves room for that). A score
  // test that never fires would pass that bound, so the sum of LM over the tests, whose mean
  // under "nothing missing" is the sum of their q, is checked too: within 3 standard
  // deviations, the deviation bounded as if the candidates of a session were fully correlated.
  constexpr int kSessions = 24;
  int tests = 0, alarms = 0;
  double lm_sum = 0.0, q_sum = 0.0, var_bound = 0.0;
  std::string alarm_list;
  for (int k = 0; k < kSessions; ++k) {
    SessionSpec spec;
    spec.poses = 16;
    spec.still_s = 3.0;
    spec.seed = 300 + static_cast<std::uint64_t>(k);
    Session s = Simulate(spec);
    s.options.confirm = 0;
    const Diagnosis d = DiagnoseSession(s, s.base);
    double session_sd = 0.0;
    for (const auto& c : d.candidates) {
      EXPECT_FALSE(c.refit_drop.has_value()) << c.effect;
      if (!c.identifiable || c.dof == 0) continue;
      ++tests;
      lm_sum += c.lm;
      q_sum += c.dof;
      session_sd += std::sqrt(2.0 * c.dof);
      if (c.significant) {
        ++alarms;
        alarm_list += "seed " + std::to_string(spec.seed) + ": " + c.effect + " LM " +
                      std::to_string(c.lm) + " (threshold " + std::to_string(c.threshold) + ")\n";
      }
    }
    var_bound += session_sd * session_sd;
  }
  const DiagnoseOptions defaults;
  const int bound = BinomialUpperBound(tests, defaults.significance, 1e-3);
  std::cout << alarms << " false alarms in " << tests << " tests (expected "
            << tests * defaults.significance << ", bound " << bound << "); sum LM " << lm_sum
            << " against sum q " << q_sum << " +- " << std::sqrt(var_bound) << "\n"
            << alarm_list;
  EXPECT_GE(tests, kSessions * 7);  // at least 7 identifiable candidates per session
  EXPECT_LE(alarms, bound) << alarm_list;
  EXPECT_NEAR(lm_sum, q_sum, 3.0 * std::sqrt(var_bound));
}

// --- 3. two hidden effects -----------------------------------------------------------------

TEST(Diagnose, TwoHiddenEffectsAreFoundInTwoRounds) {
  SessionSpec spec;
  spec.hidden = {{"gyro_g_sensitivity", 3.0}, {"accel_temperature_bias", 3.0}};
  spec.seed = 401;
  const Session s = Simulate(spec);
  const std::vector<std::string> hidden = {"gyro_g_sensitivity", "accel_temperature_bias"};

  const Diagnosis first = DiagnoseSession(s, s.base);
  ASSERT_FALSE(first.candidates.empty());
  const Candidate& found = first.candidates.front();
  ASSERT_TRUE(std::find(hidden.begin(), hidden.end(), found.effect) != hidden.end())
      << report::DiagnosisText(first);
  EXPECT_TRUE(found.significant) << report::DiagnosisText(first);
  const std::string other = found.effect == hidden[0] ? hidden[1] : hidden[0];

  const Diagnosis second =
      DiagnoseSession(s, WithReferences("base+" + found.effect, s.sim.model));
  ASSERT_FALSE(second.candidates.empty());
  const Candidate& next = second.candidates.front();
  EXPECT_EQ(next.effect, other) << report::DiagnosisText(second);
  EXPECT_TRUE(next.significant) << report::DiagnosisText(second);

  // With both, the fit is back to the noise and both effects are recovered.
  ASSERT_TRUE(next.refit.has_value()) << report::DiagnosisText(second);
  const estimation::CalibrationResult& both = *next.refit;
  const auto [lo, hi] = Chi2DofBand(both.fit.dof);
  EXPECT_GT(both.fit.chi2_dof(), lo) << report::FullReport(both);
  EXPECT_LT(both.fit.chi2_dof(), hi) << report::FullReport(both);
  for (const auto& [name, truth] : TrueValues(spec.hidden)) {
    const estimation::ParameterEstimate* p = FindParameter(both, name);
    ASSERT_NE(p, nullptr) << name;
    EXPECT_LT(std::abs(p->value - truth), 3.0 * p->sigma)
        << name << ": truth " << truth << ", estimate " << p->value << " +- " << p->sigma;
  }
}

// --- 4. not excited: not identifiable, never absent ----------------------------------------

TEST(Diagnose, EffectsStillDataCannotExciteAreNotIdentifiable) {
  // Both effects are present in the truth (3 x typical), but without the motion between the
  // poses nothing in the fit sees angular rate or acceleration: the lever arms act only
  // through Earth rate squared (~1e-11 m/s^2) and the time offset through the angular
  // acceleration, which is zero when still. (Only the two verdicts are checked: without
  // motion the backend holds every pose's heading at 0, so the base fit misfits the Earth
  // rate, chi^2/dof 2.1 here, and other candidates may come out significant.)
  SessionSpec spec;
  spec.hidden = {{"accel_size_effect", 3.0}, {"time_offset", 3.0}};
  spec.seed = 501;
  Session s = Simulate(spec);
  s.options.calibration.use_motion = false;
  const Diagnosis d = DiagnoseSession(s, s.base);
  EXPECT_EQ(d.fit.fit.motion_segments, 0);
  const std::string report = report::DiagnosisText(d);
  for (const std::string name : {"accel_size_effect", "time_offset"}) {
    const auto it = std::find_if(d.candidates.begin(), d.candidates.end(),
                                 [&](const Candidate& c) { return c.effect == name; });
    ASSERT_NE(it, d.candidates.end()) << name << "\n" << report;
    EXPECT_FALSE(it->identifiable) << name << "\n" << report;
    EXPECT_FALSE(it->significant) << name;
    EXPECT_EQ(it->dof, 0) << name;
    ASSERT_EQ(static_cast<int>(it->not_identifiable.size()), it->num_parameters) << name;
    for (const auto& n : it->not_identifiable) {
      EXPECT_FALSE(n.excited) << n.parameter << " ratio " << n.ratio;
    }
    // Listed after every identifiable candidate, and said so in the report.
    for (auto later = it; later != d.candidates.end(); ++later) {
      EXPECT_FALSE(later->identifiable) << later->effect << " after " << name;
    }
    EXPECT_NE(report.find("  " + std::string(name) + ": "), std::string::npos) << report;
  }
  EXPECT_NE(report.find("not identifiable"), std::string::npos) << report;
}

TEST(Diagnose, EarthRateIsFoundWithoutASite) {
  // The session is recorded at a real site (Earth rate in the gyroscope), then diagnosed as if
  // no site were known: earth_rate is the candidate the gyroscope's still residuals ask for,
  // and its refit measures the horizontal and vertical Earth rate in the heading gauge (the
  // first pose's true heading stated), i.e. the latitude.
  SessionSpec spec;
  spec.seed = 701;
  spec.still_s = 8.0;
  Session s = Simulate(spec);
  s.options.confirm = 1;
  const Diagnosis d = Diagnose(s.sim.session.series, s.segments, s.base,
                               geo::Site::Unknown(s.sim.site.gravity()), s.options);
  ASSERT_FALSE(d.candidates.empty());
  const Candidate& best = d.candidates.front();
  EXPECT_EQ(best.effect, "earth_rate") << report::DiagnosisText(d);
  EXPECT_TRUE(best.significant) << report::DiagnosisText(d);
  ASSERT_TRUE(best.refit.has_value());
  const double lat = 51.64 * M_PI / 180.0, omega = 7.292115e-5;
  const estimation::ParameterEstimate* north = FindParameter(*best.refit, "earth_rate.omega.north");
  const estimation::ParameterEstimate* down = FindParameter(*best.refit, "earth_rate.omega.down");
  ASSERT_NE(north, nullptr);
  ASSERT_NE(down, nullptr);
  EXPECT_EQ(north->unit, "rad/s");
  EXPECT_LT(std::abs(north->value - omega * std::cos(lat)), 3.0 * north->sigma) << north->sigma;
  EXPECT_LT(std::abs(down->value + omega * std::sin(lat)), 3.0 * down->sigma) << down->sigma;
}

// --- 5. predicted against actual fall ------------------------------------------------------

struct SmallEffect {
  std::string effect;
  double scale;  ///< multiple of the typical size giving LM of a few tens
  std::uint64_t seed;
};

class SmallHiddenEffect : public ::testing::TestWithParam<SmallEffect> {};

TEST_P(SmallHiddenEffect, ScoreStatisticPredictsTheRefitsFall) {
  // An effect of the order of the noise (LM of a few tens: the effect moves the whitened
  // residuals by well under one sigma each). LM is the Gauss-Newton prediction of the fall of
  // chi^2 and is exact for a problem linear in its unknowns (score_test_test.cc); here only
  // the attitudes (SO(3)), the effect's coupling with F and E and the refit's re-weighting of
  // the motion residuals with its own E make it approximate, to second order in parameter
  // shifts of about one sigma: measured, |LM - drop| / drop < 1e-4 for all seven effects.
  // The tolerance, 1%, is tighter than the 10-20% the issue allowed because the measured
  // agreement is that good, and still far from the tens of per cent that a mistake in the
  // statistic would cost (Z not projected away from J, or whitened differently from r).
  SessionSpec spec;
  spec.hidden = {{GetParam().effect, GetParam().scale}};
  spec.seed = GetParam().seed;
  Session s = Simulate(spec);
  s.options.candidates = {GetParam().effect};
  const Diagnosis d = DiagnoseSession(s, s.base);
  ASSERT_EQ(d.candidates.size(), 1u) << report::DiagnosisText(d);
  const Candidate& c = d.candidates.front();
  EXPECT_TRUE(c.significant) << report::DiagnosisText(d);
  ASSERT_TRUE(c.refit_drop.has_value()) << report::DiagnosisText(d);
  std::cout << c.effect << ": LM " << c.lm << " (q " << c.dof << "), refit drop " << *c.refit_drop
            << ", relative difference " << (c.lm - *c.refit_drop) / *c.refit_drop << "\n";
  EXPECT_GT(c.lm, 15.0);   // of the order of the noise: a few tens,
  EXPECT_LT(c.lm, 300.0);  // not the huge falls of the tests above
  EXPECT_NEAR(c.lm, *c.refit_drop, 0.01 * *c.refit_drop);
}

std::string SmallEffectName(const ::testing::TestParamInfo<SmallEffect>& info) {
  return info.param.effect;
}

INSTANTIATE_TEST_SUITE_P(
    Catalogue, SmallHiddenEffect,
    ::testing::Values(SmallEffect{"accel_bias_drift", 0.2, 601},
                      SmallEffect{"gyro_bias_drift", 0.1, 602},
                      SmallEffect{"accel_temperature_bias", 0.7, 603},
                      SmallEffect{"gyro_temperature_bias", 0.35, 604},
                      SmallEffect{"gyro_g_sensitivity", 0.02, 605},
                      SmallEffect{"accel_scale_nonlinearity", 0.3, 606},
                      SmallEffect{"gyro_scale_nonlinearity", 0.1, 607}),
    SmallEffectName);

}  // namespace
}  // namespace plumb::diagnostics

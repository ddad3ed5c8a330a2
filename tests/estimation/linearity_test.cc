// The check that chi^2 is as quadratic as the covariance assumes (estimation/linearity.h) and
// the nonlinear gate on it: exactly 1 where every residual is linear in the unknowns, near 1
// on well-spread poses, far above on the six faces with free attitudes (where the NEES over
// the full covariance is 1e5: docs/sensitivity.md "How many poses").
#include "plumb/estimation/linearity.h"

#include <gtest/gtest.h>

#include <cmath>

#include <algorithm>
#include <iostream>

#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/gates.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "support/sim_options.h"

namespace plumb::estimation {
namespace {

sim::Simulation Session(int poses, std::uint64_t seed, bool attitudes_known) {
  const sim::SimulationOptions opt =
      testing::TypicalMemsAt(geo::Site::At(51.64, -1.2, 100.0, "flags"), seed);
  sim::Simulation s = sim::Simulate(sim::MultiPose(poses, 5.0, 2.0, seed), opt);
  if (!attitudes_known) {
    for (auto& seg : s.truth_segments) seg.known_R_n_b.reset();
  }
  return s;
}

bool HasGate(const FitReport& fit, const std::string& name) {
  return std::any_of(fit.gates.begin(), fit.gates.end(),
                     [&](const Gate& g) { return g.name == name; });
}

TEST(Linearity, ResidualsLinearInTheUnknownsGiveRatiosOfOne) {
  // Known attitudes and no motion residuals: the still residuals F (R^T g) + b and
  // E (R^T w_e) + b_g and the wander factors are linear in every unknown, so chi^2 is exactly
  // quadratic and every direction's ratio is 1 (to rounding).
  const sim::Simulation s = Session(12, 41, true);
  CalibrationOptions options;
  options.use_motion = false;
  const CalibrationResult r = Calibrate(s.session.series, s.truth_segments, s.model, s.site, options);
  const LinearityReport& lin = r.fit.linearity;
  ASSERT_TRUE(lin.checked);
  EXPECT_EQ(lin.step_sigmas, kLinearityStepSigmas);
  EXPECT_EQ(lin.ratio.size(), static_cast<std::size_t>(kLinearityDirections));
  for (double ratio : lin.ratio) EXPECT_NEAR(ratio, 1.0, 1e-6);
  EXPECT_FALSE(HasGate(r.fit, "nonlinear"));
}

TEST(Linearity, WellSpreadPosesWithFreeAttitudesStayQuadratic) {
  for (std::uint64_t seed : {1U, 2U, 3U}) {
    const sim::Simulation s = Session(12, seed, false);
    const CalibrationResult r = Calibrate(s.session.series, s.truth_segments, s.model, s.site, {});
    ASSERT_TRUE(r.fit.linearity.checked);
    EXPECT_LT(r.fit.linearity.worst_ratio, 1.2) << "seed " << seed;
    EXPECT_TRUE(r.fit.gates.empty()) << "seed " << seed << ": " << r.fit.gates.front().message;
    std::cout << "12 poses, seed " << seed << ": worst ratio " << r.fit.linearity.worst_ratio << "\n";
  }
}

// Six faces with free attitudes lie in a curved valley of near-equal fits (the nonlinear gate
// fired on every seed, chi2 rising hundreds of times what the covariance said): the
// combinations that valley runs along are the ones the data determine no better than their
// typical spread, so the fit holds them where it starts, and what is left is quadratic.
TEST(Linearity, SixFacesWithFreeAttitudesHoldTheirCurvedValley) {
  for (std::uint64_t seed : {1U, 2U, 3U}) {
    const sim::Simulation s = Session(6, seed, false);
    const CalibrationResult r = Calibrate(s.session.series, s.truth_segments, s.model, s.site, {});
    ASSERT_TRUE(r.fit.converged);
    EXPECT_FALSE(r.calibration.observability.weakly_determined.empty()) << "seed " << seed;
    EXPECT_LT(r.fit.linearity.worst_ratio, 1.5) << "seed " << seed;
    EXPECT_FALSE(HasGate(r.fit, "nonlinear")) << "seed " << seed;
    std::cout << "6 poses, seed " << seed << ": "
              << r.calibration.observability.weakly_determined.size()
              << " weak combinations held, worst ratio " << r.fit.linearity.worst_ratio << "\n";
  }
}

TEST(Linearity, TheCheckLeavesTheSolutionAsItWas) {
  const sim::Simulation s = Session(6, 1, false);
  CalibrationOptions off;
  off.check_linearity = false;
  const CalibrationResult with = Calibrate(s.session.series, s.truth_segments, s.model, s.site, {});
  const CalibrationResult without =
      Calibrate(s.session.series, s.truth_segments, s.model, s.site, off);
  EXPECT_FALSE(without.fit.linearity.checked);
  EXPECT_FALSE(HasGate(without.fit, "nonlinear"));
  ASSERT_EQ(with.calibration.parameters.size(), without.calibration.parameters.size());
  for (std::size_t i = 0; i < with.calibration.parameters.size(); ++i) {
    const auto& a = with.calibration.parameters[i];
    const auto& b = without.calibration.parameters[i];
    EXPECT_EQ(a.value, b.value);
    if (std::isnan(a.sigma)) EXPECT_TRUE(std::isnan(b.sigma)) << a.name;
    else EXPECT_EQ(a.sigma, b.sigma) << a.name;
  }
  EXPECT_EQ(with.fit.chi2, without.fit.chi2);
  ASSERT_EQ(with.fit.still.size(), without.fit.still.size());
  for (std::size_t k = 0; k < with.fit.still.size(); ++k) {
    EXPECT_EQ(with.fit.still[k].acc_residual, without.fit.still[k].acc_residual);
  }
}

}  // namespace
}  // namespace plumb::estimation

// The analytic sensitivity of a calibration to its assumptions (estimation/sensitivity.h)
// against finite differences of full refits on the same simulated sessions: the gravity and
// the latitude the fit is given.
#include "plumb/estimation/sensitivity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "plumb/estimation/calibrator.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"
#include "support/sim_options.h"

namespace plumb::estimation {
namespace {

sim::Simulation Session(std::uint64_t seed) {
  const sim::SimulationOptions opt =
      testing::TypicalMemsAt(geo::Site::At(6.67, -1.57, 250.0, "flags"), seed);
  sim::Simulation s = sim::Simulate(sim::MultiPose(12, 5.0, 2.0, seed), opt);
  for (auto& seg : s.truth_segments) seg.known_R_n_b.reset();
  return s;
}

geo::Site WithGravity(geo::Site site, double g) {
  site.g_n = Vec3(0.0, 0.0, g);
  return site;
}

TEST(Sensitivity, AgreesWithFiniteDifferencesOfRefits) {
  // Per session: d theta / d g and d theta / d lat analytic (one fit) against
  // (theta(p + h) - theta(p - h)) / 2h from two full refits. The refits differ from the
  // linearisation by the second-order terms only: agreement within 2 % of the largest
  // derivative of each assumption, on every parameter.
  constexpr double kG = 0.01;    // m/s^2
  constexpr double kLat = 0.5;   // deg
  for (std::uint64_t seed : {31U, 32U, 33U}) {
    const sim::Simulation s = Session(seed);
    const geo::Site site = s.site;
    const double g = site.gravity();
    const geo::Site lat_minus = geo::Site::At(6.67 - kLat, -1.57, 250.0, "flags");
    const geo::Site lat_plus = geo::Site::At(6.67 + kLat, -1.57, 250.0, "flags");
    std::vector<AssumptionChange> changes = {
        {"gravity", kG, WithGravity(site, g - kG), WithGravity(site, g + kG), s.truth_segments,
         s.truth_segments},
        {"lat_deg", kLat, lat_minus, lat_plus, s.truth_segments, s.truth_segments}};
    const Sensitivities S = AssumptionSensitivity(s.session.series, s.truth_segments, s.model,
                                                  site, {}, changes);
    for (std::size_t c = 0; c < changes.size(); ++c) {
      const auto minus = Calibrate(s.session.series, s.truth_segments, s.model,
                                   changes[c].site_minus, {});
      const auto plus = Calibrate(s.session.series, s.truth_segments, s.model,
                                  changes[c].site_plus, {});
      const auto col = static_cast<Eigen::Index>(c);
      const double scale = S.d_dp.col(col).cwiseAbs().maxCoeff();
      ASSERT_GT(scale, 0.0);
      double worst = 0.0;
      std::string worst_name;
      for (std::size_t i = 0; i < S.names.size(); ++i) {
        const double fd = (plus.calibration.parameters[i].value -
                           minus.calibration.parameters[i].value) / (2.0 * changes[c].step);
        const double analytic = S.d_dp(static_cast<Eigen::Index>(i), col);
        ASSERT_TRUE(std::isfinite(analytic)) << S.names[i];
        if (std::abs(fd - analytic) > worst) {
          worst = std::abs(fd - analytic);
          worst_name = S.names[i];
        }
      }
      EXPECT_LT(worst, 0.02 * scale) << changes[c].name << ", seed " << seed << ": " << worst_name;
      std::cout << changes[c].name << ", seed " << seed << ": largest |d/dp| " << scale
                << ", worst |refit - analytic| " << worst << " (" << worst_name << ")\n";
    }
    // A gravity given to the fit scales the accelerometer: d F_xx / d g = -F_xx / g.
    const double F_xx = Calibrate(s.session.series, s.truth_segments, s.model, site, {})
                            .calibration.parameters[0].value;
    EXPECT_NEAR(S.d_dp(0, 0), -F_xx / g, 1e-3 / g);
  }
}

}  // namespace
}  // namespace plumb::estimation

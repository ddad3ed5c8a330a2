// The paper's proposed static procedure (section 5) on a simulated one-minute still.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "plumb/core/error.h"
#include "plumb/geo/site.h"
#include "plumb/paper/static_procedure.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb::paper {
namespace {

constexpr double kLatDeg = 6.5;  // a site near the paper's latitude (its tau ~ cot(lat))

// A minute still, level, x north, 400 Hz, typical MEMS noise, biases that the paper's method
// cannot see on z.
sim::Simulation SimulateStill(std::uint64_t seed) {
  sim::SimulationOptions o = sim::SimulationOptions::TypicalMems();
  o.seed = seed;
  o.site = geo::Site::At(kLatDeg, 3.4, 40.0, "test");
  sim::SetParameter(o.model, o.truth, "accel.bias.x", 0.10);
  sim::SetParameter(o.model, o.truth, "accel.bias.y", -0.05);
  sim::SetParameter(o.model, o.truth, "accel.bias.z", 0.30);
  sim::SetParameter(o.model, o.truth, "accel.matrix.zz", 1.01);
  sim::SetParameter(o.model, o.truth, "gyro.bias.x", 0.002);
  sim::SetParameter(o.model, o.truth, "gyro.bias.y", -0.004);
  sim::SetParameter(o.model, o.truth, "gyro.bias.z", 0.001);
  return sim::Simulate(sim::PaperStatic(60.0), o);
}

TEST(PaperStatic, SimulatedMinuteReproducesThePapersPattern) {
  const sim::Simulation s = SimulateStill(42);
  const ImuSeries& series = s.session.series;
  const PaperStaticResult r =
      CalibratePaperStatic(series, 0, series.size(), s.site, PaperStaticOptions{});

  // The high-passed means are ~0 (double zero at DC), so the bias is the plain mean (step 6)
  // and beta, gamma, i.e. the accelerometer's off-diagonals, are ~0 (Table 4: 5e-9, -8e-7).
  EXPECT_LT(r.accel.filtered_mean.cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_LT(std::abs(r.accel.beta), 1e-5);
  EXPECT_LT(std::abs(r.accel.gamma), 1e-5);
  EXPECT_NEAR(r.accel.bias.x(), 0.10, 2e-3);
  EXPECT_NEAR(r.accel.bias.y(), -0.05, 2e-3);
  // z bias ~0 whatever the truth (0.3 here): step 2 removes the norm, bias and all (Table 3:
  // 0.0007); what is left is (m_x^2 + m_y^2) / (2 g) ~ 6e-4.
  EXPECT_LT(std::abs(r.accel.bias.z()), 2e-3);
  // mu ~ -1 (Table 4's -1.000); F in the paper's convention ~ -I, forward ~ +I.
  EXPECT_NEAR(r.accel.mu, -1.0, 1e-3);
  EXPECT_EQ(r.accel.F_paper(0, 0), -1.0);
  EXPECT_EQ(r.accel.F_paper(0, 1), 0.0);
  EXPECT_LT((r.F + r.accel.F_paper).norm(), 1e-15);
  EXPECT_NEAR(r.F(2, 2), 1.0, 1e-3);

  // Gyroscope: b ~ the mean; tau ~ -omega_N / omega_D = cot(lat) (Table 2: 8.53); xi, nu ~ 0.
  const double lat = kLatDeg * M_PI / 180.0;
  ASSERT_TRUE(r.has_gyro);
  EXPECT_NEAR(r.gyro.omega_p.x(), 7.292115e-5 * std::cos(lat), 1e-12);
  EXPECT_NEAR(r.gyro.omega_p.y(), 0.0, 1e-12);
  EXPECT_NEAR(r.gyro.omega_p.z(), -7.292115e-5 * std::sin(lat), 1e-12);
  EXPECT_NEAR(r.b_g.x(), 0.002 + 7.292115e-5 * std::cos(lat), 2e-5);
  EXPECT_NEAR(r.gyro.tau, 1.0 / std::tan(lat), 0.1);
  EXPECT_LT(std::abs(r.gyro.xi), 0.1);
  EXPECT_LT(std::abs(r.gyro.nu), 0.1);
  EXPECT_EQ(r.E(0, 0), 1.0);
  EXPECT_EQ(r.E(0, 1), 0.0);
}

TEST(PaperStatic, EquatorIsRefusedAndNoSiteLeavesTheGyroscopeOut) {
  const sim::Simulation s = SimulateStill(7);
  const ImuSeries& series = s.session.series;
  EXPECT_THROW(CalibratePaperStatic(series, 0, series.size(), geo::Site::At(0.0, 0.0, 0.0, "t"),
                                    PaperStaticOptions{}),
               InsufficientDataError);
  const PaperStaticResult no_site =
      CalibratePaperStatic(series, 0, series.size(), geo::Site::Unknown(), PaperStaticOptions{});
  EXPECT_FALSE(no_site.has_gyro);
  EXPECT_NEAR(no_site.accel.bias.x(), 0.10, 2e-3);
  bool said = false;
  for (const Notice& n : no_site.notes) {
    said = said || (n.code == "site_unknown" && n.options == std::vector<Option>{Option::kSite} &&
                    n.message.find("no site") != std::string::npos);
  }
  EXPECT_TRUE(said);
  EXPECT_THROW(CalibratePaperStatic(series, 5, 6, s.site, PaperStaticOptions{}), Error);
}

}  // namespace
}  // namespace plumb::paper

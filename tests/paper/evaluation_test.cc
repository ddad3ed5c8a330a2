// The paper's evaluation (paper/evaluation.h): % error, the datasheet check, the reconstructed
// inputs.
#include "plumb/paper/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "plumb/core/error.h"

namespace plumb::paper {
namespace {

TEST(PaperEvaluation, PercentErrorIsRelativeToTheBenchmarksMagnitude) {
  // The paper's Table 3, x: benchmark -0.0060, proposed -0.1015: +1.58E3 as printed.
  EXPECT_NEAR(PercentError(-0.1015, -0.0060), -1591.7, 0.1);
  EXPECT_NEAR(PercentError(0.0470, 0.1310), -64.1, 0.05);   // Table 3, y, as printed
  EXPECT_NEAR(PercentError(0.0007, 0.8262), -99.9, 0.05);   // Table 3, z, as printed
  EXPECT_NEAR(PercentError(-1.0, -0.9650), -3.6, 0.05);     // Table 4 prints -3.622
  EXPECT_TRUE(std::isnan(PercentError(1.0, 0.0)));
  EXPECT_TRUE(std::isnan(PercentError(NAN, 1.0)));
}

TEST(PaperEvaluation, TablesSetTheClosedFormsSideBySideInThePapersConvention) {
  PaperBenchmarkResult b;
  b.accel_bias = Vec3(-0.0060, 0.1310, 0.8262);
  b.accel_coupling_paper = -Mat3::Identity() * 0.965;
  b.gyro_bias_b0 = Vec3(0.1901e-3, -0.1953e-3, -0.5823e-3);
  b.gyro_bias_b1 = Vec3(1.6e-9, 0, 0);
  b.gyro_coupling_paper = Mat3::Identity();
  PaperStaticResult p;
  p.accel.bias = Vec3(-0.1015, 0.0470, 0.0007);
  p.accel.F_paper = -Mat3::Identity();
  p.has_gyro = true;
  p.gyro.bias = Vec3(0.2e-3, -0.4e-3, -1.1e-3);
  p.gyro.E_paper << 1, 0, 8.5258, 0, 1, -0.0283, 0, 0, 0.1586;
  const PaperTables t = MakePaperTables(b, p);
  EXPECT_EQ(t.accel_bias.proposed, p.accel.bias);
  EXPECT_NEAR(t.accel_bias.error_pct.z(), -99.9, 0.05);
  EXPECT_NEAR(t.accel_coupling.error_pct(0, 0), -3.6, 0.05);
  EXPECT_TRUE(std::isnan(t.accel_coupling.error_pct(0, 1)));  // zero benchmark
  ASSERT_TRUE(t.has_gyro);
  EXPECT_NEAR(t.gyro_bias.error_pct.x(), 5.2, 0.05);  // the paper prints +10.8 (rounded 0.2E-3)
  EXPECT_EQ(t.gyro_bias_b1_benchmark, b.gyro_bias_b1);
  EXPECT_NEAR(t.gyro_coupling.error_pct(2, 2), -84.14, 0.01);
  p.has_gyro = false;
  EXPECT_FALSE(MakePaperTables(b, p).has_gyro);
}

TEST(PaperEvaluation, DatasheetCheckFlagsOutOfSpecValues) {
  const PartLimits& part = FindPart("mpu6000");
  EXPECT_EQ(part.name, "MPU-6000");
  EXPECT_THROW(FindPart("no-such-part"), Error);
  Mat3 F = Mat3::Identity();
  F(0, 0) = 1.02;   // 2 %: within 3 %
  F(1, 1) = 0.95;   // 5 %: out
  F(0, 2) = 0.03;   // cross-axis 3 % / 1.02: out of 2 %
  const Vec3 b_a(0.4, -0.6, 0.7);  // x within 0.49, y out of 0.49, z within 0.78
  const std::vector<LimitCheck> checks =
      CheckDatasheet(part, F, b_a, Mat3::Identity(), Vec3::Zero(), true);
  EXPECT_EQ(checks.size(), 24u);
  std::vector<std::string> out;
  for (const auto& c : checks) {
    if (!c.within) out.push_back(c.quantity);
  }
  EXPECT_EQ(out, (std::vector<std::string>{"accel.bias.y", "accel scale y", "accel cross-axis xz"}));
  EXPECT_EQ(CheckDatasheet(part, F, b_a, Mat3::Identity(), Vec3::Zero(), false).size(), 12u);
}

TEST(PaperEvaluation, ReconstructionInvertsEachCalibration) {
  ImuSeries s;
  s.acc_unit = "m/s^2";
  s.gyr_unit = "rad/s";
  PaperBenchmarkResult b;
  b.F << 1.01, 0.02, 0, 0, 0.99, 0, 0, 0, 1.0;
  b.b_a = Vec3(0.1, 0.2, 0.3);
  b.E = Mat3::Identity() * 1.05;
  b.b_g = Vec3(0.01, 0, 0);
  b.gyro_bias_drift = Vec3(0.001, 0, 0);
  b.t0_s = 0.0;
  PaperStaticResult p;
  p.has_gyro = true;
  p.F = Mat3::Identity();
  p.E << 1, 0, 8.5, 0, 1, 0, 0, 0, 0;  // nu = 0: singular, as a static E can be
  const Vec3 f(0.5, -0.2, -9.8), w(0.1, 0.2, -0.3);
  for (int k = 0; k < 4; ++k) {
    const double t = 0.5 * k;
    const Vec3 ya = b.F * f + b.b_a;
    const Vec3 yg = b.E * w + b.b_g + b.gyro_bias_drift * t;
    s.t_s.push_back(t);
    s.acc.push_back(ya.cast<float>());
    s.gyr.push_back(yg.cast<float>());
  }
  const ReconstructedInputs r = ReconstructInputs(s, b, p, 2);
  ASSERT_EQ(r.t_s.size(), 2u);
  EXPECT_LT((r.f_benchmark[1] - f).norm(), 1e-5);
  EXPECT_LT((r.omega_benchmark[1] - w).norm(), 1e-6);
  EXPECT_LT((r.f_proposed[1] - (b.F * f + b.b_a)).norm(), 1e-5);  // F = I, b = 0
  EXPECT_TRUE(std::isnan(r.omega_proposed[0].x()));
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("proposed E is singular"), std::string::npos);
}

}  // namespace
}  // namespace plumb::paper

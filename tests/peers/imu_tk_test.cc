// imu_tk's files read exactly (shared data, skipped when absent), its inverse form turned into
// plumb's forward form, and its accelerometer cost against hand computations.
#include "plumb/peers/imu_tk.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <filesystem>

#include "plumb/core/error.h"
#include "temp_files.h"

namespace plumb::peers {
namespace {

using testing::ErrorOf;
using testing::TempFolder;

const std::string kImuTk = std::string(PLUMB_SHARED_DATA_DIR) + "/multipose/imu_tk";

bool HaveImuTk() { return std::filesystem::exists(kImuTk + "/test_imu_acc.calib"); }

// The .calib files hold imu_tk's answer rounded to 6 significant digits.
TEST(ImuTkCalib, ReadsTheAccelerometerFileExactly) {
  if (!HaveImuTk()) GTEST_SKIP() << "shared data absent: " << kImuTk;
  const ImuTkTriad t = ReadImuTkCalib(kImuTk + "/test_imu_acc.calib");
  Mat3 T, K;
  T << 1, -0.0033593, -0.00890639, 0, 1, -0.0213341, -0.0, 0, 1;
  K = Vec3(0.00241278, 0.00242712, 0.00241168).asDiagonal();
  EXPECT_EQ(t.T, T);
  EXPECT_EQ(t.K, K);
  EXPECT_EQ(t.B, Vec3(33124.2, 33275.2, 32364.4));
}

TEST(ImuTkCalib, ReadsTheGyroscopeFileExactly) {
  if (!HaveImuTk()) GTEST_SKIP() << "shared data absent: " << kImuTk;
  const ImuTkTriad t = ReadImuTkCalib(kImuTk + "/test_imu_gyro.calib");
  Mat3 T, K;
  T << 1, 0.00593634, 0.00111101, 0.00808812, 1, -0.0535569, 0.0253067, -0.0025513, 1;
  K = Vec3(0.000209295, 0.000209899, 0.000209483).asDiagonal();
  EXPECT_EQ(t.T, T);
  EXPECT_EQ(t.K, K);
  EXPECT_EQ(t.B, Vec3(32777.1, 32459.8, 32511.8));
}

TEST(ImuTkCalib, FullPrecisionFileReadExactly) {
  if (!HaveImuTk()) GTEST_SKIP() << "shared data absent: " << kImuTk;
  const ImuTkCalibration c = ReadImuTkFullPrecision(kImuTk + "/full_precision_params.txt");
  Mat3 T_a, T_g;
  T_a << 1, -0.003359299033234669, -0.0089063947432312159, 0, 1, -0.02133411938518472, -0.0, 0, 1;
  T_g << 1, 0.0059363404568289245, 0.0011110094938067108, 0.0080881184058236855, 1,
      -0.053556861838479131, 0.025306721418430801, -0.0025513028663729669, 1;
  EXPECT_EQ(c.acc.T, T_a);
  EXPECT_EQ(c.acc.K.diagonal(),
            Vec3(0.0024127846281317392, 0.0024271227955775117, 0.002411680275513924));
  EXPECT_EQ(c.acc.B, Vec3(33124.182564561655, 33275.179434180718, 32364.415649443108));
  EXPECT_EQ(c.gyro.T, T_g);
  EXPECT_EQ(c.gyro.K.diagonal(),
            Vec3(0.00020929452594210579, 0.00020989853973601207, 0.00020948298421848358));
  EXPECT_EQ(c.gyro.B, Vec3(32777.13994402239, 32459.802878848459, 32511.847461015594));
}

TEST(ImuTkCalib, CalibFilesAreTheFullPrecisionAnswerRounded) {
  if (!HaveImuTk()) GTEST_SKIP() << "shared data absent: " << kImuTk;
  const ImuTkCalibration full = ReadImuTkFullPrecision(kImuTk + "/full_precision_params.txt");
  const ImuTkTriad acc = ReadImuTkCalib(kImuTk + "/test_imu_acc.calib");
  const ImuTkTriad gyro = ReadImuTkCalib(kImuTk + "/test_imu_gyro.calib");
  // 6 significant digits: relative rounding at most 5e-6 (of the largest entry for T).
  EXPECT_LT((acc.T - full.acc.T).cwiseAbs().maxCoeff(), 5e-7);
  EXPECT_LT((acc.K.diagonal() - full.acc.K.diagonal()).cwiseQuotient(full.acc.K.diagonal()).cwiseAbs().maxCoeff(), 5e-6);
  EXPECT_LT((acc.B - full.acc.B).cwiseAbs().maxCoeff(), 0.05);
  EXPECT_LT((gyro.T - full.gyro.T).cwiseAbs().maxCoeff(), 5e-7);
  EXPECT_LT((gyro.B - full.gyro.B).cwiseAbs().maxCoeff(), 0.05);
}

TEST(ImuTkCalib, BadFilesNameTheFileAndTheLine) {
  const TempFolder dir;
  const std::string good_T = "1 0 0\n0 1 0\n0 0 1\n\n";
  const std::string good_K = "2 0 0\n0 3 0\n0 0 4\n\n";
  const std::string short_file = dir.Write("short.calib", good_T + good_K + "1\n2\n");
  std::string message = ErrorOf([&] { ReadImuTkCalib(short_file); });
  EXPECT_NE(message.find(short_file), std::string::npos) << message;
  EXPECT_NE(message.find("21 numbers"), std::string::npos) << message;

  const std::string word = dir.Write("word.calib", good_T + "2 0 0\n0 x 0\n0 0 4\n\n1\n2\n3\n");
  message = ErrorOf([&] { ReadImuTkCalib(word); });
  EXPECT_NE(message.find(word + ":line 6"), std::string::npos) << message;
  EXPECT_NE(message.find("'x'"), std::string::npos) << message;

  const std::string not_T = dir.Write("t.calib", "2 0 0\n0 1 0\n0 0 1\n\n" + good_K + "1\n2\n3\n");
  message = ErrorOf([&] { ReadImuTkCalib(not_T); });
  EXPECT_NE(message.find("diagonal of imu_tk's misalignment matrix T"), std::string::npos)
      << message;

  const std::string missing = dir.Write("x", "") + ".absent";
  message = ErrorOf([&] { ReadImuTkCalib(missing); });
  EXPECT_NE(message.find(missing), std::string::npos) << message;
  EXPECT_NE(message.find("cannot open"), std::string::npos) << message;
}

TEST(ImuTkCalib, FullPrecisionFileWithoutGyroIsAnError) {
  const TempFolder dir;
  const std::string path =
      dir.Write("p.txt", "ACC\nT=\n1 0 0\n0 1 0\n0 0 1\nK=\n2 0 0\n0 2 0\n0 0 2\nB=\n1 2 3\n");
  const std::string message = ErrorOf([&] { ReadImuTkFullPrecision(path); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("no section GYRO"), std::string::npos) << message;
}

TEST(ImuTkCalib, FullPrecisionInverseScaleMustMatch) {
  const TempFolder dir;
  const std::string triad = "T=\n1 0 0\n0 1 0\n0 0 1\nK=\n2 0 0\n0 2 0\n0 0 2\nB=\n1 2 3\n";
  const std::string path = dir.Write("p.txt", "ACC\n" + triad + "1/K= 0.5 0.5 0.4\nGYRO\n" + triad);
  const std::string message = ErrorOf([&] { ReadImuTkFullPrecision(path); });
  EXPECT_NE(message.find(path + ":line 12"), std::string::npos) << message;
  EXPECT_NE(message.find("'1/K=' does not match K"), std::string::npos) << message;
}

// calibrated = T K (raw - B)  <=>  raw = (T K)^-1 calibrated + B.
TEST(ImuTkForward, ForwardFormInvertsTheCorrection) {
  ImuTkCalibration c;
  c.acc.T << 1, -0.01, 0.02, 0, 1, -0.03, 0, 0, 1;
  c.acc.K = Vec3(0.5, 0.25, 0.2).asDiagonal();
  c.acc.B = Vec3(10, 20, 30);
  c.gyro.T << 1, 0.01, -0.02, 0.03, 1, 0.04, -0.05, 0.06, 1;
  c.gyro.K = Vec3(0.001, 0.002, 0.003).asDiagonal();
  c.gyro.B = Vec3(-1, -2, -3);
  const ForwardCalibration f = ImuTkToForward(c, {"a", "g"});
  EXPECT_EQ(f.peer, "imu_tk");
  const Vec3 raw(12, 24, 35);
  const Vec3 calibrated = c.acc.T * c.acc.K * (raw - c.acc.B);
  EXPECT_LT((f.accel_matrix * calibrated + f.accel_bias - raw).norm(), 1e-12);
  EXPECT_EQ(f.accel_matrix(1, 0), 0.0);
  EXPECT_EQ(f.accel_matrix(2, 0), 0.0);
  EXPECT_EQ(f.accel_matrix(2, 1), 0.0);
  const Vec3 rate = c.gyro.T * c.gyro.K * (raw - c.gyro.B);
  EXPECT_LT((f.gyro_matrix * rate + f.gyro_bias - raw).norm(), 1e-9);
  EXPECT_EQ(f.gyro_bias, c.gyro.B);
}

// By hand: raw - B = (2, 4, 5); K (raw - B) = (1, 1, 1); T (1, 1, 1) = (1.01, 0.97, 1);
// |.|^2 = 1.0201 + 0.9409 + 1 = 2.961; r = 1.7 - sqrt(2.961) = -0.0207556...;
// imu_tk's cost 0.5 r^2 = 2.15398...e-4.
TEST(ImuTkCost, MatchesAHandComputedResidual) {
  ImuTkCalibration c;
  c.acc.T << 1, -0.01, 0.02, 0, 1, -0.03, 0, 0, 1;
  c.acc.K = Vec3(0.5, 0.25, 0.2).asDiagonal();
  c.acc.B = Vec3(10, 20, 30);
  const ForwardCalibration f = ImuTkToForward(c, {});
  const ImuTkCost cost = ImuTkAccelCost(f.accel_matrix, f.accel_bias, {Vec3(12, 24, 35)}, 1.7);
  const double r = 1.7 - std::sqrt(2.961);
  EXPECT_NEAR(r, -0.0207556480, 1e-9);
  EXPECT_NEAR(cost.cost, 2.153984612e-4, 1e-13);
  EXPECT_NEAR(cost.rms_m_s2, std::abs(r), 1e-12);
  EXPECT_EQ(cost.terms, 1);
}

// F = [[2, 0.1, 0], [0, 4, 0], [0, 0, 5]], b = (1, 2, 3), g = 9.8; outputs made from specific
// forces of norm 9.8, 10 and 9.9: residuals 0, -0.2, -0.1.
TEST(ImuTkCost, SumsHalfTheWeightedSquares) {
  Mat3 F;
  F << 2, 0.1, 0, 0, 4, 0, 0, 0, 5;
  const Vec3 b(1, 2, 3);
  const std::vector<Vec3> y = {F * Vec3(9.8, 0, 0) + b, F * Vec3(0, 0, -10) + b,
                               F * Vec3(0, 9.9, 0) + b};
  const ImuTkCost plain = ImuTkAccelCost(F, b, y, 9.8);
  EXPECT_NEAR(plain.cost, 0.5 * (0.04 + 0.01), 1e-12);
  EXPECT_NEAR(plain.rms_m_s2, std::sqrt(0.05 / 3), 1e-12);
  EXPECT_NEAR(plain.max_abs_m_s2, 0.2, 1e-12);
  const ImuTkCost weighted = ImuTkAccelCost(F, b, y, 9.8, {1, 2, 3});
  EXPECT_NEAR(weighted.cost, 0.5 * (2 * 0.04 + 3 * 0.01), 1e-12);
  EXPECT_DOUBLE_EQ(weighted.weight, 6.0);
  EXPECT_THROW(ImuTkAccelCost(F, b, y, 9.8, {1, 2}), Error);
  EXPECT_THROW(ImuTkAccelCost(Mat3::Zero(), b, y, 9.8), Error);
}

// F = 2 I, b = 0, g = 9.8, noise (0.2, 0.4, 0.6) output units = (0.1, 0.2, 0.3) m/s^2.
// Segment 1: f = (0, 0, 9.8): r = 0, s^2 = 0.3^2 -> 100 * 0.09.
// Segment 2: 50 samples, not more than 100: left out, as imu_tk does.
// Segment 3: f = (10, 0, 0): r = -0.2, s^2 = 0.1^2 -> 100 * (0.04 + 0.01).
// Expected cost 0.5 * (9 + 5) = 7 over 200 residuals.
TEST(ImuTkCost, SampleEstimateAddsTheNoiseOfOneSample) {
  const Mat3 F = 2.0 * Mat3::Identity();
  const std::vector<StillMean> segments = {
      {Vec3(0, 0, 19.6), 500}, {Vec3(0, 19.6, 0), 50}, {Vec3(20, 0, 0), 101}};
  const ImuTkCost c =
      ImuTkSampleCostEstimate(F, Vec3::Zero(), segments, Vec3(0.2, 0.4, 0.6), 9.8);
  EXPECT_NEAR(c.cost, 7.0, 1e-12);
  EXPECT_EQ(c.terms, 2);
  EXPECT_DOUBLE_EQ(c.weight, 200.0);
  EXPECT_NEAR(c.max_abs_m_s2, 0.2, 1e-12);
}

}  // namespace
}  // namespace plumb::peers

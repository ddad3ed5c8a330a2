// imucal's Ferraris JSON read exactly (shared data, skipped when absent) and turned into
// plumb's forward form: applying imucal's own correction to the forward model's outputs must
// give back the inputs, in imucal's frame.
#include "plumb/peers/imucal.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <random>

#include "plumb/core/error.h"
#include "temp_files.h"

namespace plumb::peers {
namespace {

using testing::ErrorOf;
using testing::TempFolder;

constexpr double kDeg = 3.14159265358979323846 / 180.0;
const std::string kImucal =
    std::string(PLUMB_SHARED_DATA_DIR) + "/ferraris/imucal/example_ferraris_session_cal_102.4Hz.json";

TEST(Imucal, ReadsTheSharedFileExactly) {
  if (!std::filesystem::exists(kImucal)) GTEST_SKIP() << "shared data absent: " << kImucal;
  const ImucalFerraris c = ReadImucalJson(kImucal);
  EXPECT_EQ(c.cal_type, "Ferraris");
  EXPECT_EQ(c.from_acc_unit, "m/s^2");
  EXPECT_EQ(c.from_gyr_unit, "deg/s");
  EXPECT_EQ(c.acc_unit, "m/s^2");
  EXPECT_EQ(c.gyr_unit, "deg/s");
  EXPECT_EQ(c.K_a.diagonal(), Vec3(0.9967458650887003, 1.0024376185894108, 1.0233953475452096));
  EXPECT_EQ(c.K_a(0, 1), 0.0);
  EXPECT_EQ(c.R_a.row(0).transpose(),
            Vec3(0.9998620291746435, -0.014830571004926794, -0.007481763056406514));
  EXPECT_EQ(c.b_a, Vec3(0.5371174244458201, -0.6162029930860964, 0.3988673423902682));
  EXPECT_EQ(c.K_g.diagonal(), Vec3(1.0279243264288036, 0.9824277738468916, 0.9983104874451514));
  EXPECT_EQ(c.R_g(2, 0), 0.009714004498496572);
  EXPECT_EQ(c.K_ga.row(1).transpose(),
            Vec3(0.0004320123104123373, 0.0004871099695542217, 0.0006178601683550832));
  EXPECT_EQ(c.b_g, Vec3(-0.5996686296674446, -0.36984313466306884, 0.0587739354671091));
}

/// imucal's correction (ferraris_calibration_info.py): acc_cal = R_a^-1 K_a^-1 (acc - b_a),
/// gyr_cal = R_g^-1 K_g^-1 (gyr - K_ga acc_cal - b_g), in its own units.
void ImucalCorrect(const ImucalFerraris& c, const Vec3& acc, const Vec3& gyr_deg_s, Vec3& acc_cal,
                   Vec3& gyr_cal_deg_s) {
  acc_cal = c.R_a.inverse() * c.K_a.inverse() * (acc - c.b_a);
  gyr_cal_deg_s = c.R_g.inverse() * c.K_g.inverse() * (gyr_deg_s - c.K_ga * acc_cal - c.b_g);
}

TEST(Imucal, ForwardFormIsUndoneByImucalsCorrection) {
  if (!std::filesystem::exists(kImucal)) GTEST_SKIP() << "shared data absent: " << kImucal;
  const ImucalFerraris c = ReadImucalJson(kImucal);
  const ForwardCalibration f = ImucalToForward(c, kImucal);
  EXPECT_EQ(f.accel_matrix(1, 0), 0.0);
  EXPECT_EQ(f.accel_matrix(2, 0), 0.0);
  EXPECT_EQ(f.accel_matrix(2, 1), 0.0);
  EXPECT_GT(f.accel_matrix.diagonal().minCoeff(), 0.0);
  EXPECT_NEAR(f.R_peer_b.determinant(), 1.0, 1e-12);
  EXPECT_LT((f.R_peer_b.transpose() * f.R_peer_b - Mat3::Identity()).norm(), 1e-12);
  std::mt19937_64 rng(20240611);
  std::normal_distribution<double> normal(0.0, 5.0);
  for (int trial = 0; trial < 5; ++trial) {
    const Vec3 f_b(normal(rng), normal(rng), normal(rng));       // m/s^2
    const Vec3 omega_b(normal(rng), normal(rng), normal(rng));   // rad/s
    const Vec3 y_a = f.accel_matrix * f_b + f.accel_bias;        // m/s^2 (imucal's from unit)
    const Vec3 y_g = f.gyro_matrix * omega_b + f.g_sensitivity * f_b + f.gyro_bias;  // rad/s
    Vec3 acc_cal, gyr_cal_deg_s;
    ImucalCorrect(c, y_a, y_g / kDeg, acc_cal, gyr_cal_deg_s);
    EXPECT_LT((acc_cal - f.R_peer_b * f_b).norm(), 1e-12 * f_b.norm() + 1e-12);
    EXPECT_LT((gyr_cal_deg_s * kDeg - f.R_peer_b * omega_b).norm(), 1e-10 * omega_b.norm());
  }
}

TEST(Imucal, UnknownOutputUnitIsKeptWithANote) {
  ImucalFerraris c;
  c.cal_type = "Ferraris";
  c.acc_unit = "m/s^2";
  c.gyr_unit = "deg/s";
  c.from_acc_unit = "a.u.";
  c.from_gyr_unit = "a.u.";
  c.K_a = Vec3(200, 210, 220).asDiagonal();
  c.K_g = Vec3(16, 17, 18).asDiagonal();
  c.b_g = Vec3(1, 2, 3);
  const ForwardCalibration f = ImucalToForward(c, "x.json");
  // a.u. per (m/s^2) and a.u. per (deg/s) -> a.u. per (rad/s): 16 / (pi/180).
  EXPECT_NEAR(f.accel_matrix(0, 0), 200.0, 1e-12);
  EXPECT_NEAR(f.gyro_matrix(0, 0), 16.0 / kDeg, 1e-9);
  EXPECT_EQ(f.gyro_bias, Vec3(1, 2, 3));
  ASSERT_FALSE(f.notes.empty());
  EXPECT_EQ(f.notes.front().code, "unit_kept");
  EXPECT_NE(f.notes.front().message.find("'a.u.'"), std::string::npos) << f.notes.front().message;
}

TEST(Imucal, ReflectedAccelerometerIsRefused) {
  Mat3 R;
  EXPECT_THROW(UpperTriangularFrame(Vec3(1, 1, -1).asDiagonal(), R), Error);
  EXPECT_THROW(UpperTriangularFrame(Mat3::Zero(), R), Error);
}

TEST(Imucal, BadFilesNameTheFileAndTheKey) {
  const TempFolder dir;
  const std::string broken = dir.Write("broken.json", "{\"cal_type\": \"Ferraris\", ");
  std::string message = ErrorOf([&] { ReadImucalJson(broken); });
  EXPECT_NE(message.find(broken + ":line 1, column 26: not valid JSON"), std::string::npos)
      << message;

  const std::string no_kg = dir.Write(
      "no_kg.json",
      R"({"cal_type": "Ferraris", "K_a": [[1,0,0],[0,1,0],[0,0,1]], "R_a": [[1,0,0],[0,1,0],[0,0,1]],
          "b_a": [0,0,0]})");
  message = ErrorOf([&] { ReadImucalJson(no_kg); });
  EXPECT_NE(message.find(no_kg + ":key 'K_g'"), std::string::npos) << message;

  const std::string short_row = dir.Write(
      "row.json", R"({"cal_type": "Ferraris", "K_a": [[1,0,0],[0,1],[0,0,1]]})");
  message = ErrorOf([&] { ReadImucalJson(short_row); });
  EXPECT_NE(message.find(short_row + ":key 'K_a[1]'"), std::string::npos) << message;

  const std::string other = dir.Write("other.json", R"({"cal_type": "Mystery"})");
  message = ErrorOf([&] { ReadImucalJson(other); });
  EXPECT_NE(message.find("key 'cal_type'"), std::string::npos) << message;
}

}  // namespace
}  // namespace plumb::peers

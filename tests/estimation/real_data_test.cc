// The backend on real sessions (skipped when ../shared/data is absent): it converges, and on
// imu_tk's own data its accelerometer and gyroscope agree with imu_tk's printed answer.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "plumb/estimation/calibrator.h"
#include "plumb/io/text/text_table.h"
#include "plumb/segmentation/still_detector.h"
#include "plumb/report/calibration_text.h"

namespace plumb::estimation {
namespace {

const std::string kShared = PLUMB_SHARED_DATA_DIR;

bool Exists(const std::string& p) { return std::filesystem::exists(p); }

/// imu_tk's demo data: two `t x y z` files in raw counts, 100 Hz, 50 s initial still period.
Session ReadImuTk() {
  io::TextTableOptions o;
  o.time = 0;
  o.acc.axes = {1, 2, 3};
  o.gyr.axes = {1, 2, 3};
  return io::ReadSplitTables(kShared + "/multipose/imu_tk/xsens_acc.mat",
                             kShared + "/multipose/imu_tk/xsens_gyro.mat", o);
}

CalibrationResult CalibrateImuTk() {
  const Session s = ReadImuTk();
  segmentation::StillDetectorOptions d;
  d.init_still_s = 50.0;
  const auto seg = segmentation::DetectStillSegments(s.series, d);
  model::Model m = model::Model::Parse("base");
  m.t_ref_s = s.series.t_s.front();
  return Calibrate(s.series, seg.segments, m, geo::Site::Unknown(9.81744));
}

TEST(RealData, ImuTkMatchesImuTksAnswer) {
  if (!Exists(kShared + "/multipose/imu_tk/xsens_acc.mat")) GTEST_SKIP() << "shared data absent";
  const CalibrationResult r = CalibrateImuTk();
  if (std::getenv("PLUMB_PRINT")) std::cout << report::FullReport(r);
  EXPECT_TRUE(r.fit.converged) << r.fit.solver_report;
  // imu_tk's answer (full_precision_params.txt): calibrated = T K (raw - B), so the forward
  // matrix is (T K)^-1 in counts per m/s^2 and the bias is B.
  Mat3 T_a, K_a, T_g, K_g;
  T_a << 1, -0.003359299033234669, -0.0089063947432312159, 0, 1, -0.02133411938518472, 0, 0, 1;
  K_a = Vec3(0.0024127846281317392, 0.0024271227955775117, 0.002411680275513924).asDiagonal();
  const Vec3 B_a(33124.182564561655, 33275.179434180718, 32364.415649443108);
  T_g << 1, 0.0059363404568289245, 0.0011110094938067108, 0.0080881184058236855, 1,
      -0.053556861838479131, 0.025306721418430801, -0.0025513028663729669, 1;
  K_g = Vec3(0.00020929452594210579, 0.00020989853973601207, 0.00020948298421848358).asDiagonal();
  const Vec3 B_g(32777.13994402239, 32459.802878848459, 32511.847461015594);
  const Mat3 F_tk = (T_a * K_a).inverse();
  const Mat3 E_tk = (T_g * K_g).inverse();
  if (std::getenv("PLUMB_PRINT")) {
    std::cout << "F plumb\n" << r.calibration.AccelMatrix() << "\nF imu_tk\n" << F_tk << "\nb plumb "
              << r.calibration.AccelBias().transpose() << "\nb imu_tk " << B_a.transpose() << "\nE plumb\n"
              << r.calibration.GyroMatrix() << "\nE imu_tk\n" << E_tk << "\nbg plumb " << r.calibration.GyroBias().transpose()
              << "\nbg imu_tk " << B_g.transpose() << "\n";
  }
  EXPECT_LT((r.calibration.AccelMatrix() - F_tk).norm() / F_tk.norm(), 2e-3);
  EXPECT_LT((r.calibration.AccelBias() - B_a).norm(), 10.0);  // counts, of ~33000
  EXPECT_LT((r.calibration.GyroMatrix() - E_tk).norm() / E_tk.norm(), 2e-2);
  EXPECT_LT((r.calibration.GyroBias() - B_g).norm(), 10.0);
}

}  // namespace
}  // namespace plumb::estimation

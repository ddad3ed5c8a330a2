// Every IMU table under ../shared/data/multipose and the imucal Ferraris session, read as it is.
// Sample counts and the first and last samples were read off the files with head and tail.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "plumb/io/text/text_table.h"

namespace plumb::io {
namespace {

constexpr double kG = 9.80665;
constexpr double kDegToRad = M_PI / 180.0;

std::string SharedFile(const std::string& relative) {
  return std::string(PLUMB_SHARED_DATA_DIR) + "/" + relative;
}

#define SKIP_IF_ABSENT(path) \
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << (path)

// A sample as written in the file, before conversion (file units).
struct Row {
  double t_s;
  double acc[3];
  double gyr[3];
};

// Checks sample `i` against `row` converted with the acc and gyr scales.
void ExpectSample(const ImuSeries& s, std::size_t i, const Row& row, double acc_scale,
                  double gyr_scale) {
  EXPECT_DOUBLE_EQ(s.t_s[i], row.t_s) << "sample " << i;
  for (int k = 0; k < 3; ++k) {
    EXPECT_FLOAT_EQ(s.acc[i][k], static_cast<float>(row.acc[k] * acc_scale)) << "sample " << i;
    EXPECT_FLOAT_EQ(s.gyr[i][k], static_cast<float>(row.gyr[k] * gyr_scale)) << "sample " << i;
  }
}

void ExpectRate(const ImuSeries& s, double rate_hz, double tolerance_hz) {
  EXPECT_NEAR(1.0 / s.median_dt_s(), rate_hz, tolerance_hz);
}

// --- mikoff/imu-calib: `ax ay az wx wy wz`, SI, no time, 100 Hz ----------------------------

TextTableOptions MikoffOptions() {
  TextTableOptions o;
  o.acc.axes = {0, 1, 2};
  o.gyr.axes = {3, 4, 5};
  o.rate_hz = 100.0;
  return o;
}

void CheckMikoff(const std::string& name, std::size_t rows, const Row& first, const Row& last) {
  const std::string path = SharedFile("multipose/mikoff/" + name);
  SKIP_IF_ABSENT(path);
  const Session s = ReadTextTable(path, MikoffOptions());
  ASSERT_EQ(s.series.size(), rows);
  ExpectSample(s.series, 0, first, 1.0, 1.0);
  ExpectSample(s.series, rows - 1, last, 1.0, 1.0);
  ExpectRate(s.series, 100.0, 1e-9);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(SharedData, MikoffImu0) {
  CheckMikoff("imu0.log", 15969, {0.0, {-8.42090, 0.06710, 5.24511}, {0.03515, 0.00213, 0.04155}},
              {159.68, {8.57894, 0.31137, -4.62718}, {0.01917, -0.00639, 0.02237}});
}

TEST(SharedData, MikoffImu1) {
  CheckMikoff("imu1.log", 15931, {0.0, {8.63162, 0.12459, 5.28818}, {-0.01065, 0.00213, -0.00533}},
              {159.30, {-8.40648, 0.10536, -4.79964}, {-0.01172, 0.02024, 0.00639}});
}

TEST(SharedData, MikoffImu2) {
  CheckMikoff("imu2.log", 15934, {0.0, {-8.45916, 0.11017, 4.89068}, {0.00639, -0.01598, 0.00213}},
              {159.33, {8.60288, -0.19159, -4.97681}, {0.00959, -0.00533, 0.02344}});
}

// --- imu_tk: two ASCII files `t x y z`, raw counts, shared timestamps ----------------------

TEST(SharedData, ImuTkXsensPair) {
  const std::string acc = SharedFile("multipose/imu_tk/xsens_acc.mat");
  const std::string gyr = SharedFile("multipose/imu_tk/xsens_gyro.mat");
  SKIP_IF_ABSENT(acc);
  SKIP_IF_ABSENT(gyr);
  TextTableOptions o;
  o.time = 0;
  o.acc.axes = {1, 2, 3};
  o.gyr.axes = {1, 2, 3};
  const Session s = ReadSplitTables(acc, gyr, o);
  ASSERT_EQ(s.series.size(), 51175u);
  ExpectSample(s.series, 0, {0.02984, {33108, 33329, 36429}, {32786, 32429, 32499}}, 1.0, 1.0);
  ExpectSample(s.series, 51174, {511.718, {35290, 35137, 27631}, {48789, 17563, 13676}}, 1.0, 1.0);
  ExpectRate(s.series, 100.0, 1e-6);
}

// --- tomisuarez2/ImuCalibration: 4 preamble lines, header, MPU-6050 int16, 100 Hz ----------

constexpr double kMpuAccScale = kG / 16384.0;       // +-2 g
constexpr double kMpuGyrScale = kDegToRad / 131.0;  // +-250 deg/s

TextTableOptions TomisuarezOptions() {
  TextTableOptions o;
  o.skip_lines = 4;
  o.header_row = true;
  o.rate_hz = 100.0;
  o.acc.axes = {"ax", "ay", "az"};
  o.acc.SetScale(kMpuAccScale);
  o.gyr.axes = {"gx", "gy", "gz"};
  o.gyr.SetScale(kMpuGyrScale);
  return o;
}

void CheckTomisuarez(const std::string& name, std::size_t rows, const Row& first, const Row& last) {
  const std::string path = SharedFile("multipose/tomisuarez2/" + name);
  SKIP_IF_ABSENT(path);
  const Session s = ReadTextTable(path, TomisuarezOptions());
  ASSERT_EQ(s.series.size(), rows);
  ExpectSample(s.series, 0, first, kMpuAccScale, kMpuGyrScale);
  ExpectSample(s.series, rows - 1, last, kMpuAccScale, kMpuGyrScale);
  ExpectRate(s.series, 100.0, 1e-9);
}

TEST(SharedData, TomisuarezCalibration) {
  CheckTomisuarez("example_data_calibration.csv", 10245,
                  {0.0, {-12, -812, 15032}, {-447, 156, -86}},
                  {102.44, {8636, -268, 12792}, {-413, 144, -81}});
}

TEST(SharedData, TomisuarezTinitCalc) {
  CheckTomisuarez("example_data_tinit_calc.csv", 44930,
                  {0.0, {2508, -604, 14684}, {-429, 140, -53}},
                  {449.29, {2632, -700, 14800}, {-444, 145, -57}});
}

TEST(SharedData, TomisuarezNinetyDegreesAboutX) {
  CheckTomisuarez("imu_90_x_rot.csv", 9987, {0.0, {1116, 24, 14720}, {-449, 166, -68}},
                  {99.86, {968, 16028, -2912}, {-410, 142, -71}});
}

TEST(SharedData, TomisuarezStatic) {
  CheckTomisuarez("imu_static_test.csv", 9986, {0.0, {748, 244, 15708}, {-480, 193, -83}},
                  {99.85, {912, 200, 14972}, {-435, 135, -54}});
}

// --- ChanghyeonKim93: `# time tx ty tz wx wy wz mx my mz qx qy qz qw`, unix s, SI ----------

TextTableOptions ChanghyeonOptions() {
  TextTableOptions o;
  o.time = "time";
  o.acc.axes = {"tx", "ty", "tz"};
  o.gyr.axes = {"wx", "wy", "wz"};
  return o;
}

void CheckChanghyeon(const std::string& name, std::size_t rows, const Row& first, const Row& last) {
  const std::string path = SharedFile("multipose/changhyeonkim93/" + name);
  SKIP_IF_ABSENT(path);
  const Session s = ReadTextTable(path, ChanghyeonOptions());
  ASSERT_EQ(s.series.size(), rows);
  ExpectSample(s.series, 0, first, 1.0, 1.0);
  ExpectSample(s.series, rows - 1, last, 1.0, 1.0);
  ExpectRate(s.series, 97.6, 0.1);
}

TEST(SharedData, ChanghyeonGood1) {
  CheckChanghyeon("imu_good1.txt", 6566,
                  {1535630275.916451,
                   {0.06808426231146, -0.04261315613985, -9.42799282074},
                   {-0.001047738362104, -0.006350576877594, 0.01049410644919}},
                  {1535630341.567068,
                   {0.8609566688538, -9.408056259155, -2.181256532669},
                   {-0.003354305168614, -0.006455753929913, 0.009262233041227}});
}

TEST(SharedData, ChanghyeonGood2) {
  CheckChanghyeon("imu_good2.txt", 11382,
                  {1535632344.472815,
                   {-0.03511846065521, 0.05098870396614, 10.19027233124},
                   {-0.000416884344304, -0.003840630408376, 0.009536409750581}},
                  {1535632458.283953,
                   {-0.03261598199606, -0.08816360682249, -9.463109970093},
                   {0.0002668183005881, -0.01309845224023, 0.009693185798824}});
}

// --- imucal Ferraris session: `n_samples,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z`, 102.4 Hz -----

TEST(SharedData, ImucalFerrarisSession) {
  const std::string path = SharedFile("ferraris/imucal/example_ferraris_session.csv");
  SKIP_IF_ABSENT(path);
  TextTableOptions o;
  o.header_row = true;
  o.time = "n_samples";
  o.time_unit_s = 1.0 / 102.4;
  o.acc.axes = {"acc_x", "acc_y", "acc_z"};
  o.gyr.axes = {"gyr_x", "gyr_y", "gyr_z"};
  o.gyr.SetScale(kDegToRad);
  const Session s = ReadTextTable(path, o);
  ASSERT_EQ(s.series.size(), 10376u);
  ExpectSample(s.series, 0,
               {0.0,
                {10.332114257812501, -0.5795947265625, 0.51732421875},
                {-0.6103515625, -0.30517578125, 0.06103515625}},
               1.0, kDegToRad);
  ExpectSample(s.series, 10375,
               {10375 / 102.4,
                {0.45984375, -0.5700146484375, 10.432705078125},
                {-0.54931640625, -0.30517578125, 0.18310546875}},
               1.0, kDegToRad);
  ExpectRate(s.series, 102.4, 1e-9);
}

}  // namespace
}  // namespace plumb::io

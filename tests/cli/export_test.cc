// `plumb calibrate --export FORMAT=FILE`: the files written from the bundled real session,
// read back and checked against the calibration JSON, and the usage errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using nlohmann::json;
using testing::Contains;
using testing::Plumb;
using testing::ReadJson;
using testing::TempDir;
using testing::ToolRun;

/// NAME,VALUE lines of a .param file (comments skipped).
std::map<std::string, double> ReadParam(const std::string& path) {
  std::map<std::string, double> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto comma = line.find(',');
    out[line.substr(0, comma)] = std::stod(line.substr(comma + 1));
  }
  return out;
}

std::string Mikoff() { return std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log"; }

TEST(ExportCli, ArdupilotFileFromTheBundledSessionHoldsTheCalibration) {
  if (!std::filesystem::exists(Mikoff())) GTEST_SKIP() << "bundled data absent: " << Mikoff();
  TempDir dir;
  const std::string param = dir.File("imu.param"), doc_path = dir.File("cal.json");
  const std::string yaml = dir.File("imu.yaml");
  const ToolRun run = Plumb({"calibrate", Mikoff(), "--columns", "ax,ay,az,gx,gy,gz", "--rate",
                             "100", "--export", "ardupilot=" + param, "--export",
                             "kalibr=" + yaml, "--export-imu", "1", "--json", doc_path},
                            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "wrote " + param)) << run.out;
  EXPECT_TRUE(Contains(run.out, "ardupilot: firmware correction minus plumb's")) << run.out;
  const json doc = ReadJson(doc_path);
  const auto p = ReadParam(param);
  // Instance 1: INS_ACC2*, INS_GYR2OFFS; offsets are plumb's biases, scales 1 / diag(F).
  const char* axes[3] = {"X", "Y", "Z"};
  for (int i = 0; i < 3; ++i) {
    const std::string a = axes[i];
    ASSERT_EQ(p.count("INS_ACC2OFFS_" + a), 1u) << a;
    EXPECT_NEAR(p.at("INS_ACC2OFFS_" + a), doc["accel"]["bias"][i].get<double>(), 1e-7);
    EXPECT_NEAR(p.at("INS_ACC2SCAL_" + a), 1.0 / doc["accel"]["matrix"][i][i].get<double>(),
                1e-7);
    EXPECT_NEAR(p.at("INS_GYR2OFFS_" + a), doc["gyro"]["bias"][i].get<double>(), 1e-9);
  }
  EXPECT_EQ(p.count("INS_ACCOFFS_X"), 0u);
  EXPECT_EQ(p.count("INS_TCAL2_ENABLE"), 0u);  // no temperature term in the base model
  // The report in the JSON: finite errors on every still segment.
  const json& e = doc["export"]["ardupilot"];
  EXPECT_EQ(e["file"], param);
  EXPECT_EQ(e["imu"], 1);
  EXPECT_EQ(e["accel_still"]["segments"].get<int>(), doc["fit"]["segments"]["still"].get<int>());
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(std::isfinite(e["accel_still"]["rms"][i].get<double>()));
    EXPECT_GE(e["accel_still"]["max_abs"][i].get<double>(),
              e["accel_still"]["rms"][i].get<double>());
  }
  const json& k = doc["export"]["kalibr"];
  EXPECT_NEAR(k["update_rate"].get<double>(), 100.0, 1e-6);
  EXPECT_GT(k["accelerometer_noise_density"].get<double>(), 0.0);
  EXPECT_TRUE(Contains(testing::ReadAll(yaml), "gyroscope_noise_density: ")) << testing::ReadAll(yaml);
}

TEST(ExportCli, BadFormatIsAUsageError) {
  TempDir dir;
  const ToolRun run = Plumb({"calibrate", "x.csv", "--export", "betaflight=x.txt"}, dir);
  EXPECT_EQ(run.exit_code, 2) << run.out << run.err;
  EXPECT_TRUE(Contains(run.err, "unknown format 'betaflight'")) << run.err;
  const ToolRun no_file = Plumb({"calibrate", "x.csv", "--export", "px4"}, dir);
  EXPECT_EQ(no_file.exit_code, 2) << no_file.err;
  EXPECT_TRUE(Contains(no_file.err, "FORMAT=FILE")) << no_file.err;
}

TEST(ExportCli, CountsAreRefusedBeforeCalibrating) {
  TempDir dir;
  // A table in raw counts (--acc-unit counts is not SI): firmware parameters make no sense.
  std::string rows;
  for (int i = 0; i < 50; ++i) rows += std::to_string(i * 0.01) + ",0,0,-16384,0,0,0\n";
  const std::string table = dir.Write("counts.csv", rows);
  const ToolRun run = Plumb({"calibrate", table, "--columns", "t,ax,ay,az,gx,gy,gz",
                             "--acc-unit", "counts", "--gyr-unit", "counts", "--export",
                             "ardupilot=" + dir.File("x.param")},
                            dir);
  EXPECT_EQ(run.exit_code, 1) << run.out << run.err;
  EXPECT_TRUE(Contains(run.err, "not m/s^2 and rad/s")) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir.File("x.param")));
}

TEST(ExportCli, ArdupilotLogAsLoggedIsRefusedForFirmwareFormats) {
  const std::string log =
      std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/plane408_centre_point.BIN";
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const std::string param = dir.File("ap.param");
  const ToolRun refused = Plumb({"calibrate", log, "--as-logged", "--export", "px4=" + param}, dir);
  EXPECT_EQ(refused.exit_code, 2) << refused.out << refused.err;
  EXPECT_TRUE(Contains(refused.err, "--as-logged")) << refused.err;
  // Without it: one still pose does not determine the offsets and scales: refused, naming
  // them, and nothing written.
  const ToolRun one_pose = Plumb({"calibrate", log, "--imu", "1", "--export",
                                  "ardupilot=" + param},
                                 dir);
  EXPECT_EQ(one_pose.exit_code, 1) << one_pose.out;
  EXPECT_TRUE(Contains(one_pose.err, "does not determine accel.matrix.xx")) << one_pose.err;
  EXPECT_FALSE(std::filesystem::exists(param));
  // Asked to anyway: the log's second IMU, named after its instance by default.
  const ToolRun run = Plumb({"calibrate", log, "--imu", "1", "--export", "ardupilot=" + param,
                             "--export-undetermined"},
                            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto p = ReadParam(param);
  EXPECT_EQ(p.count("INS_ACC2OFFS_Z"), 1u);
  EXPECT_EQ(p.count("INS_GYR2OFFS_Z"), 1u);
  // One pose: the report says the values are not all determined.
  EXPECT_TRUE(Contains(run.out, "not determined by this session")) << run.out;
}

}  // namespace
}  // namespace plumb::cli

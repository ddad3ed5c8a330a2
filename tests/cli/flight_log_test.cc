// Flight logs from the command line, as a user meets them (issue 5): `plumb info` on each
// format, `plumb calibrate` on a still PX4 log and on a MAVLink stream chosen by name, the
// firmware's correction undone and said, and clear errors for a stream that is not there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using nlohmann::json;
using testing::Contains;
using testing::Plumb;
using testing::ReadJson;
using testing::TempDir;
using testing::ToolRun;

std::string Shared(const std::string& relative) {
  return std::string(PLUMB_SHARED_DATA_DIR) + "/" + relative;
}

/// `plumb info LOG --json F`: exit 0, the format named, the JSON keys issue 5 asks for.
json InfoOf(const std::string& log, const std::string& format, TempDir& dir) {
  const std::string out = dir.File("info.json");
  const ToolRun run = Plumb({"info", log, "--json", out}, dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "(" + format + ")")) << run.out;
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["format"], format);
  for (const char* key : {"imus", "site", "params", "warnings", "messages"}) {
    EXPECT_TRUE(doc.contains(key)) << key;
  }
  for (const auto& imu : doc["imus"]) {
    for (const char* key : {"name", "instance", "samples", "rate_hz", "t_start_s", "t_end_s",
                            "applied", "undoable"}) {
      EXPECT_TRUE(imu.contains(key)) << key;
    }
  }
  return doc;
}

/// The determined combination of the JSON naming every one of `names`, or null.
json Determined(const json& doc, std::initializer_list<const char*> names) {
  for (const auto& c : doc["observability"]["determined"]) {
    const std::string text = c["combination"].get<std::string>();
    bool all = true;
    for (const char* n : names) all = all && text.find(n) != std::string::npos;
    if (all) return c;
  }
  return nullptr;
}

TEST(FlightLogCli, InfoOnAMavlinkTlog) {
  const std::string log = Shared("mavlink/plane385_disarmed.tlog");
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const json doc = InfoOf(log, "mavlink-tlog", dir);
  ASSERT_EQ(doc["imus"].size(), 3u);
  EXPECT_EQ(doc["imus"][1]["name"], "SCALED_IMU2");
  EXPECT_NEAR(doc["imus"][1]["rate_hz"].get<double>(), 3.49, 0.05);
  EXPECT_TRUE(doc["site"].is_null());  // the GPS never had a fix in this log
  EXPECT_TRUE(doc["params"].contains("INS_ACC2OFFS_Z"));
  // Still periods in two tilts (data README: 22 s + 7 s + 35 s).
  EXPECT_GE(doc["imus"][1]["still"].size(), 2u);
}

TEST(FlightLogCli, InfoOnAPx4ULog) {
  const std::string log = Shared("px4/sample.ulg");
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const json doc = InfoOf(log, "px4-ulog", dir);
  ASSERT_GE(doc["imus"].size(), 1u);
  EXPECT_EQ(doc["imus"][0]["name"], "sensor_combined");
  EXPECT_NEAR(doc["imus"][0]["rate_hz"].get<double>(), 248.0, 2.0);
  EXPECT_TRUE(doc["imus"][0]["undoable"].get<bool>());
  EXPECT_TRUE(doc["params"].contains("CAL_ACC0_XOFF"));
}

TEST(FlightLogCli, InfoOnAnArdupilotTextLog) {
  const std::string log = Shared("ardupilot/copter311_nan.log");
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const json doc = InfoOf(log, "ardupilot-text", dir);
  ASSERT_EQ(doc["imus"].size(), 2u);
  EXPECT_EQ(doc["imus"][0]["samples"], 705);
  EXPECT_NEAR(doc["site"]["lat_deg"].get<double>(), 14.11, 0.01);
}

TEST(FlightLogCli, CalibratesTheStillMinuteOfAPx4Log) {
  // pyulog's sample.ulg: handled 2-6 s after the start, then 62 s still. The detector keeps
  // the still minute as one pose (the short run before the knock is too short) and plumb says
  // what one pose determines, with sigma, and what it cannot.
  const std::string log = Shared("px4/sample.ulg");
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const std::string out = dir.File("ulg.json");
  const ToolRun run = Plumb({"calibrate", log, "--json", out}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "still segments: 1 detected")) << run.out;
  EXPECT_TRUE(Contains(run.err, "CAL_ACC0_*OFF")) << run.err;  // the undo's warning, with values
  const json doc = ReadJson(out);
  const json z = Determined(doc, {"accel.bias.z", "accel.matrix.zz"});
  ASSERT_FALSE(z.is_null()) << doc["observability"].dump(2);
  EXPECT_GT(z["sigma"].get<double>(), 0.0);
  EXPECT_LT(z["sigma"].get<double>(), 1e-2);
  EXPECT_GE(doc["observability"]["unobservable"].size(), 10u);
  EXPECT_EQ(doc["site"]["source"], "none");
}

TEST(FlightLogCli, CalibratesAMavlinkStreamChosenByName) {
  const std::string log = Shared("mavlink/plane385_disarmed.tlog");
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const std::string out = dir.File("tlog.json");
  const ToolRun run = Plumb({"calibrate", log, "--stream", "SCALED_IMU2", "--imu", "1",
                             "--min-still", "5", "--json", out},
                            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  EXPECT_TRUE(Contains(run.out, "SCALED_IMU2")) << run.out;
  EXPECT_TRUE(Contains(run.err, "INS_ACC2OFFS")) << run.err;  // the undo's warning
  const json doc = ReadJson(out);
  EXPECT_GE(doc["fit"]["segments"]["still"].get<int>(), 2);
}

TEST(FlightLogCli, AStreamThatIsNotThereIsAnErrorNamingTheLog) {
  const std::string log = Shared("px4/sample.ulg");
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const ToolRun run = Plumb({"calibrate", log, "--stream", "RAW_IMU"}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(Contains(run.err, log)) << run.err;
  EXPECT_TRUE(Contains(run.err, "RAW_IMU")) << run.err;
}

TEST(FlightLogCli, AnArdupilotLogWithoutImuRowsSaysSo) {
  const std::string log = Shared("ardupilot/copter31_no_imu_rows.log");
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const ToolRun run = Plumb({"calibrate", log}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(Contains(run.err, "no IMU rows")) << run.err;
}

/// A copy of `log` in `dir` whose PARM AHRS_ORIENTATION (name field of 16 characters, then
/// the float value) reads `value`.
std::string WithOrientation(const std::string& log, float value, TempDir& dir) {
  std::ifstream in(log, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  const std::string name = "AHRS_ORIENTATION";
  const auto it = std::search(bytes.begin(), bytes.end(), name.begin(), name.end());
  EXPECT_NE(it, bytes.end());
  if (it != bytes.end()) std::memcpy(&*(it + 16), &value, sizeof value);
  const std::string out = dir.File("custom_orientation.bin");
  std::ofstream(out, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return out;
}

TEST(FlightLogCli, NoFirmwareExportFromSamplesStillCarryingTheFirmwaresCorrection) {
  // A custom board orientation (101) cannot be undone: the samples keep ArduPilot's whole
  // correction, so parameters fitted to them would replace it: refused before calibrating.
  const std::string log = Shared("ardupilot/plane408_centre_point.BIN");
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const std::string custom = WithOrientation(log, 101.0f, dir);
  const std::string param = dir.File("out.param");
  const ToolRun run = Plumb({"calibrate", custom, "--export", "ardupilot=" + param,
                             "--export-undetermined"},
                            dir);
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_TRUE(Contains(run.err, "could not undo")) << run.err;
  EXPECT_TRUE(Contains(run.err, "INS_ACCOFFS")) << run.err;
  EXPECT_FALSE(std::filesystem::exists(param));
  // Kalibr's noise model does not depend on it: allowed.
  const ToolRun kalibr = Plumb({"calibrate", custom, "--export", "kalibr=" + dir.File("imu.yaml")},
                               dir);
  EXPECT_EQ(kalibr.exit_code, 0) << kalibr.err;
}

}  // namespace
}  // namespace plumb::cli

namespace plumb::cli {
namespace {

// Issue 13 point 4: the memory a run needs is said before it fails. copter36_chibios.bin is
// 3010048 bytes, all of them the 8 MiB sample, of which the session keeps the IMU, PARM and GPS
// bodies (about 0.71 MB): 20 MiB + 3.5 * those bytes (kSplitKeptMemoryFactor) = "23.4 MB".
TEST(MaxMemory, RefusedBeforeReadingWithTheEstimate) {
  const std::string log = std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/copter36_chibios.bin";
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  testing::TempDir dir;
  for (const char* command : {"info", "calibrate"}) {
    const testing::ToolRun run = testing::Plumb({command, log, "--max-memory", "1M"}, dir);
    EXPECT_EQ(run.exit_code, 1) << command;
    EXPECT_TRUE(testing::Contains(run.err, "reading " + log + " needs about 23.4 MB; 1 MB is "
                                           "available (--max-memory)")) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;  // refused before reading: nothing printed
  }
  const testing::ToolRun info = testing::Plumb({"info", log}, dir);
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_TRUE(testing::Contains(info.out, "memory to read it: about 23.4 MB (estimate)"))
      << info.out;
  const testing::ToolRun enough = testing::Plumb({"info", log, "--max-memory", "25M"}, dir);
  EXPECT_EQ(enough.exit_code, 0) << enough.err;
  const testing::ToolRun bad = testing::Plumb({"info", log, "--max-memory", "lots"}, dir);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
}

}  // namespace
}  // namespace plumb::cli

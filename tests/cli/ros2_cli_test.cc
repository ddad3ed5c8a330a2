// ROS 2 bags from the command line: `plumb info` on MCAP and .db3 copies of a real ROS 1
// recording (tests/io/ros2_fixtures/make-fixtures writes them into the build folder with an
// independent writer) lists the same topic, count, rate and still periods as on the .bag, the
// types as ROS 2 names them; calibrate --clock receive reads the receive times. Skipped with
// the reason when the data, node, the npm packages (scripts/setup) or python3-rosbag are absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "support/ros2_fixtures.h"
#include "run_tool.h"

namespace plumb::cli {
namespace {

using nlohmann::json;
using testing::Contains;
using testing::Plumb;
using testing::ReadJson;
using testing::TempDir;
using testing::ToolRun;

const std::string& kBag = plumb::testing::Ros2FixturesSourceBag();
const std::string& kPrefix = plumb::testing::Ros2FixturesPrefix();

TEST(Ros2BagCli, InfoListsTheSameTopicCountRateAndStillPeriodsAsTheBag) {
  if (const std::string why = plumb::testing::MakeRos2Fixtures(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const ToolRun ros1 = Plumb({"info", kBag, "--json", dir.File("bag.json")}, dir);
  ASSERT_EQ(ros1.exit_code, 0) << ros1.err;
  const json reference = ReadJson(dir.File("bag.json"));
  for (const auto& [file, format] :
       std::vector<std::pair<std::string, std::string>>{{kPrefix + ".mcap", "ros2-mcap"},
                                                        {kPrefix + "_zstd.mcap", "ros2-mcap"},
                                                        {kPrefix + "_lz4.mcap", "ros2-mcap"},
                                                        {kPrefix + ".db3", "ros2-db3"}}) {
    SCOPED_TRACE(file);
    const std::string out = dir.File("info.json");
    const ToolRun run = Plumb({"info", file, "--json", out}, dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_TRUE(Contains(run.out, "(" + format + ")")) << run.out;
    EXPECT_TRUE(Contains(run.out, "topic /ardrone/imu (sensor_msgs/msg/Imu): 4308 messages"))
        << run.out;
    EXPECT_TRUE(
        Contains(run.out, "topic /ardrone/mag (sensor_msgs/msg/MagneticField): 4308 messages"))
        << run.out;
    EXPECT_TRUE(Contains(run.out, "applied by the driver: a bag does not say")) << run.out;
    const json doc = ReadJson(out);
    EXPECT_EQ(doc["format"], format);
    ASSERT_EQ(doc["imus"].size(), 1u);
    EXPECT_EQ(doc["imus"][0]["name"], "/ardrone/imu");
    EXPECT_EQ(doc["imus"][0]["samples"], reference["imus"][0]["samples"]);
    EXPECT_EQ(doc["imus"][0]["rate_hz"], reference["imus"][0]["rate_hz"]);
    EXPECT_EQ(doc["imus"][0]["t_start_s"], reference["imus"][0]["t_start_s"]);
    EXPECT_EQ(doc["imus"][0]["still"], reference["imus"][0]["still"]);
    EXPECT_EQ(doc["imus"][0]["still"].size(), 4u);
    EXPECT_EQ(doc["messages"]["/ardrone/imu (sensor_msgs/msg/Imu)"], 4308);
    EXPECT_TRUE(doc["warnings"].empty()) << doc["warnings"].dump();
  }
}

TEST(Ros2BagCli, CalibrateOnTheReceiveClock) {
  if (const std::string why = plumb::testing::MakeRos2Fixtures(); !why.empty()) GTEST_SKIP() << why;
  TempDir dir;
  const ToolRun run = Plumb({"calibrate", kPrefix + "_zstd.mcap", "--topic", "/ardrone/imu",
                             "--clock", "receive"}, dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out + run.err, "record times")) << run.out << run.err;
  const ToolRun wrong = Plumb({"calibrate", kPrefix + ".db3", "--topic", "/imu/nope"}, dir);
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_TRUE(Contains(wrong.err, "/ardrone/imu (4308 messages)")) << wrong.err;
}

}  // namespace
}  // namespace plumb::cli

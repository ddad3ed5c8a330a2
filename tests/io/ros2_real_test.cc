// ROS 2 copies of a real ROS 1 recording (../shared/data/ros/ardrone_imu.bag), written by an
// independent writer (tests/io/ros2_fixtures/make-fixtures: the messages as python3-rosbag reads
// them, MCAP by @mcap/core uncompressed, zstd and lz4, .db3 by Python's sqlite3) into the build
// folder at test time, read by plumb's MCAP and .db3 readers: the same samples, bit for bit, as
// plumb's ROS 1 reader gives of the original, on both clocks, and the same topics and counts.
// Skipped with the reason when the data, node, the npm packages (scripts/setup) or
// python3-rosbag are absent.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "support/ros2_fixtures.h"
#include "plumb/core/error.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/io/ros/db3.h"
#include "plumb/io/ros/mcap.h"
#include "plumb/io/ros/ros_session.h"
#include "plumb/io/ros/rosbag.h"

namespace plumb::io {
namespace {

const std::string& kBag = plumb::testing::Ros2FixturesSourceBag();
const std::string& kPrefix = plumb::testing::Ros2FixturesPrefix();

#define NEED_FIXTURES()                                   \
  if (const std::string why = plumb::testing::MakeRos2Fixtures(); !why.empty()) \
  GTEST_SKIP() << why

void ExpectSameTopic(const RosImuTopic& a, const RosImuTopic& b) {
  EXPECT_EQ(a.topic, b.topic);
  EXPECT_EQ(a.frame_id, b.frame_id);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  // Every double and float compared exactly (operator== of the vectors).
  EXPECT_EQ(a.samples.t_s, b.samples.t_s);
  EXPECT_EQ(a.receive_s, b.receive_s);
  EXPECT_EQ(a.samples.acc, b.samples.acc);
  EXPECT_EQ(a.samples.gyr, b.samples.gyr);
  EXPECT_EQ(a.acc_not_given, b.acc_not_given);
  EXPECT_EQ(a.gyr_not_given, b.gyr_not_given);
  EXPECT_EQ(a.orientation_not_given, b.orientation_not_given);
  EXPECT_EQ(a.orientation_zero, b.orientation_zero);
}

/// "topic (type)" counts with the ROS 2 type names turned into ROS 1's.
std::vector<std::pair<std::string, std::size_t>> Ros1Names(
    std::vector<std::pair<std::string, std::size_t>> counts) {
  for (auto& [name, count] : counts) {
    const auto at = name.find("/msg/");
    if (at != std::string::npos) name.erase(at, 4);
  }
  return counts;
}

TEST(Ros2RealData, McapAndDb3CopiesGiveTheRos1SamplesBitForBit) {
  NEED_FIXTURES();
  const RosBag ros1 = ReadRosBag(kBag);
  ASSERT_EQ(ros1.imu_topics.size(), 1u);
  ASSERT_EQ(ros1.imu_topics[0].samples.size(), 4308u);
  for (const std::string& copy : {kPrefix + ".mcap", kPrefix + "_zstd.mcap", kPrefix + "_lz4.mcap",
                                  kPrefix + ".db3"}) {
    SCOPED_TRACE(copy);
    const FlightLog log = FlightLog::Open(copy);
    const RosBag ros2 = copy.size() > 4 && copy.substr(copy.size() - 4) == ".db3" ? ReadDb3(copy)
                                                                                  : ReadMcap(copy);
    EXPECT_FALSE(ros2.warnings.any()) << ros2.warnings.Describe().front();
    ASSERT_EQ(ros2.imu_topics.size(), 1u);
    ExpectSameTopic(ros2.imu_topics[0], ros1.imu_topics[0]);
    EXPECT_EQ(ros2.messages, ros1.messages);
    EXPECT_EQ(Ros1Names(ros2.MessageCounts()), ros1.MessageCounts());
    // Through FlightLog, as every command reads it: the sessions on both clocks.
    for (const bool receive : {false, true}) {
      FlightLogSelection pick;
      pick.receive_time = receive;
      const Session a = log.Select(pick);
      const Session b = RosBagSession(ros1, pick);
      EXPECT_EQ(a.series.t_s, b.series.t_s) << receive;
      EXPECT_EQ(a.series.acc, b.series.acc) << receive;
      EXPECT_EQ(a.series.gyr, b.series.gyr) << receive;
    }
    const FlightLogSummary summary = log.Summary();
    const FlightLogSummary reference = RosBagSummary(ros1);
    ASSERT_EQ(summary.imus.size(), 1u);
    EXPECT_EQ(summary.imus[0].samples, reference.imus[0].samples);
    EXPECT_EQ(summary.imus[0].rate_hz, reference.imus[0].rate_hz);
    EXPECT_EQ(summary.imus[0].t_start_s, reference.imus[0].t_start_s);
    EXPECT_EQ(summary.imus[0].t_end_s, reference.imus[0].t_end_s);
  }
}

TEST(Ros2RealData, FormatDetailsNameTheChunksAndTopics) {
  NEED_FIXTURES();
  const std::string none = FlightLog::Open(kPrefix + ".mcap").Summary().format_detail;
  EXPECT_EQ(none.rfind("MCAP, ", 0), 0u) << none;
  EXPECT_NE(none.find("(none "), std::string::npos) << none;
  EXPECT_NE(none.find(", 2 channels"), std::string::npos) << none;
  EXPECT_NE(FlightLog::Open(kPrefix + "_zstd.mcap").Summary().format_detail.find("(zstd "),
            std::string::npos);
  EXPECT_NE(FlightLog::Open(kPrefix + "_lz4.mcap").Summary().format_detail.find("(lz4 "),
            std::string::npos);
  EXPECT_EQ(FlightLog::Open(kPrefix + ".db3").Summary().format_detail,
            "ROS 2 sqlite3 bag, 2 topics");
}

// @mcap/core states every chunk's CRC-32: the copies above pass plumb's check; one bit flipped in
// the middle of the uncompressed copy's first chunk (a byte that still decodes) is refused.
TEST(Ros2RealData, AByteFlippedInAChunkIsRefusedByItsCrc) {
  NEED_FIXTURES();
  std::ifstream in(kPrefix + ".mcap", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::size_t at = 8;  // the first Chunk record (opcode 0x06), after the magic
  while (at + 9 <= bytes.size() && bytes[at] != 0x06) {
    std::uint64_t len = 0;
    std::memcpy(&len, bytes.data() + at + 1, sizeof len);
    at += 9 + static_cast<std::size_t>(len);
  }
  ASSERT_LT(at + 9, bytes.size());
  std::uint64_t len = 0;
  std::memcpy(&len, bytes.data() + at + 1, sizeof len);
  bytes[at + 9 + static_cast<std::size_t>(len) / 2] ^= 0x10;
  const std::string path =
      (std::filesystem::temp_directory_path() / "plumb_ros2_real_flipped.mcap").string();
  std::ofstream(path, std::ios::binary) << bytes;
  try {
    ReadMcap(path);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.where(), "byte " + std::to_string(at));
    EXPECT_NE(std::string(e.what()).find("uncompressed_crc"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace plumb::io

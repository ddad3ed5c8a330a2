// The ROS 1 bags of ../shared/data/ros (real recordings) read by plumb (FlightLog, as `plumb
// info` and every command read them) against Debian's python3-rosbag, an independent reader
// (tests/io/rosbag_reference.py): message counts, the first and last messages' stamps, record
// times and values; the bz2 and uncompressed copies of the AR.Drone recording give the same
// samples; and each bag read with its chunks ahead gives the same bag bit for bit. Skipped
// with the reason when the data or python3-rosbag is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/ros_bag_text.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/io/ros/ros_session.h"
#include "plumb/io/ros/rosbag.h"
#include "support/reverse_jobs.h"

namespace plumb::io {
namespace {

std::string Bag(const std::string& name) {
  return std::string(PLUMB_SHARED_DATA_DIR) + "/ros/" + name;
}

#define SKIP_IF_ABSENT(path) \
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << (path)

/// The output of `command`, and whether it exited 0.
bool RunCommand(const std::string& command, std::string* out) {
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return false;
  char buffer[65536];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out->append(buffer, n);
  return ::pclose(pipe) == 0;
}

/// A Python with the rosbag module (Debian's /usr/bin/python3 first: a pyenv python3 on PATH
/// lacks the system's packages), or "".
std::string PythonWithRosbag() {
  for (const char* python : {"/usr/bin/python3", "python3"}) {
    std::string ignored;
    if (RunCommand(std::string(python) + " -c 'import rosbag' 2>/dev/null", &ignored)) return python;
  }
  return "";
}

void ExpectMessage(const ImuSeries& s, const std::vector<double>& receive, std::size_t i,
                   const nlohmann::json& ref) {
  const double stamp = ref["stamp"][0].get<double>() + ref["stamp"][1].get<double>() * 1e-9;
  const double rec = ref["receive"][0].get<double>() + ref["receive"][1].get<double>() * 1e-9;
  EXPECT_DOUBLE_EQ(s.t_s[i], stamp) << "message " << i;
  EXPECT_DOUBLE_EQ(receive[i], rec) << "message " << i;
  for (int k = 0; k < 3; ++k) {
    EXPECT_FLOAT_EQ(s.acc[i][k], static_cast<float>(ref["acc"][k].get<double>())) << i;
    EXPECT_FLOAT_EQ(s.gyr[i][k], static_cast<float>(ref["gyr"][k].get<double>())) << i;
  }
}

TEST(RosBagRealData, AgreesWithPythonRosbag) {
  const std::vector<std::string> bags = {Bag("ardrone_imu.bag"),
                                         Bag("ardrone_imu_uncompressed.bag"),
                                         Bag("phidgets_imu_upside_down.bag")};
  for (const std::string& b : bags) SKIP_IF_ABSENT(b);
  const std::string python = PythonWithRosbag();
  if (python.empty()) GTEST_SKIP() << "python3-rosbag absent (apt-get install python3-rosbag)";
  std::string text;
  std::string command = python + " " + PLUMB_SOURCE_DIR + "/tests/io/rosbag_reference.py";
  for (const std::string& b : bags) command += " '" + b + "'";
  ASSERT_TRUE(RunCommand(command, &text)) << command;
  const nlohmann::json ref = nlohmann::json::parse(text);
  for (const std::string& b : bags) {
    SCOPED_TRACE(b);
    const RosBag bag = ReadRosBag(b);
    EXPECT_FALSE(bag.warnings.any());
    const nlohmann::json& r = ref.at(b);
    ASSERT_EQ(bag.imu_topics.size(), r["imu"].size());
    for (const RosImuTopic& t : bag.imu_topics) {
      const nlohmann::json& rt = r["imu"].at(t.topic);
      ASSERT_EQ(t.samples.size(), rt["count"].get<std::size_t>());
      EXPECT_EQ(t.frame_id, rt["first"]["frame_id"].get<std::string>());
      ExpectMessage(t.samples, t.receive_s, 0, rt["first"]);
      ExpectMessage(t.samples, t.receive_s, t.samples.size() - 1, rt["last"]);
    }
    // The counts `plumb info` shows, per topic and type.
    const FlightLogSummary summary = FlightLog::Open(b).Summary();
    for (const auto& [name, count] : summary.messages) {
      const std::string topic = name.substr(0, name.find(" ("));
      EXPECT_EQ(count, r["messages"].at(topic).get<std::size_t>()) << name;
    }
    EXPECT_EQ(summary.imus.at(0).samples, r["imu"].begin().value()["count"].get<std::size_t>());
  }
}

// The real bags' chunks (4 and 10 bz2, 3 uncompressed) read ahead through two threads, as
// `plumb` reads them on a machine of two cores: the same bag as on the calling thread alone,
// bit for bit.
TEST(RosBagRealData, ReadAheadGivesTheSameBag) {
  for (const char* name : {"ardrone_imu.bag", "ardrone_imu_uncompressed.bag",
                           "phidgets_imu_upside_down.bag"}) {
    const std::string b = Bag(name);
    SKIP_IF_ABSENT(b);
    const std::string alone = test::BagText([&] { return ReadRosBag(b); });
    ASSERT_EQ(alone.rfind("InputError", 0), std::string::npos) << alone;
    EXPECT_EQ(test::BagText([&] { return ReadRosBag(b, plumb::testing::OnTwoThreads); }), alone)
        << name;
  }
}

TEST(RosBagRealData, Bz2AndUncompressedCopiesGiveTheSameSamples) {
  const std::string bz2 = Bag("ardrone_imu.bag");
  const std::string none = Bag("ardrone_imu_uncompressed.bag");
  SKIP_IF_ABSENT(bz2);
  SKIP_IF_ABSENT(none);
  const FlightLog a = FlightLog::Open(bz2);
  const FlightLog b = FlightLog::Open(none);
  FlightLogSelection pick;
  pick.stream = "/ardrone/imu";
  const Session sa = a.Select(pick);
  const Session sb = b.Select(pick);
  EXPECT_EQ(sa.series.size(), 4308u);
  EXPECT_EQ(sa.series.t_s, sb.series.t_s);
  EXPECT_EQ(sa.series.acc, sb.series.acc);
  EXPECT_EQ(sa.series.gyr, sb.series.gyr);
  EXPECT_NE(a.Summary().format_detail.find("bz2 4"), std::string::npos);
  EXPECT_NE(b.Summary().format_detail.find("none"), std::string::npos);
}

TEST(RosBagRealData, PhidgetsUpsideDownAllZeroOrientation) {
  const std::string path = Bag("phidgets_imu_upside_down.bag");
  SKIP_IF_ABSENT(path);
  const RosBag bag = ReadRosBag(path);
  ASSERT_EQ(bag.imu_topics.size(), 1u);
  const RosImuTopic& t = bag.imu_topics[0];
  EXPECT_EQ(t.topic, "/imu/data_raw");
  EXPECT_EQ(t.samples.size(), 13964u);
  EXPECT_EQ(t.orientation_zero, 13964u);
  EXPECT_LT(t.samples.acc[0].z(), -9.5f);  // upside down, as logged (z up: gravity reads -g)
  EXPECT_EQ(bag.compression.at("bz2"), 10u);
}

}  // namespace
}  // namespace plumb::io

namespace plumb::io {
namespace {

// Three small bags python3-rosbag wrote (tests/fuzz/seeds/rosbag: the first 60 messages of the
// Phidgets bag, chunks none, bz2 and lz4 as roslz4 writes them): the same 30 IMU samples.
TEST(RosBagWrittenByRosbag, EveryCompressionGivesTheSameSamples) {
  const std::string dir = std::string(PLUMB_SOURCE_DIR) + "/tests/fuzz/seeds/rosbag/";
  const RosBag none = ReadRosBag(dir + "phidgets_60_none.bag");
  ASSERT_EQ(none.imu_topics.size(), 1u);
  EXPECT_EQ(none.imu_topics[0].samples.size(), 30u);
  EXPECT_FALSE(none.warnings.any());
  for (const char* c : {"bz2", "lz4"}) {
    const RosBag other = ReadRosBag(dir + "phidgets_60_" + c + ".bag");
    ASSERT_EQ(other.imu_topics.size(), 1u) << c;
    EXPECT_EQ(other.compression.at(c), 4u) << c;
    EXPECT_FALSE(other.warnings.any()) << c;
    EXPECT_EQ(other.imu_topics[0].samples.t_s, none.imu_topics[0].samples.t_s) << c;
    EXPECT_EQ(other.imu_topics[0].samples.acc, none.imu_topics[0].samples.acc) << c;
    EXPECT_EQ(other.imu_topics[0].samples.gyr, none.imu_topics[0].samples.gyr) << c;
    EXPECT_EQ(other.imu_topics[0].receive_s, none.imu_topics[0].receive_s) << c;
  }
}

}  // namespace
}  // namespace plumb::io

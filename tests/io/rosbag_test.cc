// The ROS 1 bag reader (io/ros) on small bags written here (rosbag_builder.h): chunks of each
// compression, with and without an index, connections after the chunks, bags cut short at
// every byte, corrupt lengths, and the session's topic, clock and frame.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "io/io_test_util.h"
#include "io/ros_bag_text.h"
#include "io/rosbag_builder.h"
#include "plumb/core/error.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/io/input/open_inputs.h"
#include "plumb/io/ros/read_ahead.h"
#include "plumb/io/ros/ros_session.h"
#include "plumb/io/ros/rosbag.h"
#include "support/reverse_jobs.h"

namespace plumb::io {
namespace {

using test::RosBagStart;
using test::RosChunkRecord;
using test::RosConnectionRecord;
using test::RosImuMessage;
using test::RosMessageRecord;

constexpr std::uint32_t kSec = 1360242236;

/// The records of `n` IMU messages of connection `conn` at 100 Hz, the connection first.
std::string ImuRecords(std::uint32_t conn, const std::string& topic, int n, int from = 0,
                       bool with_connection = true) {
  std::string out = with_connection ? RosConnectionRecord(conn, topic) : "";
  for (int i = from; i < from + n; ++i) {
    const std::uint32_t nsec = static_cast<std::uint32_t>(i) * 10000000u;
    const std::array<double, 3> acc = {0.1 * i, -0.2, 9.8 + 0.001 * i};
    const std::array<double, 3> gyr = {0.01, 0.002 * i, -0.03};
    out += RosMessageRecord(conn, kSec + 1, nsec + 5000,
                            RosImuMessage(static_cast<std::uint32_t>(i), kSec, nsec, "/imu", acc, gyr));
  }
  return out;
}

/// A bag of 3 chunks of 40 messages each, compressed with `compression`, indexed or not.
std::string ThreeChunks(const std::string& compression, bool indexed) {
  std::string bag = RosBagStart();
  const std::size_t first_chunk = bag.size();
  bag += RosChunkRecord(compression, ImuRecords(0, "/imu/data_raw", 40));
  bag += RosChunkRecord(compression, ImuRecords(0, "/imu/data_raw", 40, 40, false));
  bag += RosChunkRecord(compression, ImuRecords(0, "/imu/data_raw", 40, 80, false));
  if (indexed) {
    bag += RosConnectionRecord(0, "/imu/data_raw");
    bag += test::RosIndexRecords(0, first_chunk);
  }
  return bag;
}

/// The offsets where the top-level records of `bag` start, and its size.
std::vector<std::size_t> RecordStarts(const std::string& bag) {
  std::vector<std::size_t> out;
  std::size_t pos = 13;
  while (pos + 4 <= bag.size()) {
    out.push_back(pos);
    std::uint32_t header = 0, data = 0;
    std::memcpy(&header, &bag[pos], 4);
    std::memcpy(&data, &bag[pos + 4 + header], 4);
    pos += 8 + header + data;
  }
  out.push_back(bag.size());
  return out;
}

RosBag Parse(const std::string& bytes) {
  return ParseRosBag(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), "t.bag");
}

TEST(RosBag, ReadsEveryCompressionAlike) {
  const RosBag none = Parse(ThreeChunks("none", true));
  ASSERT_EQ(none.imu_topics.size(), 1u);
  const RosImuTopic& t = none.imu_topics[0];
  EXPECT_EQ(t.topic, "/imu/data_raw");
  EXPECT_EQ(t.frame_id, "/imu");
  ASSERT_EQ(t.samples.size(), 120u);
  EXPECT_DOUBLE_EQ(t.samples.t_s[0], kSec);
  EXPECT_DOUBLE_EQ(t.samples.t_s[119], kSec + 1.19);
  EXPECT_DOUBLE_EQ(t.receive_s[0], kSec + 1 + 5e-6);
  EXPECT_FLOAT_EQ(t.samples.acc[119].x(), static_cast<float>(0.1 * 119));
  EXPECT_FLOAT_EQ(t.samples.acc[7].z(), static_cast<float>(9.8 + 0.007));
  EXPECT_FLOAT_EQ(t.samples.gyr[9].y(), static_cast<float>(0.018));
  EXPECT_EQ(t.orientation_not_given, 120u);
  EXPECT_FALSE(none.warnings.any()) << none.warnings.Describe()[0];
  EXPECT_EQ(none.chunks, 3u);
  EXPECT_EQ(none.chunk_infos, 1u);
  EXPECT_EQ(none.connections.size(), 1u);
  EXPECT_EQ(none.connections.at(0).callerid, "/test_node");
  for (const char* c : {"bz2", "lz4"}) {
    for (const bool indexed : {true, false}) {
      const RosBag other = Parse(ThreeChunks(c, indexed));
      ASSERT_EQ(other.imu_topics.size(), 1u) << c;
      EXPECT_EQ(other.imu_topics[0].samples.t_s, t.samples.t_s) << c;
      EXPECT_EQ(other.imu_topics[0].samples.acc, t.samples.acc) << c;
      EXPECT_EQ(other.imu_topics[0].samples.gyr, t.samples.gyr) << c;
      EXPECT_EQ(other.imu_topics[0].receive_s, t.receive_s) << c;
      EXPECT_EQ(other.compression.at(c), 3u);
      EXPECT_EQ(other.chunk_infos, indexed ? 1u : 0u);
      EXPECT_FALSE(other.warnings.any()) << c;
    }
  }
}

TEST(RosBag, MixedCompressionAndOtherTopics) {
  std::string bag = RosBagStart();
  bag += RosChunkRecord("bz2", ImuRecords(0, "/a", 10) +
                                   RosConnectionRecord(1, "/mag", "sensor_msgs/MagneticField",
                                                       "2f3b0b43eed0c9501de0fa3ff89a45aa") +
                                   RosMessageRecord(1, kSec, 0, std::string(100, 'x')));
  bag += RosChunkRecord("lz4", ImuRecords(2, "/b", 10));
  bag += RosChunkRecord("none", ImuRecords(0, "/a", 10, 10, false));
  const RosBag b = Parse(bag);
  ASSERT_EQ(b.imu_topics.size(), 2u);
  EXPECT_EQ(b.Find("/a")->samples.size(), 20u);
  EXPECT_EQ(b.Find("/b")->samples.size(), 10u);
  const auto counts = b.MessageCounts();
  ASSERT_EQ(counts.size(), 3u);
  EXPECT_EQ(counts[1].first, "/mag (sensor_msgs/MagneticField)");
  EXPECT_EQ(counts[1].second, 1u);
  const FlightLogSummary summary = RosBagSummary(b);
  EXPECT_EQ(summary.format, "ros1-bag");
  ASSERT_EQ(summary.imus.size(), 2u);
  EXPECT_EQ(summary.imus[1].name, "/b");
  EXPECT_EQ(summary.imus[1].instance, 1);
  EXPECT_NEAR(summary.imus[0].rate_hz, 100.0, 1e-3);  // unix times: 2.4e-7 s steps
  EXPECT_NE(summary.format_detail.find("no index"), std::string::npos) << summary.format_detail;
  // Two IMU topics and none named: an error listing them and naming the option.
  try {
    RosBagSession(b, FlightLogSelection{});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/a (20 messages), /b (10 messages)"), std::string::npos)
        << e.what();
    EXPECT_EQ(e.options(), std::vector<Option>{Option::kTopic});
  }
  FlightLogSelection pick;
  pick.stream = "/b";
  EXPECT_EQ(RosBagSession(b, pick).series.size(), 10u);
  pick.stream = "/c";
  EXPECT_THROW(RosBagSession(b, pick), InputError);
  FlightLogSelection by_instance;  // --imu 1: the second IMU topic
  by_instance.imu = 1;
  EXPECT_EQ(RosBagSession(b, by_instance).source, "t.bag (/b)");
  by_instance.imu = 2;
  EXPECT_THROW(RosBagSession(b, by_instance), InputError);
}

TEST(RosBag, ConnectionsOnlyAfterTheChunks) {
  // A writer that puts connections in the index section only: messages kept aside, decoded.
  std::string bag = RosBagStart();
  bag += RosChunkRecord("none", ImuRecords(4, "/imu", 30, 0, false));
  bag += RosConnectionRecord(4, "/imu");
  const RosBag b = Parse(bag);
  ASSERT_EQ(b.imu_topics.size(), 1u);
  EXPECT_EQ(b.imu_topics[0].samples.size(), 30u);
  EXPECT_EQ(b.warnings.orphan_messages, 0u);
  // Without the connection at all: counted, not decoded.
  std::string orphan = RosBagStart();
  orphan += RosChunkRecord("none", ImuRecords(4, "/imu", 30, 0, false));
  const RosBag o = Parse(orphan);
  EXPECT_TRUE(o.imu_topics.empty());
  EXPECT_EQ(o.warnings.orphan_messages, 30u);
}

TEST(RosBag, CutShortAtEveryByteKeepsAPrefix) {
  for (const char* c : {"none", "bz2", "lz4"}) {
    const std::string whole = ThreeChunks(c, true);
    const RosBag full = Parse(whole);
    const std::vector<double>& all = full.imu_topics[0].samples.t_s;
    const std::size_t header_end = RosBagStart().size();
    const std::vector<std::size_t> starts = RecordStarts(whole);
    std::size_t last_count = 0;
    for (std::size_t cut = 13; cut < whole.size(); ++cut) {
      const std::string part = whole.substr(0, cut);
      if (cut < header_end) {
        EXPECT_THROW(Parse(part), InputError) << c << " cut " << cut;
        continue;
      }
      RosBag b;
      ASSERT_NO_THROW(b = Parse(part)) << c << " cut " << cut;
      const std::size_t n = b.imu_topics.empty() ? 0 : b.imu_topics[0].samples.size();
      ASSERT_LE(n, all.size());
      if (n > 0) {
        EXPECT_TRUE(std::equal(b.imu_topics[0].samples.t_s.begin(),
                               b.imu_topics[0].samples.t_s.end(), all.begin()));
      }
      EXPECT_GE(n, last_count) << c << " cut " << cut;  // more file, never fewer samples
      last_count = n;
      // Cut inside a record: said (at a record boundary the bag looks whole, its header's
      // index_pos being 0 here).
      const bool boundary = std::find(starts.begin(), starts.end(), cut) != starts.end();
      EXPECT_EQ(b.warnings.cut_at.has_value(), !boundary) << c << " cut " << cut;
    }
  }
  // An uncompressed chunk cut in the middle keeps its whole messages and says so.
  const std::string whole = ThreeChunks("none", false);
  const RosBag b = Parse(whole.substr(0, whole.size() - 1000));
  EXPECT_GT(b.warnings.cut_messages_kept, 0u);
  const std::string text = b.warnings.Describe()[0];
  EXPECT_NE(text.find("cut short: the record at byte "), std::string::npos) << text;
}

TEST(RosBag, CorruptLengthsAreCountedNeverFatal) {
  const std::string whole = ThreeChunks("none", false);
  const std::size_t chunk = RosBagStart().size();
  {  // The first chunk's header length past the end of the file: cut there.
    std::string bad = whole;
    const std::uint32_t huge = 0x7fffffff;
    std::memcpy(&bad[chunk], &huge, 4);
    const RosBag b = Parse(bad);
    EXPECT_EQ(b.warnings.cut_at, chunk);
    EXPECT_TRUE(b.imu_topics.empty() || b.imu_topics[0].samples.empty());
  }
  {  // A field length inside the chunk's header past the header: record skipped, rest read.
    std::string bad = whole;
    const std::uint32_t huge = 0x10000;
    std::memcpy(&bad[chunk + 4], &huge, 4);
    const RosBag b = Parse(bad);
    EXPECT_EQ(b.warnings.bad_records, 1u);
    EXPECT_EQ(b.warnings.first_bad_record, chunk);
  }
  {  // A chunk's size that does not match its data: damaged, its whole records read.
    std::string records = ImuRecords(0, "/imu", 10);
    std::string chunk_record = RosChunkRecord("bz2", records);
    const std::string field = test::RosField("size", test::Bytes(std::uint32_t(records.size())));
    const std::size_t at = chunk_record.find(field);
    const std::uint32_t wrong = static_cast<std::uint32_t>(records.size() - 400);
    std::memcpy(&chunk_record[at + 9], &wrong, 4);
    const RosBag b = Parse(RosBagStart() + chunk_record + RosChunkRecord("none", ImuRecords(0, "/imu", 5, 10, false)));
    EXPECT_EQ(b.warnings.damaged_chunks, 1u);
    ASSERT_EQ(b.imu_topics.size(), 1u);
    EXPECT_GE(b.imu_topics[0].samples.size(), 5u + 8u);
  }
  {  // An IMU message one byte short, another with a frame_id length past its end.
    std::string msg = RosImuMessage(0, kSec, 0, "imu", {0, 0, 9.8}, {0, 0, 0});
    std::string shorter = msg.substr(0, msg.size() - 1);
    std::string long_id = msg;
    const std::uint32_t len = 0xffffff00;
    std::memcpy(&long_id[12], &len, 4);
    const RosBag b = Parse(RosBagStart() + RosChunkRecord("none", RosConnectionRecord(0, "/i") +
                                                                       RosMessageRecord(0, kSec, 0, shorter) +
                                                                       RosMessageRecord(0, kSec, 0, long_id) +
                                                                       RosMessageRecord(0, kSec, 1, msg)));
    EXPECT_EQ(b.warnings.malformed_imu, 2u);
    EXPECT_EQ(b.imu_topics[0].samples.size(), 1u);
  }
  {  // Another md5sum: said, decoded where the size fits.
    const RosBag b = Parse(RosBagStart() +
                           RosChunkRecord("none", RosConnectionRecord(0, "/i", "sensor_msgs/Imu", "0123") +
                                                      ImuRecords(0, "/i", 5, 0, false)));
    ASSERT_EQ(b.warnings.md5_notes.size(), 1u);
    EXPECT_EQ(b.imu_topics[0].samples.size(), 5u);
  }
  {  // A chunk stating more than 1 GiB: skipped, counted, the next chunk read.
    std::string records = ImuRecords(0, "/imu", 10);
    std::string chunk_record = RosChunkRecord("lz4", records);
    const std::string field = test::RosField("size", test::Bytes(std::uint32_t(records.size())));
    const std::size_t at = chunk_record.find(field);
    const std::uint32_t huge = 0xfffffff0u;
    std::memcpy(&chunk_record[at + 9], &huge, 4);
    const RosBag b = Parse(RosBagStart() + chunk_record +
                           RosChunkRecord("none", ImuRecords(1, "/imu", 5, 10)));
    EXPECT_EQ(b.warnings.damaged_chunks, 1u);
    EXPECT_NE(b.warnings.first_damage.find("more than plumb reads"), std::string::npos);
    EXPECT_EQ(b.imu_topics.at(0).samples.size(), 5u);
  }
  {  // A damaged compressed stream: counted.
    std::string chunk_record = RosChunkRecord("bz2", ImuRecords(0, "/imu", 50));
    chunk_record[chunk_record.size() / 2] ^= 0x55;
    RosBag b;
    ASSERT_NO_THROW(b = Parse(RosBagStart() + chunk_record));
    EXPECT_EQ(b.warnings.damaged_chunks, 1u);
  }
}

// A message record's header is read at its places when it is the usual three fields (conn, op,
// time) in any order, and walked otherwise: the same sample either way.
TEST(RosBag, MessageHeadersInAnyFieldOrderReadAlike) {
  using test::RosField;
  const std::string conn = RosField("conn", test::Bytes(std::uint32_t{0}));
  const std::string op = test::RosOpField(0x02);
  const std::string time = RosField("time", test::RosTime(kSec + 1, 5000));
  const std::string msg =
      RosImuMessage(0, kSec, 7000, "/imu", {0.1, -0.2, 9.8}, {0.01, 0.0, -0.03});
  const auto read = [&](const std::string& header) {
    return test::BagText([&] {
      return Parse(RosBagStart() +
                   RosChunkRecord("none", RosConnectionRecord(0, "/imu") +
                                              test::RosRecord(header, msg)));
    });
  };
  const std::string usual = read(conn + op + time);
  ASSERT_NE(usual.find("\n/imu /imu 0 1 "), std::string::npos) << usual;
  EXPECT_EQ(read(op + conn + time), usual);
  EXPECT_EQ(read(time + conn + op), usual);  // the AR.Drone bag's order
  EXPECT_EQ(read(time + op + conn), usual);
  EXPECT_EQ(read(conn + time + op), usual);
  EXPECT_EQ(read(op + time + conn), usual);
  EXPECT_EQ(read(conn + op + time + RosField("x", "1")), usual);  // walked: an extra field
  // The usual size, another name: walked, the record has no time and is skipped.
  const std::string tame = RosField("tame", test::RosTime(1, 2));
  const RosBag other =
      Parse(RosBagStart() + RosChunkRecord("none", RosConnectionRecord(0, "/imu") +
                                                       test::RosRecord(conn + op + tame, msg)));
  EXPECT_EQ(other.warnings.bad_records, 1u);
  EXPECT_TRUE(other.imu_topics.empty() || other.imu_topics[0].samples.empty());
}

/// ReadRosBag's reading of `bytes` as text (test::BagText), the chunks read ahead through
/// `run_jobs` when it is not empty and there are `min_chunks` at least.
std::string Everything(const std::string& bytes, const JobRunner& run_jobs,
                       std::size_t min_chunks) {
  return test::BagText([&] {
    return detail::ParseRosBagReadingAhead(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                           bytes.size(), "t.bag", run_jobs, min_chunks);
  });
}

/// Eight chunks of 10 IMU messages, with a top-level message among them, the IMU connection
/// defined only after the chunks when `late_connection` (its messages kept aside until then),
/// then the index.
std::string EightChunks(const std::string& compression, bool late_connection) {
  std::string bag = RosBagStart();
  const std::size_t first_chunk = bag.size();
  for (int k = 0; k < 8; ++k) {
    bag += RosChunkRecord(compression,
                          ImuRecords(0, "/imu/data_raw", 10, 10 * k, k == 0 && !late_connection));
    if (k == 2) bag += ImuRecords(1, "/imu/other", 3);
  }
  bag += RosConnectionRecord(0, "/imu/data_raw");
  bag += test::RosIndexRecords(0, first_chunk);
  return bag;
}

// The chunks read ahead (through a runner of two threads, or one that runs the jobs last first)
// or on the calling thread alone: the same bag, the same warnings, the same error, for whole,
// cut, damaged and refused bags.
TEST(RosBag, ReadingChunksAheadGivesTheSameBag) {
  const auto same = [](const std::string& bytes, const std::string& what) {
    const std::string alone = Everything(bytes, {}, 0);
    EXPECT_EQ(Everything(bytes, plumb::testing::OnTwoThreads, 0), alone) << what;
    EXPECT_EQ(Everything(bytes, test::Backwards, 0), alone) << what;
    // Fewer chunks than the reader reads ahead from: read alone, no job run.
    EXPECT_EQ(Everything(bytes, test::Backwards, 100), alone) << what;
  };
  for (const char* c : {"none", "bz2", "lz4"}) {
    for (const bool late : {false, true}) {
      const std::string whole = EightChunks(c, late);
      const std::string name = std::string(c) + (late ? " late" : "");
      ASSERT_EQ(Everything(whole, plumb::testing::OnTwoThreads, 0).rfind("8 83 1 0\n", 0), 0u)
          << Everything(whole, plumb::testing::OnTwoThreads, 0);
      // Every few bytes (bz2's chunks, slow to decompress, less often).
      const std::size_t step = std::string(c) == "bz2" ? 97 : 13;
      for (std::size_t cut = 0; cut <= whole.size(); cut += step) {
        same(whole.substr(0, cut), name + " cut " + std::to_string(cut));
      }
      // A byte changed in turn: a damaged chunk, a record that does not parse, a message
      // that no longer decodes.
      for (std::size_t at = whole.size() / 16; at < whole.size(); at += whole.size() / 16) {
        std::string damaged = whole;
        damaged[at] = static_cast<char>(damaged[at] ^ 0x5a);
        same(damaged, name + " byte " + std::to_string(at) + " changed");
      }
    }
  }
  // An unknown compression and a chunk stating more than 1 GiB among the others; a bag whose
  // first record is not its header.
  std::string bag = RosBagStart();
  for (int k = 0; k < 6; ++k) {
    bag += RosChunkRecord(k % 2 ? "lz4" : "bz2", ImuRecords(0, "/imu", 10, 10 * k, k == 0));
  }
  bag += RosChunkRecord("bogus", ImuRecords(0, "/imu", 10, 60, false));
  std::string huge = RosChunkRecord("none", ImuRecords(0, "/imu", 10, 70, false));
  const std::uint32_t over = 0xfffffff0u;
  std::memcpy(&huge[huge.find("size=") + 5], &over, 4);
  same(bag + huge + RosChunkRecord("lz4", ImuRecords(0, "/imu", 10, 80, false)), "bogus and huge");
  same("#ROSBAG V2.0\n" + RosChunkRecord("none", ImuRecords(0, "/imu", 10)), "no bag header");
}

// A bag of 40 chunks read from disk through two threads (ReadRosBag reads them ahead from
// detail::kRosChunksReadAhead) and on one: the same bag, whole, cut and with a chunk damaged.
TEST(RosBag, ReadAheadFromDiskGivesTheSameBag) {
  std::string bag = RosBagStart();
  for (int k = 0; k < 40; ++k) {
    bag += RosChunkRecord(k % 3 == 0 ? "bz2" : (k % 3 == 1 ? "lz4" : "none"),
                          ImuRecords(0, "/imu/data_raw", 25, 25 * k, k == 0));
  }
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("plumb_rosbag_test_read_ahead_" + std::to_string(::getpid()) + ".bag"))
                               .string();
  std::string damaged = bag;
  damaged[bag.size() / 2] = static_cast<char>(damaged[bag.size() / 2] ^ 0x5a);
  for (const std::string& bytes : {bag, bag.substr(0, bag.size() - 777), damaged}) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    const std::string alone = test::BagText([&] { return ReadRosBag(path); });
    EXPECT_EQ(test::BagText([&] { return ReadRosBag(path, plumb::testing::OnTwoThreads); }), alone);
    EXPECT_EQ(test::BagText([&] { return ReadRosBag(path, test::Backwards); }), alone);
  }
  const RosBag whole = [&] {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bag;
    return ReadRosBag(path, plumb::testing::OnTwoThreads);
  }();
  EXPECT_EQ(whole.chunks, 40u);
  ASSERT_EQ(whole.imu_topics.size(), 1u);
  EXPECT_EQ(whole.imu_topics[0].samples.size(), 1000u);
  std::filesystem::remove(path);
}

TEST(RosBag, RefusesWhatIsNotABag20) {
  try {
    Parse("#ROSBAG V1.2\n" + std::string(100, '\0'));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "byte 0");
    EXPECT_NE(std::string(e.what()).find("version 2.0"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Parse("ULog"), InputError);
  try {  // The first record is not the bag header.
    Parse("#ROSBAG V2.0\n" + RosConnectionRecord(0, "/imu"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "byte 13");
  }
}

TEST(RosBag, SessionClockFrameAndGyroNotGiven) {
  std::string records = RosConnectionRecord(0, "/imu");
  for (int i = 0; i < 20; ++i) {
    records += RosMessageRecord(0, kSec + 100, static_cast<std::uint32_t>(i) * 20000000u,
                                RosImuMessage(i, kSec, static_cast<std::uint32_t>(i) * 10000000u,
                                              "/imu", {0, 0, 9.8}, {0.1, 0, 0}, -1.0, 0.0, true));
  }
  const RosBag b = Parse(RosBagStart() + RosChunkRecord("lz4", records));
  FlightLogSelection pick;
  const Session s = RosBagSession(b, pick);
  EXPECT_EQ(s.series.size(), 20u);
  EXPECT_FALSE(s.series.has_gyro());  // every angular_velocity_covariance[0] is -1
  EXPECT_NEAR(s.series.t_s[1] - s.series.t_s[0], 0.01, 1e-6);
  const auto has = [&](const std::string& code, const std::string& text) {
    return std::any_of(s.warnings.begin(), s.warnings.end(), [&](const Notice& n) {
      return n.code == code && n.message.find(text) != std::string::npos;
    });
  };
  EXPECT_TRUE(has("sample_source", "REP-103"));
  EXPECT_TRUE(has("sample_source", "20 message(s) with an all-zero orientation"));
  EXPECT_TRUE(has("sample_source", "accelerometer only"));
  EXPECT_TRUE(has("sample_times", "header stamps"));
  pick.receive_time = true;
  const Session r = RosBagSession(b, pick);
  EXPECT_NEAR(r.series.t_s[1] - r.series.t_s[0], 0.02, 1e-6);
  EXPECT_DOUBLE_EQ(r.series.t_s[0], kSec + 100.0);
  pick.from_s = kSec + 100.1;
  pick.to_s = kSec + 100.2;
  EXPECT_EQ(RosBagSession(b, pick).series.size(), 6u);
  pick.from_s = kSec + 500.0;
  EXPECT_THROW(RosBagSession(b, pick), InputError);
}

TEST(RosBag, FlightLogReadsTheBagsOtherImuTopics) {
  // FlightLogSelection::other_imus: a bag's instance k is its IMU topic k, read on the clock
  // and window of IMU 0 (here the topic /b, instance 1, by name).
  std::string bytes = RosBagStart();
  bytes += RosChunkRecord("lz4", ImuRecords(0, "/a", 20) + ImuRecords(1, "/b", 10));
  testing::TempDir dir;
  const std::string path = (dir.path() / "two.bag").string();
  {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  const FlightLog log = FlightLog::Open(path);
  EXPECT_EQ(BoardInstances(log.Summary(), 1), std::vector<int>{0});
  FlightLogSelection pick;
  pick.stream = "/b";
  pick.receive_time = true;
  pick.other_imus = {0};
  const Session s = log.Select(pick);
  ASSERT_EQ(s.other_imus.size(), 1u);
  const BoardImu& a = s.other_imus[0];
  EXPECT_EQ(a.instance, 0);
  EXPECT_EQ(a.name, "/a");
  FlightLogSelection alone;
  alone.stream = "/a";
  alone.receive_time = true;
  const Session expected = log.Select(alone);
  EXPECT_EQ(a.series.t_s, expected.series.t_s);
  EXPECT_EQ(a.series.acc, expected.series.acc);
  EXPECT_DOUBLE_EQ(a.series.t_s[0], kSec + 1 + 5e-6);  // the record time, not the stamp
  EXPECT_EQ(s.series.size(), 10u);
  pick.other_imus = {1};  // /b is IMU 0
  try {
    log.Select(pick);
    ADD_FAILURE() << "/b listed as another IMU";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("IMU instance 1 is IMU 0"), std::string::npos) << e.what();
  }
  pick.other_imus = {2};
  EXPECT_THROW(log.Select(pick), InputError);
}

TEST(RosBag, FlightLogAndOpenInputsReadABagFile) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "plumb_rosbag_test.bag").string();
  {
    std::ofstream out(path, std::ios::binary);
    const std::string bytes = ThreeChunks("bz2", true);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  EXPECT_EQ(SniffFlightLog(path), FlightLogFormat::kRosBag);
  const FlightLog log = FlightLog::Open(path);
  EXPECT_EQ(log.Summary().format, "ros1-bag");
  EXPECT_EQ(log.Summary().imus.at(0).samples, 120u);
  InputOptions o;
  EXPECT_EQ(OpenInputs({path}, o).series.size(), 120u);
  o.clock = Clock::kReceive;
  EXPECT_DOUBLE_EQ(OpenInputs({path}, o).series.t_s[0], kSec + 1 + 5e-6);
  std::filesystem::remove(path);
  // Receive times are a bag's only.
  const std::string csv =
      (std::filesystem::temp_directory_path() / "plumb_rosbag_test.csv").string();
  {
    std::ofstream out(csv);
    out << "time_s,acc_x,acc_y,acc_z\n0,0,0,9.8\n0.01,0,0,9.8\n0.02,0,0,9.8\n";
  }
  try {
    OpenInputs({csv}, o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.options(), std::vector<Option>{Option::kClock});
  }
  std::filesystem::remove(csv);
}

}  // namespace
}  // namespace plumb::io

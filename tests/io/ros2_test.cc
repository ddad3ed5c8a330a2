// The ROS 2 bag readers (io/ros: mcap.h, db3.h, the CDR decoding of ros_imu.h) on small bags
// written here (ros2_builder.h): chunks of each compression, files cut short at every byte, bad
// magic, an unknown compression, big-endian CDR, frame_id alignment, covariance -1 (not
// given), an all-zero quaternion, malformed messages; .db3 read without a byte written beside
// it; and FlightLog recognising both by content.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "io/ros2_builder.h"
#include "plumb/core/error.h"
#include "io/ros_bag_text.h"
#include "support/reverse_jobs.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/io/ros/db3.h"
#include "plumb/io/ros/mcap.h"
#include "plumb/io/ros/read_ahead.h"
#include "plumb/io/ros/ros_imu.h"
#include "plumb/io/ros/ros_session.h"

namespace plumb::io {
namespace {

using test::CdrImu;
using test::McapChannel;
using test::McapChunk;
using test::McapMessage;
using test::McapSchema;
using test::Ros2Imu;

constexpr std::uint64_t kReceiveNs = 1700000000123456789ull;

/// Message i of a 100 Hz stream.
Ros2Imu Nth(int i) {
  Ros2Imu m;
  m.nsec = static_cast<std::uint32_t>(i) * 10000000u;
  m.acc = {0.1 * i, -0.2, 9.8 + 0.001 * i};
  m.gyr = {0.01, 0.002 * i, -0.03};
  return m;
}

/// Message i's linear_acceleration as the reader keeps it (float).
Vec3f AccOf(int i) {
  const Ros2Imu m = Nth(i);
  return Vec3f(static_cast<float>(m.acc[0]), static_cast<float>(m.acc[1]),
               static_cast<float>(m.acc[2]));
}

/// The Schema and Channel of "/imu" (channel 1) and `n` messages from `from`.
std::string ImuRecords(int n, int from = 0, bool definitions = true, bool little = true) {
  std::string out = definitions ? McapSchema(1) + McapChannel(1, 1, "/imu") : "";
  for (int i = from; i < from + n; ++i) {
    out += McapMessage(1, kReceiveNs + static_cast<std::uint64_t>(i) * 10000000u,
                       CdrImu(Nth(i), little));
  }
  return out;
}

std::string Mcap(const std::string& records) {
  return test::kMcapMagic + test::McapHeader() + records + test::McapFooter() + test::kMcapMagic;
}

/// Three chunks of 40 messages, compressed with `compression`.
std::string ThreeChunks(const std::string& compression) {
  return Mcap(McapChunk(ImuRecords(40), compression) +
              McapChunk(ImuRecords(40, 40, false), compression) +
              McapChunk(ImuRecords(40, 80, false), compression));
}

RosBag Parse(const std::string& bytes) {
  return ParseMcap(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), "t.mcap");
}

TEST(McapReader, ReadsUnchunkedMessages) {
  const RosBag bag = Parse(Mcap(ImuRecords(5)));
  EXPECT_EQ(bag.kind, RosBagKind::kMcap);
  ASSERT_EQ(bag.imu_topics.size(), 1u);
  const RosImuTopic& t = bag.imu_topics[0];
  EXPECT_EQ(t.topic, "/imu");
  EXPECT_EQ(t.frame_id, "imu_link");
  ASSERT_EQ(t.samples.size(), 5u);
  EXPECT_EQ(t.samples.t_s[2], 1700000000.0 + 20000000 * 1e-9);
  EXPECT_EQ(t.receive_s[0], 1700000000.0 + 123456789 * 1e-9);
  EXPECT_EQ(t.samples.acc[3], AccOf(3));
  EXPECT_EQ(t.samples.gyr[4].y(), static_cast<float>(0.002 * 4));
  EXPECT_FALSE(bag.warnings.any()) << bag.warnings.Describe().front();
  const FlightLogSummary summary = RosBagSummary(bag);
  EXPECT_EQ(summary.format, "ros2-mcap");
  EXPECT_EQ(summary.format_detail, "MCAP, 0 chunks, 1 channels");
  ASSERT_EQ(summary.messages.size(), 1u);
  EXPECT_EQ(summary.messages[0].first, "/imu (sensor_msgs/msg/Imu)");
  EXPECT_EQ(summary.messages[0].second, 5u);
}

TEST(McapReader, EveryCompressionGivesTheSameSamples) {
  const RosBag none = Parse(ThreeChunks(""));
  ASSERT_EQ(none.imu_topics.size(), 1u);
  EXPECT_EQ(none.imu_topics[0].samples.size(), 120u);
  EXPECT_EQ(RosBagSummary(none).format_detail, "MCAP, 3 chunks (none 3), 1 channels");
  for (const char* c : {"zstd", "lz4"}) {
    const RosBag other = Parse(ThreeChunks(c));
    EXPECT_FALSE(other.warnings.any()) << c;
    EXPECT_EQ(other.compression.at(c), 3u);
    ASSERT_EQ(other.imu_topics.size(), 1u);
    EXPECT_EQ(other.imu_topics[0].samples.t_s, none.imu_topics[0].samples.t_s) << c;
    EXPECT_EQ(other.imu_topics[0].samples.acc, none.imu_topics[0].samples.acc) << c;
    EXPECT_EQ(other.imu_topics[0].samples.gyr, none.imu_topics[0].samples.gyr) << c;
    EXPECT_EQ(other.imu_topics[0].receive_s, none.imu_topics[0].receive_s) << c;
  }
  EXPECT_EQ(RosBagSummary(Parse(ThreeChunks("zstd"))).format_detail,
            "MCAP, 3 chunks (zstd 3), 1 channels");
}

TEST(McapReader, CutAtEveryByteKeepsTheMessagesBefore) {
  for (const char* c : {"", "zstd", "lz4"}) {
    const std::string whole = ThreeChunks(c);
    std::size_t last = 0;
    for (std::size_t cut = 8; cut < whole.size(); ++cut) {
      const std::string part = whole.substr(0, cut);
      RosBag bag;
      try {
        bag = Parse(part);
      } catch (const InputError& e) {
        // Only a file whose Header record is not whole is refused.
        EXPECT_LT(cut, 8u + 9u + 4u + 4u + 4u + 10u + 1u) << c << " cut " << cut << ": " << e.what();
        continue;
      }
      const std::size_t n = bag.imu_topics.empty() ? 0 : bag.imu_topics[0].samples.size();
      EXPECT_GE(n, last) << c << " cut " << cut;  // never fewer for a longer file
      last = n;
      // Cut before the Footer: said (past it only the closing magic is missing).
      if (cut <= whole.size() - 8 - 29) EXPECT_TRUE(bag.warnings.any()) << c << " cut " << cut;
      (void)bag.warnings.Describe();
    }
    EXPECT_EQ(last, 120u) << c;
  }
}

TEST(McapReader, CutInsideAChunkSaysWhereAndKeepsItsWholeMessages) {
  const std::string whole = ThreeChunks("");
  const std::string part = whole.substr(0, whole.size() / 2);
  const RosBag bag = Parse(part);
  ASSERT_TRUE(bag.warnings.cut_at.has_value());
  EXPECT_GT(bag.warnings.cut_messages_kept, 0u);
  const std::string line = bag.warnings.Describe().front();
  EXPECT_NE(line.find("cut short: the record at byte " + std::to_string(*bag.warnings.cut_at)),
            std::string::npos) << line;
}

TEST(McapReader, RefusesBadMagicOtherVersionAndMissingHeader) {
  const auto message = [](const std::string& bytes) {
    try {
      Parse(bytes);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("\x89MCAX0\r\n").find("not an MCAP file"), std::string::npos);
  EXPECT_NE(message("\x89MCAP1\r\n" + test::McapHeader()).find("another version ('1')"),
            std::string::npos);
  EXPECT_NE(message(test::kMcapMagic + McapSchema(1)).find("Header record"), std::string::npos);
  EXPECT_NE(message(test::kMcapMagic).find("t.mcap"), std::string::npos);
}

TEST(McapReader, UnknownCompressionIsADamagedChunk) {
  const RosBag bag = Parse(Mcap(McapChunk(ImuRecords(10), "bogus") + McapChunk(ImuRecords(5, 10), "")));
  EXPECT_EQ(bag.warnings.damaged_chunks, 1u);
  EXPECT_NE(bag.warnings.first_damage.find("unknown compression 'bogus'"), std::string::npos);
  EXPECT_EQ(bag.compression.at("bogus"), 1u);
  ASSERT_EQ(bag.imu_topics.size(), 1u);
  EXPECT_EQ(bag.imu_topics[0].samples.size(), 5u);
}

TEST(McapReader, ChunksStatingTheirCrcAreChecked) {
  for (const char* c : {"", "zstd", "lz4"}) {
    const RosBag bag = Parse(Mcap(McapChunk(ImuRecords(40), c, true) +
                                  McapChunk(ImuRecords(40, 40, false), c, true)));
    EXPECT_FALSE(bag.warnings.any()) << c;
    EXPECT_EQ(bag.imu_topics.at(0).samples.size(), 80u) << c;
  }
}

TEST(McapReader, AChunkNotMatchingItsCrcIsAnInputErrorNamingTheChunk) {
  const std::string first = McapChunk(ImuRecords(40), "", true);
  const std::string second = McapChunk(ImuRecords(40, 40, false), "", true);
  std::string bytes = Mcap(first + second);
  const std::size_t at = bytes.find(second);
  ASSERT_NE(at, std::string::npos);
  bytes[at + second.size() - 40] ^= 0x01;  // a bit of a double of the chunk's last message
  try {
    Parse(bytes);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "t.mcap");
    EXPECT_EQ(e.where(), "byte " + std::to_string(at));
    EXPECT_NE(std::string(e.what()).find("uncompressed_crc"), std::string::npos) << e.what();
  }
  // A compressed chunk whose stated CRC is wrong: the same.
  std::string zstd = McapChunk(ImuRecords(40), "zstd", true);
  zstd[9 + 24] ^= 0x01;  // uncompressed_crc's first byte
  EXPECT_THROW(Parse(Mcap(zstd)), InputError);
}

TEST(McapReader, NoFooterIsSaid) {
  const RosBag bag = Parse(test::kMcapMagic + test::McapHeader() + ImuRecords(3));
  ASSERT_EQ(bag.warnings.notes.size(), 1u);
  EXPECT_NE(bag.warnings.notes[0].find("without its Footer"), std::string::npos);
  EXPECT_EQ(bag.imu_topics.at(0).samples.size(), 3u);
}

TEST(McapReader, OtherChannelsCountedOrphansAndOtherEncodings) {
  const std::string records = McapSchema(1) + McapSchema(2, "sensor_msgs/msg/MagneticField") +
                              McapChannel(1, 1, "/imu") + McapChannel(2, 2, "/mag") +
                              McapChannel(3, 1, "/imu_json", "json") +
                              McapMessage(1, kReceiveNs, CdrImu(Nth(0))) +
                              McapMessage(2, kReceiveNs, "\x00\x01\x00\x00") +
                              McapMessage(3, kReceiveNs, "{}") + McapMessage(9, kReceiveNs, "x");
  const RosBag bag = Parse(Mcap(records));
  EXPECT_EQ(bag.messages, 4u);
  EXPECT_EQ(bag.warnings.orphan_messages, 1u);
  ASSERT_EQ(bag.warnings.notes.size(), 1u);
  EXPECT_NE(bag.warnings.notes[0].find("/imu_json"), std::string::npos);
  const auto counts = bag.MessageCounts();
  ASSERT_EQ(counts.size(), 3u);
  EXPECT_EQ(counts[1].first, "/mag (sensor_msgs/msg/MagneticField)");
  EXPECT_EQ(counts[1].second, 1u);
  ASSERT_EQ(bag.imu_topics.size(), 1u);
}

using plumb::testing::OnTwoThreads;
using test::Backwards;

/// The text of the error a read throws ("" when none): its file, place and words.
template <typename Read>
std::string ErrorOf(const Read& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.file() + " | " + e.where() + " | " + e.what();
  }
  return "";
}

/// All a read of `bytes` gives (counts, connections, warnings, the samples' bits), or the
/// error it throws, as text; the chunks read ahead through `run_jobs` when it is not empty
/// and there are `min_chunks` at least.
std::string Everything(const std::string& bytes, const JobRunner& run_jobs,
                       std::size_t min_chunks) {
  return test::BagText([&] {
    return detail::ParseMcapReadingAhead(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                         bytes.size(), "t.mcap", run_jobs, min_chunks);
  });
}

/// Eight chunks of 10 messages (CRC-32 stated) and a top-level message among them.
std::string EightChunks(const std::string& compression) {
  std::string records;
  for (int k = 0; k < 8; ++k) {
    records += McapChunk(ImuRecords(10, 10 * k, k == 0), compression, true);
    if (k == 2) records += McapMessage(1, kReceiveNs, CdrImu(Nth(1000)));
  }
  return Mcap(records);
}

// The chunks read ahead (through a runner of two threads, or one that runs the jobs last first)
// or on the calling thread alone: the same bag, the same warnings, the same error, for whole,
// cut, damaged and refused files.
TEST(McapReader, ReadingChunksAheadGivesTheSameBag) {
  const auto same = [](const std::string& bytes, const std::string& what) {
    const std::string alone = Everything(bytes, {}, 0);
    EXPECT_EQ(Everything(bytes, OnTwoThreads, 0), alone) << what;
    EXPECT_EQ(Everything(bytes, Backwards, 0), alone) << what;
    // Fewer chunks than the reader reads ahead from: read alone, no job run.
    EXPECT_EQ(Everything(bytes, Backwards, detail::kMcapChunksReadAhead), alone) << what;
  };
  for (const char* c : {"", "zstd", "lz4"}) {
    const std::string whole = EightChunks(c);
    ASSERT_EQ(Everything(whole, OnTwoThreads, 0).rfind("8 81 0 0\n", 0), 0u)
        << Everything(whole, OnTwoThreads, 0);
    for (std::size_t cut = 8; cut <= whole.size(); cut += 3) {
      same(whole.substr(0, cut), std::string(c) + " cut " + std::to_string(cut));
    }
    // A byte of each chunk's data changed in turn: a CRC error, a damaged chunk (zstd, lz4),
    // or a message that no longer decodes.
    for (std::size_t at = whole.size() / 16; at < whole.size(); at += whole.size() / 16) {
      std::string damaged = whole;
      damaged[at] = static_cast<char>(damaged[at] ^ 0x5a);
      same(damaged, std::string(c) + " byte " + std::to_string(at) + " changed");
    }
  }
  // An unknown compression and a chunk stating more than 1 GiB among the others.
  std::string records = McapChunk(ImuRecords(10), "", true);
  for (int k = 1; k < 6; ++k) records += McapChunk(ImuRecords(10, 10 * k, false), "zstd", true);
  records += McapChunk(ImuRecords(10, 60, false), "bogus");
  std::string huge = McapChunk(ImuRecords(10, 70, false), "", false);
  huge[9 + 16 + 3] = 0x7f;  // uncompressed size's fourth byte: over 1 GiB
  same(Mcap(records + huge + McapChunk(ImuRecords(10, 80, false), "lz4")), "bogus and huge");
}

// A file of 200 chunks (over detail::kMcapChunksReadAhead: ReadMcap reads them ahead through
// its runner) read from disk through two threads and on one: the same bag; with a byte changed
// in chunk 150 and in chunk 170, the same error, chunk 150's (the first in file order), naming
// the file and the chunk's byte offset.
TEST(McapReader, ReadAheadOfALargeFileReportsTheFirstCorruptChunk) {
  const std::string head = test::kMcapMagic + test::McapHeader();
  std::string records;
  std::vector<std::size_t> chunk_at;
  for (int k = 0; k < 200; ++k) {
    chunk_at.push_back(head.size() + records.size());
    records += McapChunk(ImuRecords(20, 20 * k, k == 0), k % 2 == 0 ? "zstd" : "lz4", true);
    if (k % 7 == 3) records += McapMessage(1, kReceiveNs, CdrImu(Nth(5000 + k)));
  }
  const std::string whole = Mcap(records);
  ASSERT_GE(chunk_at.size(), detail::kMcapChunksReadAhead);
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("plumb_ros2_test_read_ahead_" + std::to_string(::getpid()) + ".mcap"))
                               .string();
  const auto write = [&](const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  };
  write(whole);
  const RosBag alone = ReadMcap(path);
  const RosBag ahead = ReadMcap(path, OnTwoThreads);
  EXPECT_EQ(alone.chunks, 200u);
  EXPECT_EQ(ahead.chunks, alone.chunks);
  EXPECT_EQ(ahead.messages, alone.messages);
  ASSERT_EQ(alone.imu_topics.size(), 1u);
  ASSERT_EQ(ahead.imu_topics.size(), 1u);
  EXPECT_EQ(alone.imu_topics[0].samples.size(), 200u * 20u + 29u);
  EXPECT_EQ(ahead.imu_topics[0].samples.t_s, alone.imu_topics[0].samples.t_s);
  EXPECT_EQ(ahead.imu_topics[0].samples.acc, alone.imu_topics[0].samples.acc);
  EXPECT_EQ(ahead.imu_topics[0].samples.gyr, alone.imu_topics[0].samples.gyr);
  EXPECT_EQ(ahead.imu_topics[0].receive_s, alone.imu_topics[0].receive_s);
  EXPECT_EQ(Everything(whole, OnTwoThreads, detail::kMcapChunksReadAhead),
            Everything(whole, {}, detail::kMcapChunksReadAhead));

  // The uncompressed_crc's last byte of chunks 150 and 170 changed: a CRC error at each.
  std::string damaged = whole;
  for (const int k : {170, 150}) {
    const std::size_t crc_byte = chunk_at[static_cast<std::size_t>(k)] + 9 + 8 + 8 + 8 + 3;
    damaged[crc_byte] = static_cast<char>(damaged[crc_byte] ^ 0x01);
  }
  write(damaged);
  const std::string serial = ErrorOf([&] { ReadMcap(path); });
  EXPECT_EQ(serial, path + " | byte " + std::to_string(chunk_at[150]) + " | " +
                        serial.substr(serial.rfind(" | ") + 3));
  EXPECT_NE(serial.find("uncompressed_crc"), std::string::npos) << serial;
  for (int run = 0; run < 5; ++run) EXPECT_EQ(ErrorOf([&] { ReadMcap(path, OnTwoThreads); }), serial);
  EXPECT_EQ(ErrorOf([&] { ReadMcap(path, Backwards); }), serial);
  std::filesystem::remove(path);
}

TEST(CdrImu, BigEndianGivesTheSameValues) {
  const RosBag little = Parse(Mcap(ImuRecords(4)));
  const RosBag big = Parse(Mcap(ImuRecords(4, 0, true, false)));
  ASSERT_EQ(big.imu_topics.at(0).samples.size(), 4u);
  EXPECT_EQ(big.imu_topics[0].samples.t_s, little.imu_topics[0].samples.t_s);
  EXPECT_EQ(big.imu_topics[0].samples.acc, little.imu_topics[0].samples.acc);
  EXPECT_EQ(big.imu_topics[0].samples.gyr, little.imu_topics[0].samples.gyr);
}

TEST(CdrImu, FrameIdOfEveryLengthAlignsTheDoubles) {
  for (const std::string frame : {"", "/", "/imu", "/imu_link", "/base/imu_link_0123"}) {
    Ros2Imu m = Nth(3);
    m.frame_id = frame;
    const RosBag bag = Parse(Mcap(McapSchema(1) + McapChannel(1, 1, "/imu") +
                                  McapMessage(1, kReceiveNs, CdrImu(m))));
    ASSERT_EQ(bag.imu_topics.at(0).samples.size(), 1u) << frame;
    EXPECT_EQ(bag.imu_topics[0].frame_id, frame);  // a leading '/' kept
    EXPECT_EQ(bag.imu_topics[0].samples.acc[0], AccOf(3));
  }
}

TEST(CdrImu, CovarianceMinusOneAndZeroQuaternion) {
  std::string records = McapSchema(1) + McapChannel(1, 1, "/imu");
  for (int i = 0; i < 4; ++i) {
    Ros2Imu m = Nth(i);
    m.gyr_cov0 = -1.0;
    m.orientation_cov0 = -1.0;
    m.orientation = {0.0, 0.0, 0.0, 0.0};
    records += McapMessage(1, kReceiveNs + i * 10000000ull, CdrImu(m));
  }
  const RosBag bag = Parse(Mcap(records));
  const RosImuTopic& t = bag.imu_topics.at(0);
  EXPECT_EQ(t.gyr_not_given, 4u);
  EXPECT_EQ(t.orientation_not_given, 4u);
  EXPECT_EQ(t.orientation_zero, 4u);
  EXPECT_EQ(t.acc_not_given, 0u);
  EXPECT_FALSE(RosBagImuStreams(bag).at(0).has_gyro);  // accelerometer only
  const Session s = RosBagSession(bag, {});
  EXPECT_TRUE(s.series.gyr.empty());

  std::string no_acc = McapSchema(1) + McapChannel(1, 1, "/imu");
  for (int i = 0; i < 3; ++i) {
    Ros2Imu m = Nth(i);
    m.acc_cov0 = -1.0;
    no_acc += McapMessage(1, kReceiveNs + i, CdrImu(m));
  }
  EXPECT_THROW(RosBagSession(Parse(Mcap(no_acc)), {}), InputError);
}

TEST(CdrImu, MalformedMessagesAreSkippedAndSaidWhere) {
  const std::string good = CdrImu(Nth(1));
  std::string no_nul = good;
  no_nul[4 + 12 + 8] = 'x';  // the NUL after "imu_link" replaced
  const std::string records = McapSchema(1) + McapChannel(1, 1, "/imu") +
                              McapMessage(1, kReceiveNs, good.substr(0, good.size() - 8)) +
                              McapMessage(1, kReceiveNs, "\x01\x01\x00\x00" + good.substr(4)) +
                              McapMessage(1, kReceiveNs, no_nul) +
                              McapMessage(1, kReceiveNs, good.substr(0, 3)) +
                              McapMessage(1, kReceiveNs + 1, good);
  const RosBag bag = Parse(Mcap(records));
  EXPECT_EQ(bag.warnings.malformed_imu, 4u);
  EXPECT_EQ(bag.imu_topics.at(0).malformed, 4u);
  EXPECT_EQ(bag.imu_topics[0].samples.size(), 1u);
  const std::string line = bag.warnings.Describe().back();
  EXPECT_NE(line.find("the message 0 of /imu"), std::string::npos) << line;
  EXPECT_NE(line.find("ends in its orientation"), std::string::npos) << line;
}

TEST(CdrImu, StampTimesAreExact) {
  Ros2Imu m;
  m.sec = 1352907204;
  m.nsec = 593772365;
  const RosBag bag = Parse(Mcap(McapSchema(1) + McapChannel(1, 1, "/imu") +
                                McapMessage(1, 1352907204594176427ull, CdrImu(m))));
  EXPECT_EQ(bag.imu_topics.at(0).samples.t_s[0],
            static_cast<double>(1352907204u) + static_cast<double>(593772365u) * 1e-9);
  EXPECT_EQ(bag.imu_topics[0].receive_s[0],
            static_cast<double>(1352907204u) + static_cast<double>(594176427u) * 1e-9);
}

TEST(CdrImu, EveryCutAndFrameIdLengthDecodesAsTheGeneralPath) {
  // Little-endian messages take DecodeCdrImu's fixed-offset path; the same message big endian
  // takes the general one. Both agree on every frame_id length, and a message cut anywhere
  // before its last covariance is refused by both with the same words.
  for (std::size_t length = 0; length <= 17; ++length) {
    Ros2Imu m = Nth(7);
    m.frame_id = std::string(length, 'f');
    const std::string little = CdrImu(m, true);
    const std::string big = CdrImu(m, false);
    ASSERT_EQ(little.size(), big.size());
    for (std::size_t n = 0; n <= little.size() + 1; ++n) {
      const std::string a = little.substr(0, std::min(n, little.size())) +
                            (n > little.size() ? std::string(1, '\0') : std::string());
      const std::string b = big.substr(0, std::min(n, big.size())) +
                            (n > big.size() ? std::string(1, '\0') : std::string());
      detail::RosImuMessage ma, mb;
      std::string why_a, why_b;
      const bool ok_a = detail::DecodeCdrImu(reinterpret_cast<const std::uint8_t*>(a.data()),
                                             a.size(), &ma, &why_a);
      const bool ok_b = detail::DecodeCdrImu(reinterpret_cast<const std::uint8_t*>(b.data()),
                                             b.size(), &mb, &why_b);
      ASSERT_EQ(ok_a, ok_b) << length << " " << n;
      EXPECT_EQ(ok_a, n >= little.size()) << length << " " << n;
      EXPECT_EQ(why_a, why_b) << length << " " << n;
      if (!ok_a) continue;
      EXPECT_EQ(ma.sec, mb.sec);
      EXPECT_EQ(ma.nsec, mb.nsec);
      EXPECT_EQ(ma.frame_id, m.frame_id);
      EXPECT_EQ(mb.frame_id, m.frame_id);
      EXPECT_EQ(ma.acc, mb.acc);
      EXPECT_EQ(ma.gyr, mb.gyr);
      EXPECT_EQ(ma.acc, Vec3(m.acc[0], m.acc[1], m.acc[2]));
      for (int i = 0; i < 4; ++i) EXPECT_EQ(ma.orientation[i], mb.orientation[i]);
      EXPECT_EQ(ma.orientation_cov0, mb.orientation_cov0);
      EXPECT_EQ(ma.gyr_cov0, mb.gyr_cov0);
      EXPECT_EQ(ma.acc_cov0, mb.acc_cov0);
    }
  }
}

TEST(CdrImu, EveryValueGivesTheSameSampleAndCountsInEitherByteOrder) {
  // A little-endian message is appended straight from its bytes (AppendCdrImuFast); a
  // big-endian one through DecodeCdrImu's general path and AppendImu. Both give the same
  // floats, bit for bit (values beyond the float range saturated), and the same counts.
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> values = {0.0, -0.0, -1.0, 9.80665, 1e39, -1e39, kInf, nan,
                                      std::nextafter(double{std::numeric_limits<float>::max()},
                                                     kInf)};
  std::string little = McapSchema(1) + McapChannel(1, 1, "/imu");
  std::string big = little;
  int count = 0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    for (int slot = 0; slot < 10; ++slot) {
      Ros2Imu m = Nth(count);
      const double v = values[k];
      const double w = values[(k + 1 + static_cast<std::size_t>(slot)) % values.size()];
      switch (slot) {
        case 0: m.acc = {v, w, 1.0}; break;
        case 1: m.acc = {1.0, v, w}; break;
        case 2: m.acc[2] = v; m.acc_cov0 = w; break;
        case 3: m.gyr = {v, w, 1.0}; break;
        case 4: m.gyr = {1.0, v, w}; break;
        case 5: m.gyr[2] = v; m.gyr_cov0 = w; break;
        case 6: m.orientation = {v, v, w, v}; m.orientation_cov0 = w; break;
        case 7: m.orientation = {v, v, v, v}; m.orientation_cov0 = v; break;
        case 8: m.acc_cov0 = v; m.gyr_cov0 = w; break;
        default: m.acc = {v, v, v}; m.gyr = {w, w, w}; break;
      }
      const std::uint64_t at = kReceiveNs + static_cast<std::uint64_t>(count) * 1000u;
      little += McapMessage(1, at, CdrImu(m, true));
      big += McapMessage(1, at, CdrImu(m, false));
      ++count;
    }
  }
  const RosBag a = Parse(Mcap(little));
  const RosBag b = Parse(Mcap(big));
  const RosImuTopic& ta = a.imu_topics.at(0);
  const RosImuTopic& tb = b.imu_topics.at(0);
  ASSERT_EQ(ta.samples.size(), static_cast<std::size_t>(count));
  ASSERT_EQ(tb.samples.size(), static_cast<std::size_t>(count));
  const auto same_bytes = [](const auto& x, const auto& y) {
    return x.size() == y.size() &&
           std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
  };
  EXPECT_TRUE(same_bytes(ta.samples.t_s, tb.samples.t_s));
  EXPECT_TRUE(same_bytes(ta.receive_s, tb.receive_s));
  EXPECT_TRUE(same_bytes(ta.samples.acc, tb.samples.acc));
  EXPECT_TRUE(same_bytes(ta.samples.gyr, tb.samples.gyr));
  EXPECT_EQ(ta.acc_not_given, tb.acc_not_given);
  EXPECT_EQ(ta.gyr_not_given, tb.gyr_not_given);
  EXPECT_EQ(ta.orientation_not_given, tb.orientation_not_given);
  EXPECT_EQ(ta.orientation_zero, tb.orientation_zero);
  EXPECT_GT(ta.acc_not_given, 0u);
  EXPECT_GT(ta.orientation_zero, 0u);
  EXPECT_TRUE(std::isinf(ta.samples.acc[4 * 10 + 0][0]));  // 1e39: +infinity
}

// --- .db3 -------------------------------------------------------------------------------

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("plumb_ros2_test_" + name)).string();
}

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::vector<test::Db3Message> Db3Imu(int n) {
  std::vector<test::Db3Message> out;
  for (int i = 0; i < n; ++i) {
    out.push_back({1, static_cast<std::int64_t>(kReceiveNs) + i * 10000000ll, CdrImu(Nth(i))});
    out.push_back({2, static_cast<std::int64_t>(kReceiveNs) + i * 10000000ll, "\x00\x01\x00\x00"});
  }
  return out;
}

TEST(Db3Reader, ReadsTopicsAndMessagesLikeTheMcapReader) {
  const std::string path = TempPath("a.db3");
  test::WriteDb3(path, {{1, "/imu", "sensor_msgs/msg/Imu"}, {2, "/mag", "sensor_msgs/msg/MagneticField"}},
                 Db3Imu(40));
  const RosBag db3 = ReadDb3(path);
  EXPECT_EQ(db3.kind, RosBagKind::kSqlite3);
  EXPECT_FALSE(db3.warnings.any());
  const RosBag mcap = Parse(Mcap(ImuRecords(40)));
  ASSERT_EQ(db3.imu_topics.size(), 1u);
  EXPECT_EQ(db3.imu_topics[0].samples.t_s, mcap.imu_topics[0].samples.t_s);
  EXPECT_EQ(db3.imu_topics[0].samples.acc, mcap.imu_topics[0].samples.acc);
  EXPECT_EQ(db3.imu_topics[0].samples.gyr, mcap.imu_topics[0].samples.gyr);
  EXPECT_EQ(db3.imu_topics[0].receive_s, mcap.imu_topics[0].receive_s);
  const FlightLogSummary summary = RosBagSummary(db3);
  EXPECT_EQ(summary.format, "ros2-db3");
  EXPECT_EQ(summary.format_detail, "ROS 2 sqlite3 bag, 2 topics");
  ASSERT_EQ(summary.messages.size(), 2u);
  EXPECT_EQ(summary.messages[1].first, "/mag (sensor_msgs/msg/MagneticField)");
  EXPECT_EQ(summary.messages[1].second, 40u);
  // The same bytes in memory.
  const std::string bytes = FileBytes(path);
  const RosBag memory =
      ParseDb3(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), "m.db3");
  EXPECT_EQ(memory.imu_topics.at(0).samples.t_s, db3.imu_topics[0].samples.t_s);
  std::filesystem::remove(path);
}

TEST(Db3Reader, NeverWritesBesideTheInput) {
  const std::filesystem::path dir = TempPath("dir");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "bag.db3").string();
  test::WriteDb3(path, {{1, "/imu", "sensor_msgs/msg/Imu"}}, Db3Imu(5));
  const std::string before = FileBytes(path);
  const auto mtime = std::filesystem::last_write_time(path);
  std::filesystem::permissions(path, std::filesystem::perms::owner_read |
                                         std::filesystem::perms::group_read);
  EXPECT_EQ(SniffFlightLog(path), FlightLogFormat::kRos2Db3);
  const FlightLog log = FlightLog::Open(path);
  EXPECT_EQ(log.Summary().imus.at(0).samples, 5u);
  EXPECT_EQ(FileBytes(path), before);
  EXPECT_EQ(std::filesystem::last_write_time(path), mtime);
  std::size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1u);  // no -journal, -wal or -shm
  std::filesystem::remove_all(dir);
}

/// The names of the files in `dir`.
std::vector<std::string> FilesIn(const std::filesystem::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    out.push_back(e.path().filename().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// A recorder killed in WAL mode: its last messages (or, checkpointed 0, everything, the tables
// too) only in bag.db3-wal. Every message is read, with a warning naming the -wal file; the
// two files stay as they were, nothing is written beside them, and the temporary folder plumb
// reads them in is left as it was (TMPDIR pointed at an empty folder of the test's).
TEST(Db3Reader, MessagesLeftInTheWalFileAreReadWithoutWritingBesideTheInput) {
  const std::filesystem::path dir = TempPath("wal");
  const std::filesystem::path tmp = TempPath("wal_tmp");
  const std::filesystem::path scratch = TempPath("wal_scratch");
  const RosBag reference = Parse(Mcap(ImuRecords(40)));
  const char* old_tmp = std::getenv("TMPDIR");
  const std::string saved = old_tmp == nullptr ? "" : old_tmp;
  for (const std::size_t checkpointed : {std::size_t{30}, std::size_t{0}}) {
    SCOPED_TRACE(checkpointed);
    for (const auto& d : {dir, tmp, scratch}) {
      std::filesystem::remove_all(d);
      std::filesystem::create_directories(d);
    }
    const std::string path = (dir / "bag.db3").string();
    test::WriteUnclosedDb3(path, (scratch / "x.db3").string(),
                           {{1, "/imu", "sensor_msgs/msg/Imu"},
                            {2, "/mag", "sensor_msgs/msg/MagneticField"}},
                           Db3Imu(40), checkpointed);
    ASSERT_GT(std::filesystem::file_size(path + "-wal"), 32u);
    const std::string bag_bytes = FileBytes(path), wal_bytes = FileBytes(path + "-wal");
    for (const std::string& f : {path, path + "-wal"}) {
      std::filesystem::permissions(f, std::filesystem::perms::owner_read);
    }
    ::setenv("TMPDIR", tmp.c_str(), 1);
    EXPECT_EQ(SniffFlightLog(path), FlightLogFormat::kRos2Db3);
    const RosBag bag = ReadDb3(path);
    EXPECT_EQ(FlightLog::Open(path).Summary().imus.at(0).samples, 40u);
    if (old_tmp == nullptr) ::unsetenv("TMPDIR"); else ::setenv("TMPDIR", saved.c_str(), 1);
    ASSERT_EQ(bag.imu_topics.size(), 1u);
    EXPECT_EQ(bag.imu_topics[0].samples.t_s, reference.imu_topics.at(0).samples.t_s);
    EXPECT_EQ(bag.messages, 80u);
    const std::vector<std::string> said = bag.warnings.Describe();
    ASSERT_EQ(said.size(), 1u) << said.front();
    EXPECT_NE(said[0].find(path + "-wal"), std::string::npos) << said[0];
    EXPECT_EQ(FilesIn(dir), (std::vector<std::string>{"bag.db3", "bag.db3-wal"}));
    EXPECT_EQ(FileBytes(path), bag_bytes);
    EXPECT_EQ(FileBytes(path + "-wal"), wal_bytes);
    EXPECT_TRUE(FilesIn(tmp).empty());
  }
  for (const auto& d : {dir, tmp, scratch}) std::filesystem::remove_all(d);
}

TEST(Db3Reader, AnSqliteFileWithoutTheTablesIsNotABag) {
  const std::string path = TempPath("other.db3");
  test::WriteDb3(path, {}, {}, false);
  EXPECT_EQ(SniffFlightLog(path), FlightLogFormat::kNone);
  EXPECT_THROW(ReadDb3(path), InputError);
  std::filesystem::remove(path);
}

TEST(Db3Reader, MalformedAndOrphanMessagesSaidByTheirId) {
  const std::string path = TempPath("bad.db3");
  std::vector<test::Db3Message> messages = Db3Imu(3);
  messages.push_back({1, static_cast<std::int64_t>(kReceiveNs), "\x00\x01\x00\x00"});
  messages.push_back({7, static_cast<std::int64_t>(kReceiveNs), "x"});
  test::WriteDb3(path, {{1, "/imu", "sensor_msgs/msg/Imu"}, {2, "/mag", "sensor_msgs/msg/MagneticField"}},
                 messages);
  const RosBag bag = ReadDb3(path);
  EXPECT_EQ(bag.warnings.malformed_imu, 1u);
  EXPECT_EQ(bag.warnings.orphan_messages, 1u);
  bool said = false;
  for (const std::string& w : bag.warnings.Describe()) {
    said = said || w.find("the message of id 7 (/imu)") != std::string::npos;
  }
  EXPECT_TRUE(said);
  EXPECT_EQ(bag.imu_topics.at(0).samples.size(), 3u);
  std::filesystem::remove(path);
}

TEST(Db3Reader, CutOrGarbageIsAnInputErrorOrAWarningNeverACrash) {
  const std::string path = TempPath("cut.db3");
  test::WriteDb3(path, {{1, "/imu", "sensor_msgs/msg/Imu"}}, Db3Imu(400));
  const std::string whole = FileBytes(path);
  for (std::size_t cut = 0; cut < whole.size(); cut += 512) {
    try {
      const RosBag bag =
          ParseDb3(reinterpret_cast<const std::uint8_t*>(whole.data()), cut, "cut.db3");
      (void)bag.warnings.Describe();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cut.db3"), std::string::npos);
    }
  }
  std::filesystem::remove(path);
}

// --- recognised by content ---------------------------------------------------------------

TEST(Ros2Sniff, McapIsRecognisedByContentWhateverItsName) {
  const std::string path = TempPath("named.bin");
  {
    std::ofstream out(path, std::ios::binary);
    out << ThreeChunks("zstd");
  }
  EXPECT_EQ(SniffFlightLog(path), FlightLogFormat::kRos2Mcap);
  EXPECT_TRUE(IsRosBag(FlightLogFormat::kRos2Mcap));
  EXPECT_TRUE(IsRosBag("ros2-db3"));
  EXPECT_FALSE(IsRosBag("px4-ulog"));
  const FlightLog log = FlightLog::Open(path);
  EXPECT_EQ(log.Summary().format, "ros2-mcap");
  FlightLogSelection pick;
  pick.receive_time = true;
  const Session s = log.Select(pick);
  EXPECT_EQ(s.series.size(), 120u);
  EXPECT_EQ(s.series.t_s[0], 1700000000.0 + 123456789 * 1e-9);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace plumb::io

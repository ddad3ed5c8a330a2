// The .ulg reader in two parts (ULogReadOptions, split_read.h): the log is the one the
// reader gives in one part, to the byte (formats, subscriptions, counts, last timestamps, kept
// bodies, decoded sensor_combined samples, info, parameters and their changes, texts, sync and
// dropout counts, warnings), wherever the second part's start is looked for: before and after
// the messages it reads besides data (parameter changes, whose timestamps come from both parts,
// default parameters, info, continued info, late subscriptions and their data, a format
// defined late) and those it stops at (a subscription whose id is taken or whose format is
// unknown, an info continuing nothing, a D of an id never subscribed, an unknown type, corrupt
// bytes, a cut last message), in the middle of a blob whose bytes look like messages (not
// joined: the first part goes on), times that spike, go back and repeat on either side; a log with appended data (one part); every
// shared .ulg through ReadULog, jobs run in either order or at once.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "io_test_util.h"
#include "plumb/io/px4/px4_session.h"
#include "plumb/io/px4/ulog.h"
#include "support/reverse_jobs.h"
#include "support/split_read_testing.h"
#include "support/ulog_log_difference.h"
#include "ulog_builder.h"

namespace plumb::io {
namespace {

using testing::Bytes;
using testing::Cat;
using testing::Le;
using testing::Writer;

/// Every part of two decoded logs the same (ULogDifference).
void ExpectSameLog(const ULog& one, const ULog& two) {
  EXPECT_EQ(plumb::testing::ULogDifference(one, two), "");
}

using plumb::testing::InOrder;
using plumb::testing::TwoParts;

/// InOrder counting in `joins` the joins of a decoded topic's samples (AppendSamples, whose
/// four columns are the only four jobs run at once in a read).
JobRunner CountingJoins(std::size_t* joins) { return plumb::testing::CountingCalls(4, joins); }

/// A sensor_combined message of the PX4 layout (with its trailing padding when `padded`).
Bytes Combined(std::uint64_t t_us, int n, bool padded) {
  Bytes b = Le(t_us);
  for (int k = 0; k < 3; ++k) b = Cat({b, Le(0.5f * static_cast<float>(n % 17 + k) - 2.0f)});
  b = Cat({b, Le<std::uint32_t>(4000), Le<std::int32_t>(0)});
  for (int k = 0; k < 3; ++k) b = Cat({b, Le(9.0f + 0.01f * static_cast<float>(n % 29 + k))});
  b = Cat({b, Le<std::uint32_t>(4000), Bytes{0}});
  if (padded) b = Cat({b, Bytes{0, 0, 0}});
  return b;
}

/// Writes the formats of sensor_combined (PX4's layout), sensor_accel and vehicle_status.
void CombinedFormats(Writer& w) {
  w.Format("sensor_combined:uint64_t timestamp;float[3] gyro_rad;uint32_t gyro_integral_dt;"
           "int32_t accelerometer_timestamp_relative;float[3] accelerometer_m_s2;"
           "uint32_t accelerometer_integral_dt;uint8_t accelerometer_clipping;"
           "uint8_t[3] _padding0;");
  w.Format("sensor_accel:uint64_t timestamp;float x;float y;float z;");
  w.Format("vehicle_status:uint64_t timestamp;uint8_t nav_state;");
}

/// The formats of sensor_combined (PX4's layout), sensor_accel and vehicle_status, and
/// sensor_combined subscribed as msg_id 0: the start of a made-up log for the cases at the
/// edge of what the second part decides.
Writer CombinedLog() {
  Writer w;
  CombinedFormats(w);
  w.Add(0, 0, "sensor_combined");
  return w;
}

/// A log with what the join must get right near any of its bytes (see the file comment).
/// `definitions_end`: the offset where its data section starts.
Bytes SeamLog(std::size_t* definitions_end) {
  Writer w;
  w.Message('B', Bytes(40, 0));
  CombinedFormats(w);
  w.Format("late_topic:uint64_t timestamp;float v;");
  w.Format("blob:uint64_t timestamp;uint8_t[224] bytes;");
  w.KeyValue('I', "char[3] sys_name", Bytes{'P', 'X', '4'});
  w.KeyValue('P', "float CAL_ACC0_XOFF", Le(0.25f));
  w.Add(0, 0, "sensor_combined");
  w.Add(0, 1, "sensor_accel");
  w.Add(0, 2, "vehicle_status");
  w.Add(0, 4, "blob");
  *definitions_end = w.bytes().size();
  std::uint64_t t = 1000;
  for (int n = 0; n < 900; ++n) {
    // Mostly rising by 1 ms; now and then a step back, a repeat; near the end a spike far
    // ahead (the samples after it are all dropped).
    std::uint64_t time = t;
    if (n == 850) time = t + 90000000;
    if (n % 53 == 7) time = t - 3500;
    if (n % 41 == 9) time = t - 1000;
    w.Data(0, Combined(time, n, n % 13 != 4));
    if (n % 3 == 0) w.Data(1, Cat({Le(time + 7), Le(1.0f * n), Le(2.0f), Le(3.0f)}));
    if (n % 5 == 0) w.Data(2, Cat({Le(time), Bytes{static_cast<std::uint8_t>(n % 7)}}));
    if (n % 7 == 0) w.Message('L', Cat({Bytes{'6'}, Le(time), Bytes{'h', 'i'}}));
    if (n % 11 == 0) w.Message('C', Cat({Bytes{'4'}, Le<std::uint16_t>(3), Le(time), Bytes{'x'}}));
    if (n % 50 == 0) w.Message('S', Bytes{0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12});
    if (n % 60 == 0) w.Message('O', Le<std::uint16_t>(static_cast<std::uint16_t>(n)));
    if (n == 300) w.KeyValue('P', "float CAL_ACC0_XOFF", Le(0.5f));
    if (n == 800) w.Add(0, 3, "late_topic");
    if (n > 800 && n % 4 == 0) w.Data(3, Cat({Le(time), Le(0.5f)}));
    if (n == 820) w.Add(1, 3, "late_topic");                       // msg_id taken
    if (n == 830) w.Add(0, 7, "no_such_format");                   // not resolved
    if (n == 840) w.Format("late_two:uint64_t timestamp;double w;");
    if (n == 845) w.Add(0, 8, "late_two");
    if (n > 845 && n % 3 == 0) w.Data(8, Cat({Le(time), Le(0.25)}));
    if (n == 870 || n == 100 || n == 600) w.KeyValue('P', "int32_t COM_X", Le<std::int32_t>(n));
    if (n == 460) w.KeyValue('M', "char[2] perf", Bytes{'e', 'f'}, 1);  // continues 450's
    if (n == 470) w.KeyValue('M', "char[2] other", Bytes{'g', 'h'}, 1);  // continues nothing
    if (n == 400) w.KeyValue('I', "char[3] ver", Bytes{'1', '.', '2'});
    if (n == 450) w.KeyValue('M', "char[2] perf", Bytes{'a', 'b'}, 0);
    if (n == 500) w.Data(9, Le(time));                             // never subscribed
    if (n == 600) w.Raw("\x01\x00\x07\xFF\x00", 5);              // corrupt bytes
    if (n == 650) w.Message('Z', Bytes{1, 2, 3});                  // an unknown type
    if (n == 700) w.Message('R', Le<std::uint16_t>(2));
    if (n == 750) w.KeyValue('Q', "float CAL_ACC0_XOFF", Le(0.0f), 1);
    if (n % 90 == 45) {  // a blob whose bytes are 16 D messages of vehicle_status, its time
                         // ahead of the others' (the newest of a parameter change's topics)
      Bytes fake;
      for (int k = 0; k < 16; ++k) {
        fake = Cat({fake, Le<std::uint16_t>(11), Bytes{'D'}, Le<std::uint16_t>(2), Le(time),
                    Bytes{1}});
      }
      w.Data(4, Cat({Le(time + 50000000), fake}));
    }
    t += 1000;
  }
  w.Data(0, Combined(t, 1, true));
  Bytes& bytes = w.bytes();
  bytes.resize(bytes.size() - 20);
  return bytes;
}

TEST(ULogTwoParts, SameLogWhereverTheSecondPartStarts) {
  std::size_t definitions_end = 0;
  const Bytes log = SeamLog(&definitions_end);
  for (const RecordFilter& filter : {RecordFilter{}, Px4SessionTopics()}) {
    const ULog one = ParseULog(log.data(), log.size(), "seam.ulg", filter);
    ASSERT_EQ(one.warnings.truncated_records, 1u);
    ASSERT_GT(one.warnings.bytes_skipped, 0u);
    ASSERT_EQ(one.warnings.unknown_msg_id_messages, 1u);
    ASSERT_EQ(one.warnings.unknown_type_messages, 1u);
    ASSERT_EQ(one.param_changes.size(), 4u);
    ASSERT_EQ(one.warnings.malformed_messages, 1u);
    ASSERT_EQ(one.warnings.unresolved_subscriptions, 1u);
    ASSERT_NE(one.Find("late_two"), nullptr);
    ASSERT_GT(one.texts.size(), 200u);
    ASSERT_EQ(one.Find("sensor_combined")->imu_decoded, filter.decode != nullptr);
    if (filter.decode) ASSERT_GT(one.Find("sensor_combined")->imu.size(), 800u);
    std::size_t joins = 0;
    for (const std::size_t lead : {definitions_end - 40, definitions_end, definitions_end + 5000}) {
      for (int k = 0; k <= 1000; ++k) {
        const double at = k / 1000.0;
        SCOPED_TRACE(::testing::Message() << "lead " << lead << ", at " << at);
        ExpectSameLog(one, ParseULog(log.data(), log.size(), "seam.ulg", filter,
                                     TwoParts(lead, at, CountingJoins(&joins))));
        if (::testing::Test::HasFailure()) return;
      }
    }
    // With sensor_combined decoded, the starts before the late subscription join its samples
    // when the lead held every subscription (the others: a start inside a blob, or a second
    // part that stops at once).
    if (filter.decode) EXPECT_GT(joins, 1200u);
  }
}

/// The log in 3 to 16 parts at once (SplitReadOptions::parts; the starts at the multiples of
/// `second_part_at`), jobs in order and in reverse on two threads: the log read in one part,
/// with parts joined one after another and parts left to the first parser between them.
TEST(ULogTwoParts, SameLogInManyParts) {
  std::size_t definitions_end = 0;
  const Bytes log = SeamLog(&definitions_end);
  for (const RecordFilter& filter : {RecordFilter{}, Px4SessionTopics()}) {
    const ULog one = ParseULog(log.data(), log.size(), "seam.ulg", filter);
    std::size_t joins = 0;
    for (const int parts : {3, 5, 8, 16}) {
      for (int k = 1; k <= 40; ++k) {
        const double at = k / (40.0 * (parts - 1));
        SCOPED_TRACE(::testing::Message() << parts << " parts, at " << at);
        ULogReadOptions options = TwoParts(definitions_end, at, CountingJoins(&joins), parts);
        ExpectSameLog(one, ParseULog(log.data(), log.size(), "seam.ulg", filter, options));
        options.run_jobs = plumb::testing::ReverseOnTwoThreads;
        ExpectSameLog(one, ParseULog(log.data(), log.size(), "seam.ulg", filter, options));
        if (::testing::Test::HasFailure()) return;
      }
    }
    // sensor_combined's samples joined about six times a read (about 960 in all; fewer than
    // 800 when the first parser does not read on between the parts).
    if (filter.decode) EXPECT_GT(joins, 900u);
  }
}

/// The clock set back at the seam by less than the first part's last sample: the second
/// part's first kept samples are dropped in the join, as one part drops them.
TEST(ULogTwoParts, ClockSetBackAtTheSeamJoinsAsInOnePart) {
  Writer w = CombinedLog();
  const std::size_t lead = w.bytes().size();
  for (int n = 0; n < 2000; ++n) {
    const std::uint64_t time = n < 1000 ? 1000000 + 1000 * n : 1500000 + 1000 * (n - 1000);
    w.Data(0, Combined(time, n, true));
    if (n == 1500) w.KeyValue('P', "float X", Le(1.0f));
  }
  const Bytes& log = w.bytes();
  const ULog one = ParseULog(log.data(), log.size(), "seam.ulg", Px4SessionTopics());
  ASSERT_EQ(one.Find("sensor_combined")->imu.size(), 1500u);
  for (const double at : {0.25, 0.5, 0.6, 0.9}) {
    SCOPED_TRACE(at);
    std::size_t joins = 0;
    ExpectSameLog(one, ParseULog(log.data(), log.size(), "seam.ulg", Px4SessionTopics(),
                                 TwoParts(lead, at, CountingJoins(&joins))));
    EXPECT_EQ(joins, 1u);
    ExpectSameLog(one, ParseULog(log.data(), log.size(), "seam.ulg", Px4SessionTopics(),
                                 TwoParts(lead, at, plumb::testing::ReverseOnTwoThreads)));
  }
}


/// The first part subscribes a topic after the lead, the second part another under the same
/// msg_id (in one pass an id taken: malformed): the second part's subscription must not join.
TEST(ULogTwoParts, SubscriptionsOnBothSidesOfTheSeam) {
  Writer w = CombinedLog();
  const std::size_t lead = w.bytes().size();
  w.Add(0, 5, "sensor_accel");
  for (int n = 0; n < 40; ++n) w.Data(0, Combined(1000u * n, n, true));
  w.Add(1, 5, "vehicle_status");  // msg_id 5 taken
  for (int n = 40; n < 80; ++n) w.Data(0, Combined(1000u * n, n, true));
  w.Data(5, Cat({Le<std::uint64_t>(5), Le(1.0f), Le(2.0f), Le(3.0f)}));
  const Bytes& log = w.bytes();
  const ULog one = ParseULog(log.data(), log.size(), "seam.ulg");
  ASSERT_EQ(one.warnings.malformed_messages, 1u);
  for (int k = 1; k < 40; ++k) {
    SCOPED_TRACE(k);
    ExpectSameLog(one, ParseULog(log.data(), log.size(), "seam.ulg", {},
                                 TwoParts(lead, k / 100.0, InOrder)));
  }
}

/// Parameters after a run of sync messages and before any subscription or text are initial
/// values in one pass: a second part started in the run must not take them for changes.
TEST(ULogTwoParts, ParametersBeforeAnySubscriptionAreInitialValues) {
  Writer w = CombinedLog();
  w.bytes().resize(w.bytes().size() - (3 + 3 + 15));  // without the subscription
  w.KeyValue('P', "float A", Le(1.0f));
  const std::size_t lead = w.bytes().size();
  for (int n = 0; n < 60; ++n) w.Message('S', Bytes{0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12});
  w.KeyValue('P', "float B", Le(2.0f));
  w.Add(0, 0, "sensor_combined");
  w.KeyValue('P', "float C", Le(3.0f));
  const Bytes& log = w.bytes();
  const ULog one = ParseULog(log.data(), log.size(), "seam.ulg");
  ASSERT_EQ(one.params.size(), 2u);
  ASSERT_EQ(one.param_changes.size(), 1u);
  for (int k = 1; k < 60; ++k) {
    SCOPED_TRACE(k);
    ExpectSameLog(one, ParseULog(log.data(), log.size(), "seam.ulg", {},
                                 TwoParts(lead, k / 100.0, InOrder)));
  }
}

/// Appended data: its segments are read by one parser (no second part), the same log.
TEST(ULogTwoParts, AppendedDataIsReadInOnePart) {
  Writer w;
  w.Message('B', testing::AppendedDataFlagBits());
  w.Format("sensor_accel:uint64_t timestamp;float x;float y;float z;");
  w.Add(0, 1, "sensor_accel");
  const std::size_t flags_offsets = 16 + 3 + 16;
  for (int n = 0; n < 400; ++n) w.Data(1, Cat({Le<std::uint64_t>(n), Le(1.0f), Le(2.0f), Le(3.0f)}));
  const std::uint64_t appended = w.bytes().size() - 100;  // cuts a message: dropped, counted
  for (int n = 400; n < 800; ++n) {
    w.Data(1, Cat({Le<std::uint64_t>(n), Le(1.0f), Le(2.0f), Le(3.0f)}));
  }
  std::memcpy(w.bytes().data() + flags_offsets, &appended, sizeof(appended));
  const Bytes& log = w.bytes();
  const ULog one = ParseULog(log.data(), log.size(), "appended.ulg");
  ASSERT_TRUE(one.data_appended);
  for (const double at : {0.1, 0.5, 0.9}) {
    ExpectSameLog(one, ParseULog(log.data(), log.size(), "appended.ulg", {},
                                 TwoParts(200, at, InOrder)));
  }
}

/// ReadULog in two parts, jobs run one after another and at once in the other order, the
/// second part's start looked for at several places: the log read in one part.
TEST(ULogTwoParts, EverySharedUlgReadInTwoPartsAsInOne) {
  const std::string dir = testing::SharedLogPath("px4", "");
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "shared data absent: " << dir;
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".ulg") continue;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    ++files;
    for (const RecordFilter& filter : {RecordFilter{}, Px4SessionTopics()}) {
      const ULog one = ReadULog(path, filter);
      for (const double at : {0.0, 0.13, 0.5, 0.77, 0.999}) {
        SCOPED_TRACE(at);
        const JobRunner run_jobs =
            at == 0.5 ? JobRunner(plumb::testing::ReverseOnTwoThreads) : InOrder;
        ExpectSameLog(one, ReadULog(path, filter, TwoParts(256 << 10, at, run_jobs)));
        if (::testing::Test::HasFailure()) return;
      }
    }
  }
  EXPECT_GE(files, 2u);
}

}  // namespace
}  // namespace plumb::io

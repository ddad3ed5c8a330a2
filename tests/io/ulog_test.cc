// PX4 ULog reader (io/px4/ulog.h) and sessions (io/px4/px4_session.h): every .ulg under
// ../shared/data/px4 against golden data from an independent Python decoder
// (tests/data/px4/decode_golden.py, see README.md there), damaged copies of real logs, small
// hand-built logs for each message type and rule, and a session on a real still period.
#include <gtest/gtest.h>

#include <algorithm>
#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "io_test_util.h"
#include "ulog_builder.h"
#include "plumb/core/error.h"
#include "plumb/io/px4/px4_session.h"
#include "plumb/io/px4/ulog.h"

namespace plumb::io {
namespace {

using testing::Bytes;
using testing::Cat;
using testing::Le;
using testing::ReadBytes;
using testing::Writer;
std::string SharedLog(const std::string& name) {
  return testing::SharedLogPath("px4", name);
}
nlohmann::json ReadGolden(const std::string& name) {
  return testing::ReadGoldenJson("px4", name);
}


std::size_t Topics(const ULog& log, const std::string& name, int multi_id) {
  const ULogTopic* t = log.Find(name, multi_id);
  return t == nullptr ? 0 : t->rows;
}

// Every input byte after the header is in a stored message, skipped, or in a dropped record,
// unless data was appended (the bytes cut by an appended offset are not accounted).
std::size_t BytesInMessages(const ULog& log) {
  std::size_t n = 0;
  for (const ULogTopic& t : log.topics) n += t.rows * (t.body_size + 5);
  return n;
}

// --- real logs against the golden JSON -------------------------------------------------------

void ExpectHeaderMatchesGolden(const ULog& log, const nlohmann::json& g) {
  EXPECT_EQ(log.size_bytes, g["size_bytes"].get<std::size_t>());
  EXPECT_EQ(log.version, g["version"].get<int>());
  EXPECT_EQ(log.start_timestamp_us, g["start_timestamp_us"].get<std::uint64_t>());
  EXPECT_EQ(log.data_appended, g["appended"].get<bool>());
  EXPECT_EQ(log.appended_offsets, g["appended_offsets"].get<std::vector<std::uint64_t>>());
}

void ExpectCountsMatchGolden(const ULog& log, const nlohmann::json& g) {
  EXPECT_EQ(log.warnings.bytes_skipped, g["bytes_skipped"].get<std::size_t>());
  EXPECT_EQ(log.warnings.skip_runs, g["skip_runs"].get<std::size_t>());
  EXPECT_EQ(log.warnings.truncated_records, g["truncated_records"].get<std::size_t>());
  EXPECT_EQ(log.warnings.truncated_bytes, g["truncated_bytes"].get<std::size_t>());
  EXPECT_EQ(log.warnings.unknown_msg_id_messages, g["unknown_msg_id_messages"].get<std::size_t>());
  EXPECT_EQ(log.warnings.unknown_type_messages, g["unknown_type_messages"].get<std::size_t>());
  EXPECT_EQ(log.warnings.unresolved_subscriptions,
            g["unresolved_subscriptions"].get<std::size_t>());
  EXPECT_EQ(log.dropouts, g["dropouts"].get<std::size_t>());
  EXPECT_EQ(log.dropout_total_ms, g["dropout_total_ms"].get<std::uint64_t>());
  EXPECT_EQ(log.sync_messages, g["sync_messages"].get<std::size_t>());
  EXPECT_EQ(log.texts.size(), g["logging_messages"].get<std::size_t>());
  std::map<std::string, std::size_t> counts;
  for (const auto& [name, n] : log.MessageCounts()) counts[name] += n;
  std::map<std::string, std::size_t> expected;
  for (const auto& [name, n] : g["topic_counts"].items()) expected[name] = n.get<std::size_t>();
  EXPECT_EQ(counts, expected);
}

void ExpectParamsMatchGolden(const ULog& log, const nlohmann::json& g) {
  EXPECT_EQ(log.params.size(), g["param_count"].get<std::size_t>());
  EXPECT_EQ(log.param_changes.size(), g["param_changes"].get<std::size_t>());
  EXPECT_EQ(log.default_params.size(), g["default_params"].get<std::size_t>());
  for (const auto& [name, value] : g["params"].items()) {
    ASSERT_TRUE(log.params.count(name)) << name;
    EXPECT_EQ(log.params.at(name), value.get<double>()) << name;
  }
  for (const auto& [key, value] : g["info"].items()) {
    ASSERT_TRUE(log.info.count(key)) << key;
    EXPECT_EQ(log.info.at(key), value.get<std::string>()) << key;
  }
}

// Every field the golden lists, of row `row`, equals the decoded value exactly.
void ExpectRowEq(const ULogTopic& t, std::size_t row, const nlohmann::json& fields) {
  for (const auto& [name, value] : fields.items()) {
    const int c = t.ColumnIndex(name);
    ASSERT_GE(c, 0) << t.name << "." << name;
    EXPECT_EQ(t.Value(row, static_cast<std::size_t>(c)), value.get<double>())
        << t.name << "/" << t.multi_id << " row " << row << " " << name;
  }
}

void ExpectSamplesMatchGolden(const ULog& log, const nlohmann::json& g) {
  for (const auto& [key, s] : g["imu_samples"].items()) {
    const std::string name = key.substr(0, key.find('/'));
    const int multi_id = std::stoi(key.substr(key.find('/') + 1));
    const ULogTopic* t = log.Find(name, multi_id);
    ASSERT_NE(t, nullptr) << key;
    ASSERT_EQ(t->rows, s["count"].get<std::size_t>()) << key;
    ExpectRowEq(*t, 0, s["first"]);
    ExpectRowEq(*t, t->rows - 1, s["last"]);
  }
}

void ExpectGpsMatchesGolden(const ULog& log, const nlohmann::json& g) {
  const nlohmann::json& fix = g["gps_first_fix"];
  if (fix.is_null()) {
    EXPECT_FALSE(SiteFromULog(log).has_value());
    return;
  }
  const ULogTopic* t = log.Find(fix["topic"].get<std::string>(), fix["multi_id"].get<int>());
  ASSERT_NE(t, nullptr);
  const int fix_col = t->ColumnIndex("fix_type");
  ASSERT_GE(fix_col, 0);
  std::size_t row = 0;
  while (row < t->rows && t->Value(row, static_cast<std::size_t>(fix_col)) < 3) ++row;
  ASSERT_LT(row, t->rows);
  nlohmann::json fields = fix;
  fields.erase("topic");
  fields.erase("multi_id");
  ExpectRowEq(*t, row, fields);
  ASSERT_TRUE(SiteFromULog(log).has_value());
}

class ULogRealLog : public ::testing::TestWithParam<const char*> {};

TEST_P(ULogRealLog, MatchesIndependentDecoder) {
  const std::string path = SharedLog(GetParam());
  PLUMB_SKIP_IF_ABSENT(path);
  const nlohmann::json golden = ReadGolden(GetParam());
  const ULog log = ReadULog(path);
  ExpectHeaderMatchesGolden(log, golden);
  ExpectCountsMatchGolden(log, golden);
  ExpectParamsMatchGolden(log, golden);
  ExpectSamplesMatchGolden(log, golden);
  ExpectGpsMatchesGolden(log, golden);
  EXPECT_FALSE(log.warnings.any());
}

INSTANTIATE_TEST_SUITE_P(AllUlg, ULogRealLog,
                         ::testing::Values("sample.ulg", "sample_log_small.ulg",
                                           "sample_appended_multiple.ulg",
                                           "sample_logging_tagged_and_default_params.ulg",
                                           "sample_px4_events.ulg"));

TEST(ULog, TaggedLoggingDefaultParamsAndLooksLike) {
  const std::string path = SharedLog("sample_logging_tagged_and_default_params.ulg");
  PLUMB_SKIP_IF_ABSENT(path);
  const ULog log = ReadULog(path);
  bool tagged = false;
  for (const ULogText& t : log.texts) tagged = tagged || t.tag >= 0;
  EXPECT_TRUE(tagged);
  ASSERT_FALSE(log.default_params.empty());
  EXPECT_NE(log.default_params.front().default_types, 0);
  EXPECT_TRUE(LooksLikeULog(path));
  EXPECT_FALSE(LooksLikeULog(std::string(PLUMB_SOURCE_DIR) + "/tests/data/px4/sample.ulg.golden.json"));
}

// --- damaged copies of real logs -------------------------------------------------------------

// Rows of the damaged log's topics are a prefix of the intact log's, topic by topic.
void ExpectPrefixOf(const ULog& part, const ULog& whole) {
  for (const ULogTopic& t : part.topics) {
    const ULogTopic* w = whole.Find(t.name, t.multi_id);
    ASSERT_NE(w, nullptr) << t.name;
    ASSERT_LE(t.rows, w->rows) << t.name;
    for (std::size_t r = 0; r < t.rows && t.bodies_kept; ++r) {
      ASSERT_EQ(std::memcmp(t.bodies.Row(r), w->bodies.Row(r), t.body_size), 0) << t.name << r;
    }
  }
}

TEST(ULog, EveryTruncationDecodesItsPrefix) {
  const std::string path = SharedLog("sample_log_small.ulg");
  PLUMB_SKIP_IF_ABSENT(path);
  const Bytes full = ReadBytes(path);
  const ULog whole = ParseULog(full.data(), full.size(), path);
  std::mt19937_64 rng(20240611);
  std::uniform_int_distribution<std::size_t> length(16, full.size());
  for (int trial = 0; trial < 60; ++trial) {
    const std::size_t cut = length(rng);
    const ULog part = ParseULog(full.data(), cut, "cut");
    EXPECT_EQ(part.warnings.bytes_skipped, 0u) << "cut " << cut;
    EXPECT_LE(part.warnings.truncated_records, 1u) << "cut " << cut;
    EXPECT_LE(BytesInMessages(part) + part.warnings.truncated_bytes, cut) << "cut " << cut;
    ExpectPrefixOf(part, whole);
  }
  const ULog half = ParseULog(full.data(), full.size() / 2 + 3, "half");
  EXPECT_EQ(half.warnings.truncated_records, 1u);
  EXPECT_GT(Topics(half, "sensor_combined", 0), Topics(whole, "sensor_combined", 0) / 3);
}

TEST(ULog, GarbledCopyResynchronisesAndCountsSkippedBytes) {
  const std::string path = SharedLog("sample_log_small.ulg");
  PLUMB_SKIP_IF_ABSENT(path);
  const Bytes clean = ReadBytes(path);
  const ULog whole = ParseULog(clean.data(), clean.size(), path);
  Bytes garbled = clean;
  std::mt19937_64 rng(42);
  // Leave the first 200 KiB (definitions and subscriptions) intact, garble 100 bytes after.
  std::uniform_int_distribution<std::size_t> where(200000, garbled.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int k = 0; k < 100; ++k) garbled[where(rng)] = static_cast<std::uint8_t>(byte(rng));
  const ULog log = ParseULog(garbled.data(), garbled.size(), "garbled");
  EXPECT_GT(log.warnings.bytes_skipped, 0u);
  EXPECT_GT(log.warnings.skip_runs, 0u);
  EXPECT_GE(log.warnings.first_skip_offset, 200000u);
  EXPECT_FALSE(log.warnings.Describe().empty());
  EXPECT_GT(Topics(log, "sensor_combined", 0), Topics(whole, "sensor_combined", 0) * 8 / 10);
  const Session s = ULogSession(log, FlightLogSelection{});
  EXPECT_GT(s.series.size(), Topics(whole, "sensor_combined", 0) * 8 / 10);
}

// The damaged copy decode_golden.py --damaged makes (XOR 0x5A at the type bytes of an F, a P
// and an A header, and at 70000 + 97001 k): both decoders must resynchronise alike, in the
// definitions section (on chains of valid headers) and in the data section.
TEST(ULog, DamagedCopyMatchesIndependentDecoder) {
  const std::string path = SharedLog("sample_log_small.ulg");
  PLUMB_SKIP_IF_ABSENT(path);
  Bytes data = ReadBytes(path);
  for (std::size_t offset : {std::size_t{5202}, std::size_t{30012}, std::size_t{61026}}) {
    data[offset] ^= 0x5A;
  }
  for (std::size_t offset = 70000; offset < data.size(); offset += 97001) data[offset] ^= 0x5A;
  const nlohmann::json g = ReadGolden("sample_log_small.ulg.damaged");
  const ULog log = ParseULog(data.data(), data.size(), "damaged");
  ExpectCountsMatchGolden(log, g);
  EXPECT_EQ(log.warnings.first_skip_offset, g["first_skip_offset"].get<std::size_t>());
  EXPECT_EQ(log.params.size(), g["param_count"].get<std::size_t>());
  EXPECT_EQ(log.formats.size(), g["format_count"].get<std::size_t>());
  EXPECT_GT(log.warnings.bytes_skipped, 0u);
}

// Flips bits anywhere (header and definitions included), then runs everything the CLI runs.
TEST(ULog, BitFlippedLogsNeverCrash) {
  const std::string path = SharedLog("sample_appended_multiple.ulg");
  PLUMB_SKIP_IF_ABSENT(path);
  const Bytes clean = ReadBytes(path);
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::size_t> where(0, clean.size() - 1);
  std::uniform_int_distribution<int> bit(0, 7);
  int parsed = 0;
  for (int trial = 0; trial < 40; ++trial) {
    Bytes damaged = clean;
    for (int k = 0; k < 200; ++k) damaged[where(rng)] ^= static_cast<std::uint8_t>(1u << bit(rng));
    try {
      const ULog log = ParseULog(damaged.data(), damaged.size(), "flipped");
      ++parsed;
      for (const ImuStreamInfo& info : ULogImuStreams(log)) {
        FlightLogSelection sel;
        sel.imu = info.instance;
        sel.stream = info.name;
        try {
          ULogSession(log, sel);
        } catch (const Error&) {
        }
      }
      SiteFromULog(log);
    } catch (const Error&) {
      // a clean error (e.g. the magic hit) is fine; a crash is not
    }
  }
  EXPECT_GT(parsed, 20);
}

// --- hand-built logs ---------------------------------------------------------------------------

ULog Parse(Writer& w) { return ParseULog(w.bytes().data(), w.bytes().size(), "built"); }

// One "imu" message: timestamp, a nested vec3 with an inner pad, an int16 array, trailing pad.
Bytes ImuBody(std::uint64_t t_us, float x, std::int16_t c0, bool with_trailing_pad) {
  Bytes b = Cat({Le(t_us), Le(x), Le(2.0f), Le(3.0f), Bytes{0xEE}, Le(c0), Le<std::int16_t>(-7),
                 Bytes{1}});
  if (with_trailing_pad) b.insert(b.end(), {0xAA, 0xAA, 0xAA});
  return b;
}

Writer ImuLog() {
  Writer w(0);
  w.Format("vec3:float x;float y;float z;uint8_t[1] _padding0;");
  w.Format("imu:uint64_t timestamp;vec3 v;int16_t[2] counts;bool ok;uint8_t[3] _padding0;");
  w.KeyValue('I', "char[3] sys_name", Bytes{'P', 'X', '4'});
  w.KeyValue('P', "float CAL_ACC0_XOFF", Le(0.25f));
  w.KeyValue('P', "int32_t CAL_ACC0_ID", Le<std::int32_t>(42));
  w.KeyValue('Q', "float CAL_ACC0_XOFF", Le(0.0f), 3);
  w.KeyValue('M', "char[2] perf", Bytes{'a', 'b'}, 0);
  w.KeyValue('M', "char[2] perf", Bytes{'c', 'd'}, 1);
  w.Add(2, 5, "imu");
  return w;
}

TEST(ULogBuilt, NestedArraysPaddingAndEveryMessageType) {
  Writer w = ImuLog();
  w.Data(5, ImuBody(2000, 1.5f, 100, false));  // trailing padding not logged
  w.Data(5, ImuBody(3000, 2.5f, 200, true));   // with it
  w.Message('O', Le<std::uint16_t>(30));
  w.Message('S', Bytes{0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12});
  w.Message('L', Cat({Bytes{'6'}, Le<std::uint64_t>(2500), Bytes{'h', 'i'}}));
  w.Message('C', Cat({Bytes{'4'}, Le<std::uint16_t>(9), Le<std::uint64_t>(2600), Bytes{'x'}}));
  w.KeyValue('P', "float CAL_ACC0_XOFF", Le(0.5f));  // a change in the data section
  w.Message('Z', Bytes{1, 2, 3});                     // a future message type
  w.Data(77, Bytes{1, 2, 3});                         // never subscribed
  const ULog log = Parse(w);
  EXPECT_EQ(log.version, 0);
  EXPECT_EQ(log.start_timestamp_us, 1000u);
  EXPECT_EQ(log.info.at("sys_name"), "PX4");
  EXPECT_EQ(log.info_multiple.at("perf"), std::vector<std::string>{"abcd"});
  EXPECT_EQ(log.params.at("CAL_ACC0_XOFF"), 0.25);
  EXPECT_EQ(log.params.at("CAL_ACC0_ID"), 42.0);
  ASSERT_EQ(log.param_changes.size(), 1u);
  EXPECT_EQ(log.param_changes[0].value, 0.5);
  EXPECT_EQ(log.param_changes[0].timestamp_us, 3000u);
  ASSERT_EQ(log.default_params.size(), 1u);
  EXPECT_EQ(log.default_params[0].default_types, 3);
  EXPECT_EQ(log.dropouts, 1u);
  EXPECT_EQ(log.dropout_total_ms, 30u);
  EXPECT_EQ(log.sync_messages, 1u);
  ASSERT_EQ(log.texts.size(), 2u);
  EXPECT_EQ(log.texts[0].text, "hi");
  EXPECT_EQ(log.texts[1].tag, 9);
  EXPECT_EQ(log.warnings.unknown_type_messages, 1u);
  EXPECT_EQ(log.warnings.unknown_msg_id_messages, 1u);
  EXPECT_EQ(log.warnings.bytes_skipped, 0u);

  const ULogTopic* t = log.Find("imu", 2);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->body_size, 8u + 13u + 4u + 1u);
  EXPECT_EQ(t->full_size, t->body_size + 3u);
  ASSERT_EQ(t->rows, 2u);
  std::vector<std::string> names;
  for (const ULogColumn& c : t->columns) names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"timestamp", "v.x", "v.y", "v.z", "counts[0]",
                                             "counts[1]", "ok"}));
  EXPECT_EQ(t->columns[static_cast<std::size_t>(t->ColumnIndex("counts[0]"))].offset, 21u);
  EXPECT_EQ(t->TimestampUs(1), 3000u);
  EXPECT_EQ(t->Column("v.x"), (std::vector<double>{1.5, 2.5}));
  EXPECT_EQ(t->Column("counts[0]"), (std::vector<double>{100, 200}));
  EXPECT_EQ(t->Column("counts[1]"), (std::vector<double>{-7, -7}));
  EXPECT_EQ(t->Column("ok"), (std::vector<double>{1, 1}));
  EXPECT_THROW(t->Column("nope"), Error);
}

TEST(ULogBuilt, CorruptHeaderResyncsOnTheNextValidMessage) {
  Writer w = ImuLog();
  w.Data(5, ImuBody(2000, 1.5f, 1, false));
  w.bytes().insert(w.bytes().end(), {0x00, 0x00, 0x01, 0x02, 0x03});  // 5 garbage bytes
  w.Data(5, ImuBody(3000, 2.5f, 2, false));
  // A D message of the right id but a wrong size is corrupt too: its 3 + 6 bytes are skipped.
  w.Data(5, Bytes{1, 2, 3, 4});
  w.Data(5, ImuBody(4000, 3.5f, 3, false));
  const ULog log = Parse(w);
  EXPECT_EQ(log.warnings.bytes_skipped, 5u + 9u);
  EXPECT_EQ(log.warnings.skip_runs, 2u);
  EXPECT_EQ(log.Find("imu", 2)->Column("counts[0]"), (std::vector<double>{1, 2, 3}));
}

TEST(ULogBuilt, TruncatedLastMessageIsCountedAndDropped) {
  Writer w = ImuLog();
  w.Data(5, ImuBody(2000, 1.5f, 1, false));
  w.Data(5, ImuBody(3000, 2.5f, 2, false));
  const std::size_t whole = w.bytes().size();
  const ULog log = ParseULog(w.bytes().data(), whole - 4, "cut");
  EXPECT_EQ(log.warnings.truncated_records, 1u);
  EXPECT_EQ(log.warnings.truncated_bytes, 3u + 2u + 26u - 4u);
  EXPECT_EQ(log.Find("imu", 2)->rows, 1u);
}

TEST(ULogBuilt, AppendedSegmentsFollowTheFlagBitsOffsets) {
  Writer w;
  w.Message('B', testing::AppendedDataFlagBits());
  w.Format("t:uint64_t timestamp;float v;");
  w.Add(0, 0, "t");
  w.Data(0, Cat({Le<std::uint64_t>(1), Le(1.0f)}));
  w.Data(0, Cat({Le<std::uint64_t>(2), Le(2.0f)}));
  w.bytes().resize(w.bytes().size() - 5);  // the regular log stops mid-message
  const std::uint64_t offset = w.bytes().size();
  std::memcpy(w.bytes().data() + 16 + 3 + 16, &offset, 8);
  w.Data(0, Cat({Le<std::uint64_t>(3), Le(3.0f)}));  // appended data
  const ULog log = Parse(w);
  EXPECT_TRUE(log.data_appended);
  EXPECT_EQ(log.appended_offsets, std::vector<std::uint64_t>{offset});
  EXPECT_EQ(log.Find("t", 0)->Column("v"), (std::vector<double>{1.0, 3.0}));
  EXPECT_EQ(log.warnings.truncated_records, 1u);
  EXPECT_EQ(log.warnings.bytes_skipped, 0u);
}

TEST(ULogBuilt, UnresolvableFormatsAreCountedNotAllocated) {
  Writer w;
  w.Format("big:uint64_t timestamp;double[65535] x;");  // larger than a D message can hold
  w.Format("loop_a:loop_b inner;");
  w.Format("loop_b:loop_a inner;");
  w.Format("orphan:missing_type m;");
  w.Format("no colon here");
  w.Add(0, 0, "big");
  w.Add(0, 1, "loop_a");
  w.Add(0, 2, "orphan");
  w.Data(0, Bytes{1, 2, 3});
  const ULog log = Parse(w);
  EXPECT_EQ(log.warnings.unresolved_subscriptions, 3u);
  EXPECT_EQ(log.warnings.malformed_messages, 1u);
  EXPECT_EQ(log.warnings.unknown_msg_id_messages, 1u);
  EXPECT_TRUE(log.topics.empty());
}

// A binary tree of nested formats: t14 flattens to 32768 columns. Subscribing it 100 times
// in a 2 KB input must stop at the column budget (input bytes + 65536), quickly.
TEST(ULogBuilt, NestedFanOutIsBoundedByTheColumnBudget) {
  Writer w;
  w.Format("t0:uint8_t a;uint8_t b;");
  for (int k = 1; k <= 15; ++k) {
    const std::string inner = "t" + std::to_string(k - 1);
    w.Format("t" + std::to_string(k) + ":" + inner + " a;" + inner + " b;");
  }
  for (std::uint16_t id = 0; id < 100; ++id) w.Add(0, id, "t14");
  w.Add(0, 100, "t15");  // 65536 bytes: larger than a D message
  const ULog log = Parse(w);
  EXPECT_EQ(log.topics.size(), 2u);
  EXPECT_EQ(log.topics[0].columns.size(), 32768u);
  EXPECT_EQ(log.topics[0].columns.back().name, "b.b.b.b.b.b.b.b.b.b.b.b.b.b.b");
  EXPECT_EQ(log.warnings.unresolved_subscriptions, 99u);
}

TEST(ULogBuilt, BadHeadersAndUnknownIncompatibleBitsThrow) {
  const Bytes short_input = {'U', 'L', 'o', 'g'};
  EXPECT_THROW(ParseULog(short_input.data(), short_input.size(), "short"), InputError);
  Writer wrong;
  wrong.bytes()[1] = 'X';
  EXPECT_THROW(Parse(wrong), InputError);
  Writer future;
  Bytes flags(40, 0);
  flags[8] = 2;  // an incompatible bit this reader does not know
  future.Message('B', flags);
  EXPECT_THROW(Parse(future), InputError);
  Writer newer(7);
  EXPECT_TRUE(Parse(newer).warnings.unknown_version);
}

/// sensor_combined decoded in the reader's pass (Px4SessionTopics) against decoded from kept
/// bodies: times going back, repeated, NaN-free but huge values (saturated to float), a
/// corrupt message and a cut last one give the same samples.
TEST(ULogBuilt, SensorCombinedDecodedInThePassAsFromBodies) {
  Writer w(1);
  w.Format("sensor_combined:uint64_t timestamp;float[3] gyro_rad;uint32_t gyro_integral_dt;"
           "double[3] accelerometer_m_s2;uint8_t[4] _padding0;");
  w.Add(0, 3, "sensor_combined");
  const std::uint64_t times[] = {1000, 2000, 1500, 3000, 3000, 4000, 90000000, 5000, 6000};
  for (std::size_t k = 0; k < std::size(times); ++k) {
    const double big = k == 4 ? 1e300 : 9.8 + static_cast<double>(k);
    w.Data(3, Cat({Le(times[k]), Le(0.1f * static_cast<float>(k)), Le(-0.2f), Le(0.3f),
                   Le<std::uint32_t>(4000), Le(big), Le(-big), Le(0.5)}));
    if (k == 5) w.bytes().insert(w.bytes().end(), {0x07, 0x00, 0x44});  // a corrupt header
  }
  w.bytes().resize(w.bytes().size() - 5);  // the last message cut
  const Bytes& b = w.bytes();
  const ULog all = ParseULog(b.data(), b.size(), "built");
  const ULog kept = ParseULog(b.data(), b.size(), "built", Px4SessionTopics());
  const ULogTopic* t = kept.Find("sensor_combined");
  ASSERT_NE(t, nullptr);
  EXPECT_TRUE(t->imu_decoded);
  EXPECT_EQ(t->rows, all.Find("sensor_combined")->rows);
  EXPECT_EQ(kept.warnings.Describe(), all.warnings.Describe());
  const std::vector<ImuStreamInfo> a = ULogImuStreams(all);
  const std::vector<ImuStreamInfo> k = ULogImuStreams(kept);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(k.size(), 1u);
  EXPECT_EQ(a[0].samples, k[0].samples);
  EXPECT_LT(a[0].samples, std::size(times) - 2);  // the rule dropped some
  const Session sa = ULogSession(all, FlightLogSelection{});
  const Session sk = ULogSession(kept, FlightLogSelection{});
  EXPECT_EQ(sa.series.t_s, sk.series.t_s);
  EXPECT_EQ(sa.series.acc, sk.series.acc);
  EXPECT_EQ(sa.series.gyr, sk.series.gyr);
  // Issue 35 item 7: the samples left out are counted and said, the same either way (a time
  // going back was dropped without a word; the message 90 s ahead is lost to the corrupt
  // header before it). The rule keeps a time below the next record's, so 2000 before the
  // 1500 that steps back goes, and the first of two 3000s.
  EXPECT_EQ(sk.series.t_s, (std::vector<double>{0.001, 0.0015, 0.003, 0.004, 0.005}));
  for (const Session* s : {&sa, &sk}) {
    const std::string dropped =
        "sensor_combined of IMU instance 0: left out 2 of 7 records by their time (not finite, "
        "not above the last kept one, or a spike above the next record's: a corrupt or "
        "backwards time stamp); the first with time 0.002000 s";
    const std::vector<std::string> said = Messages(s->warnings);
    EXPECT_EQ(std::count(said.begin(), said.end(), dropped), 1) << ::testing::PrintToString(said);
    for (const Notice& n : s->warnings) {
      if (n.message == dropped) EXPECT_EQ(n.code, "records_dropped");
    }
  }
}

// One time stamp far ahead (5e12 s in a real log) hid every later sample when a sample was
// kept for being above the last kept one alone: now it costs that one sample.
TEST(ULogBuilt, OneStampFarAheadCostsOneSample) {
  Writer w(1);
  w.Format("sensor_combined:uint64_t timestamp;float[3] gyro_rad;uint32_t gyro_integral_dt;"
           "float[3] accelerometer_m_s2;");
  w.Add(0, 3, "sensor_combined");
  for (std::uint64_t k = 0; k < 100; ++k) {
    const std::uint64_t t = k == 40 ? std::uint64_t{5000000000000000000} : 1000 + 4000 * k;
    w.Data(3, Cat({Le(t), Le(0.0f), Le(0.0f), Le(0.0f), Le<std::uint32_t>(4000), Le(0.0f),
                   Le(0.0f), Le(-9.8f)}));
  }
  const Bytes& b = w.bytes();
  for (const ULog& log : {ParseULog(b.data(), b.size(), "built"),
                          ParseULog(b.data(), b.size(), "built", Px4SessionTopics())}) {
    const Session s = ULogSession(log, FlightLogSelection{});
    EXPECT_EQ(s.series.size(), 99u);
    EXPECT_DOUBLE_EQ(s.series.t_s.back(), (1000 + 4000 * 99) * 1e-6);
    const std::vector<ImuStreamInfo> info = ULogImuStreams(log);
    ASSERT_EQ(info.size(), 1u);
    EXPECT_EQ(info[0].records, 100u);
    EXPECT_EQ(info[0].samples, 99u);
    const std::vector<std::string> said = Messages(s.warnings);
    EXPECT_NE(std::find(said.begin(), said.end(),
                        "sensor_combined of IMU instance 0: left out 1 of 100 records by their time "
                        "(not finite, not above the last kept one, or a spike above the next "
                        "record's: a corrupt or backwards time stamp); the first with time "
                        "5000000000000.000000 s"),
              said.end())
        << ::testing::PrintToString(said);
  }
}

// --- sessions ---------------------------------------------------------------------------------

double MeanNorm(const std::vector<Vec3f>& v) {
  double sum = 0.0;
  for (const Vec3f& x : v) sum += x.cast<double>().norm();
  return sum / static_cast<double>(v.size());
}

TEST(ULogSession, SampleUlgStillPeriodAfterUndoingTheCalibration) {
  const std::string path = SharedLog("sample.ulg");
  PLUMB_SKIP_IF_ABSENT(path);
  const ULog log = ReadULog(path);
  const std::vector<ImuStreamInfo> streams = ULogImuStreams(log);
  ASSERT_EQ(streams.size(), 1u);
  EXPECT_EQ(streams[0].name, "sensor_combined");
  EXPECT_NEAR(streams[0].rate_hz, 250.0, 5.0);
  EXPECT_TRUE(streams[0].undoable);
  EXPECT_NE(streams[0].applied.find("CAL_ACC0"), std::string::npos);

  // The first minute is still except for a bump 3-7 s after the start: keep 8 s .. 60 s.
  FlightLogSelection still;
  still.from_s = streams[0].t_start_s + 8.0;
  still.to_s = streams[0].t_start_s + 60.0;
  const Session raw = ULogSession(log, still);
  still.undo_correction = false;
  const Session logged = ULogSession(log, still);
  ASSERT_EQ(raw.series.size(), logged.series.size());
  EXPECT_NEAR(raw.series.duration_s(), 52.0, 0.1);
  for (const Vec3f& g : logged.series.gyr) ASSERT_LT(g.norm(), 0.05f);
  EXPECT_NEAR(MeanNorm(logged.series.acc), 9.705, 0.01);
  // CAL_ACC_PRIME names CAL_ACC0 (ZOFF -0.61 m/s^2): undone, the sensor read |a| ~ 10.4.
  EXPECT_NEAR(MeanNorm(raw.series.acc), 10.40, 0.03);
  // raw = R^T logged ./ CAL_ACC0_*SCALE + CAL_ACC0_*OFF with R = Euler(SENS_BOARD_X/Y/Z_OFF)
  // (SENS_BOARD_ROT = 0), R = Rz(yaw) Ry(pitch) Rx(roll).
  const double deg = 3.14159265358979323846 / 180.0;
  const Mat3 r = (Eigen::AngleAxisd(log.params.at("SENS_BOARD_Z_OFF") * deg, Vec3::UnitZ()) *
                  Eigen::AngleAxisd(log.params.at("SENS_BOARD_Y_OFF") * deg, Vec3::UnitY()) *
                  Eigen::AngleAxisd(log.params.at("SENS_BOARD_X_OFF") * deg, Vec3::UnitX()))
                     .toRotationMatrix();
  const Vec3 scale(log.params.at("CAL_ACC0_XSCALE"), log.params.at("CAL_ACC0_YSCALE"),
                   log.params.at("CAL_ACC0_ZSCALE"));
  const Vec3 offset(log.params.at("CAL_ACC0_XOFF"), log.params.at("CAL_ACC0_YOFF"),
                    log.params.at("CAL_ACC0_ZOFF"));
  const Vec3 expected =
      (r.transpose() * logged.series.acc[10].cast<double>()).cwiseQuotient(scale) + offset;
  EXPECT_LT((raw.series.acc[10].cast<double>() - expected).norm(), 1e-5);
  const Vec3 gyro_offset(log.params.at("CAL_GYRO0_XOFF"), log.params.at("CAL_GYRO0_YOFF"),
                         log.params.at("CAL_GYRO0_ZOFF"));
  const Vec3 expected_gyro = r.transpose() * logged.series.gyr[10].cast<double>() + gyro_offset;
  EXPECT_LT((raw.series.gyr[10].cast<double>() - expected_gyro).norm(), 1e-6);
  bool said = false;
  for (const auto& w : raw.warnings) said = said || w.message.find("reconstructed") != std::string::npos;
  EXPECT_TRUE(said);
  // sample.ulg subscribes vehicle_gps_position but logs no message of it: no site.
  EXPECT_FALSE(raw.site.has_value());
}

TEST(ULogSession, SmallLogStreamsSiteAndRawSensorAccel) {
  const std::string path = SharedLog("sample_log_small.ulg");
  PLUMB_SKIP_IF_ABSENT(path);
  const ULog log = ReadULog(path);
  std::map<std::string, int> per_name;
  for (const ImuStreamInfo& s : ULogImuStreams(log)) {
    ++per_name[s.name];
    if (s.name == "sensor_accel") {
      EXPECT_TRUE(s.applied.empty());
      EXPECT_TRUE(s.has_temperature);
    } else {
      EXPECT_TRUE(s.undoable) << s.name << " " << s.instance;
    }
  }
  EXPECT_EQ(per_name["sensor_combined"], 1);
  EXPECT_EQ(per_name["vehicle_imu"], 3);
  EXPECT_EQ(per_name["sensor_accel"], 3);
  const Session def = ULogSession(log, FlightLogSelection{});
  EXPECT_NE(def.source.find("sensor_combined"), std::string::npos);
  ASSERT_TRUE(def.site.has_value());
  EXPECT_NEAR(def.site->lat_deg, 63.417, 0.01);
  EXPECT_NEAR(def.site->lon_deg, 10.408, 0.01);
  EXPECT_EQ(def.site->source, "gps");
  FlightLogSelection imu2;
  imu2.imu = 2;
  imu2.stream = "vehicle_imu";
  const Session v = ULogSession(log, imu2);
  EXPECT_GT(v.series.size(), 5u);
  EXPECT_TRUE(v.series.has_gyro());
  FlightLogSelection accel;
  accel.stream = "sensor_accel";
  const Session a = ULogSession(log, accel);
  EXPECT_TRUE(a.series.has_temperature());
  FlightLogSelection missing;
  missing.imu = 9;
  EXPECT_THROW(ULogSession(log, missing), InputError);
  FlightLogSelection empty;
  empty.from_s = 1e9;
  EXPECT_THROW(ULogSession(log, empty), InputError);
  const auto params = ULogParams(log);
  EXPECT_EQ(params.at("SENS_BOARD_ROT"), 4.0);
  EXPECT_FALSE(params.count("MPC_XY_VEL_MAX"));
  const FlightLogSummary summary = ULogSummary(log);
  EXPECT_EQ(summary.format, "px4-ulog");
  EXPECT_EQ(summary.imus.size(), 7u);
  EXPECT_EQ(summary.params, params);
  EXPECT_TRUE(summary.site.has_value());
  EXPECT_EQ(summary.messages, log.MessageCounts());
  ASSERT_EQ(summary.warnings.size(), 1u);  // one dropout
  EXPECT_EQ(summary.warnings[0].code, "records_dropped");
}

// vehicle_imu: mean specific force = delta_velocity / dt, checked against the raw fields.
TEST(ULogSession, VehicleImuIsDeltaOverDt) {
  const std::string path = SharedLog("sample_px4_events.ulg");
  PLUMB_SKIP_IF_ABSENT(path);
  const ULog log = ReadULog(path);
  FlightLogSelection sel;
  sel.stream = "vehicle_imu";
  sel.undo_correction = false;
  const Session s = ULogSession(log, sel);
  const ULogTopic* t = log.Find("vehicle_imu", 0);
  ASSERT_NE(t, nullptr);
  const double dt_s = t->Column("delta_velocity_dt")[0] * 1e-6;
  EXPECT_FLOAT_EQ(s.series.acc[0].z(),
                  static_cast<float>(t->Column("delta_velocity[2]")[0] / dt_s));
  EXPECT_NEAR(MeanNorm(s.series.acc), 9.8, 0.2);  // SITL, on the ground
  EXPECT_DOUBLE_EQ(s.series.t_s[0], t->Column("timestamp_sample")[0] * 1e-6);
}

// A hand-built modern log: vehicle_imu of accel device 77, its temperature in sensor_accel,
// CAL_ACC0 with SENS_BOARD_ROT = 2 (yaw 90) and thermal compensation TC_A0 enabled.
Writer ThermalLog() {
  Writer w;
  w.Format("vehicle_imu:uint64_t timestamp;uint64_t timestamp_sample;uint32_t accel_device_id;"
           "uint32_t gyro_device_id;float[3] delta_angle;float[3] delta_velocity;"
           "uint16_t delta_angle_dt;uint16_t delta_velocity_dt;");
  w.Format("sensor_accel:uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;"
           "float x;float y;float z;float temperature;");
  const auto f = [&](const std::string& name, float v) { w.KeyValue('P', "float " + name, Le(v)); };
  const auto i = [&](const std::string& name, std::int32_t v) {
    w.KeyValue('P', "int32_t " + name, Le(v));
  };
  i("CAL_ACC0_ID", 77);
  i("CAL_ACC0_ROT", -1);
  i("CAL_GYRO0_ID", 88);
  i("SENS_BOARD_ROT", 2);
  i("TC_A_ENABLE", 1);
  i("TC_A0_ID", 77);
  f("TC_A0_TREF", 25.0f);
  f("TC_A0_TMIN", 10.0f);
  f("TC_A0_TMAX", 50.0f);
  const char* axis = "XYZ";
  for (int k = 0; k < 3; ++k) {
    const std::string a(1, axis[k]);
    f("CAL_ACC0_" + a + "OFF", 0.1f * static_cast<float>(k + 1));
    f("CAL_ACC0_" + a + "SCALE", 1.0f + 0.01f * static_cast<float>(k + 1));
    f("CAL_GYRO0_" + a + "OFF", -0.01f * static_cast<float>(k + 1));
    for (int order = 0; order < 4; ++order) {
      f("TC_A0_X" + std::to_string(order) + "_" + std::to_string(k),
        0.02f / static_cast<float>(order + 1) * static_cast<float>(k + 1));
    }
  }
  w.Add(0, 0, "vehicle_imu");
  w.Add(0, 1, "sensor_accel");
  const auto accel = [&](std::uint64_t t_us, float temp) {
    w.Data(1, Cat({Le(t_us), Le(t_us), Le<std::uint32_t>(77), Le(0.f), Le(0.f), Le(-9.8f),
                   Le(temp)}));
  };
  const auto imu = [&](std::uint64_t t_us, float ax) {
    w.Data(0, Cat({Le(t_us), Le(t_us), Le<std::uint32_t>(77), Le<std::uint32_t>(88),
                   Le(0.001f * 0.005f), Le(0.f), Le(0.f),                  // delta_angle, rad
                   Le(ax * 0.005f), Le(0.5f * 0.005f), Le(-9.8f * 0.005f),  // delta_velocity
                   Le<std::uint16_t>(5000), Le<std::uint16_t>(5000)}));      // dt, us
  };
  accel(1000000, 30.0f);
  imu(1500000, 0.2f);
  accel(2000000, 60.0f);  // above TC_A0_TMAX: clamped to 50
  imu(2500000, 0.3f);
  return w;
}

TEST(ULogSession, UndoesBoardRotationCalibrationAndThermalOffset) {
  Writer w = ThermalLog();
  const ULog log = Parse(w);
  FlightLogSelection sel;
  sel.stream = "vehicle_imu";
  const Session s = ULogSession(log, sel);
  sel.undo_correction = false;
  const Session logged = ULogSession(log, sel);
  ASSERT_EQ(s.series.size(), 2u);
  const Mat3 r = Eigen::AngleAxisd(3.14159265358979323846 / 2, Vec3::UnitZ()).toRotationMatrix();
  const auto p = [&](const std::string& name) { return log.params.at(name); };
  const Vec3 scale(p("CAL_ACC0_XSCALE"), p("CAL_ACC0_YSCALE"), p("CAL_ACC0_ZSCALE"));
  const Vec3 offset(p("CAL_ACC0_XOFF"), p("CAL_ACC0_YOFF"), p("CAL_ACC0_ZOFF"));
  const double temps_c[2] = {30.0, 50.0};
  for (std::size_t k = 0; k < 2; ++k) {
    const double dt = temps_c[k] - p("TC_A0_TREF");
    Vec3 thermal;
    for (int i = 0; i < 3; ++i) {
      const std::string ax = "_" + std::to_string(i);
      thermal[i] = p("TC_A0_X0" + ax) + p("TC_A0_X1" + ax) * dt + p("TC_A0_X2" + ax) * dt * dt +
                   p("TC_A0_X3" + ax) * dt * dt * dt;
    }
    const Vec3 expected =
        (r.transpose() * logged.series.acc[k].cast<double>()).cwiseQuotient(scale) + offset +
        thermal;
    EXPECT_LT((s.series.acc[k].cast<double>() - expected).norm(), 1e-4) << "sample " << k;
    const Vec3 gyro_expected = r.transpose() * logged.series.gyr[k].cast<double>() +
                               Vec3(p("CAL_GYRO0_XOFF"), p("CAL_GYRO0_YOFF"), p("CAL_GYRO0_ZOFF"));
    EXPECT_LT((s.series.gyr[k].cast<double>() - gyro_expected).norm(), 1e-6) << "sample " << k;
  }
  EXPECT_NEAR(logged.series.acc[0].x(), 0.2, 1e-6);  // delta_velocity / dt
  bool thermal_said = false;
  for (const auto& m : s.warnings) thermal_said = thermal_said || m.message.find("TC_A0") != std::string::npos;
  EXPECT_TRUE(thermal_said);
}

}  // namespace
}  // namespace plumb::io

namespace plumb::io {
namespace {

// Appends D messages of topic 0 ("t": timestamp, float) and, every 997th, of topic 7 ("big":
// timestamp, 3000 bytes), with 3 garbage bytes every 4099th, until the log has `until` bytes.
void FillTwoTopics(Writer* w, std::size_t until, std::uint64_t* t_us) {
  Bytes small(2 + 12, 0), big(2 + 3008, 0);  // msg_id, then the bodies of t and big
  big[0] = 7;
  for (std::size_t k = 0; w->bytes().size() < until; ++k) {
    ++*t_us;
    const auto v = static_cast<float>(*t_us % 977);
    std::memcpy(small.data() + 2, t_us, 8);
    std::memcpy(small.data() + 10, &v, 4);
    w->Message('D', small);
    if (k % 997 == 0) {
      std::memcpy(big.data() + 2, t_us, 8);
      std::fill(big.begin() + 10, big.end(), static_cast<std::uint8_t>(k));
      w->Message('D', big);
    }
    if (k % 4099 == 0) w->Raw("\0\0Q", 3);  // garbage: a message of size 0
  }
}

// A file of several read chunks: ReadULog (reading forward in chunks; appended segments, a
// resync over garbage longer than a chunk, resyncs and truncated messages near the chunks'
// ends) decodes exactly what the in-memory parser does.
TEST(ULogBuilt, ReadingInChunksDecodesWhatTheWholeInputDoes) {
  Writer w;
  w.Message('B', testing::AppendedDataFlagBits());
  w.Format("t:uint64_t timestamp;float v;uint8_t[3] _padding0;");
  w.Format("big:uint64_t timestamp;uint8_t[3000] blob;");
  w.Add(0, 0, "t");
  w.Add(0, 7, "big");
  std::uint64_t t_us = 0;
  const auto fill = [&](std::size_t until) { FillTwoTopics(&w, until, &t_us); };
  fill(std::size_t{3} << 20);
  ++t_us;
  w.Data(0, Cat({Le(t_us), Le(1.0f)}));
  w.bytes().resize(w.bytes().size() - 2);  // the regular log stops mid-message
  const std::uint64_t first = w.bytes().size();
  fill(first + (std::size_t{1} << 20));
  w.bytes().insert(w.bytes().end(), std::size_t{3} << 19, 0x33);  // 1.5 MiB of garbage
  const std::uint64_t second = w.bytes().size();
  fill(second + (std::size_t{2} << 20) + 12345);
  std::memcpy(w.bytes().data() + 16 + 3 + 16, &first, 8);
  std::memcpy(w.bytes().data() + 16 + 3 + 24, &second, 8);
  ::plumb::testing::TempDir dir;
  const std::string path = dir.File("big.ulg");
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(w.bytes().data()),
              static_cast<std::streamsize>(w.bytes().size()));
  }
  const ULog from_file = ReadULog(path);
  const ULog in_memory = ParseULog(w.bytes().data(), w.bytes().size(), path);
  EXPECT_EQ(from_file.size_bytes, w.bytes().size());
  EXPECT_EQ(from_file.appended_offsets, (std::vector<std::uint64_t>{first, second}));
  EXPECT_EQ(from_file.appended_offsets, in_memory.appended_offsets);
  EXPECT_EQ(from_file.warnings.Describe(), in_memory.warnings.Describe());
  EXPECT_GT(in_memory.warnings.skip_runs, 50u);
  EXPECT_GE(in_memory.warnings.truncated_records, 1u);
  ASSERT_EQ(from_file.topics.size(), 2u);
  for (std::size_t k = 0; k < in_memory.topics.size(); ++k) {
    EXPECT_EQ(from_file.topics[k].rows, in_memory.topics[k].rows) << k;
    EXPECT_TRUE(from_file.topics[k].bodies == in_memory.topics[k].bodies) << k;
  }
  EXPECT_EQ(in_memory.Find("t", 0)->rows + 1, t_us);  // the cut message is the only one lost
}

// Read from a pipe (not a regular file: read whole, its size known only at its end), the
// shared sample.ulg decodes as from the file, subscriptions and all.
TEST(ULog, ReadFromAPipeDecodesAsTheFile) {
  const std::string path = SharedLog("sample.ulg");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  ::plumb::testing::TempDir dir;
  const std::string fifo = dir.File("log.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const Bytes bytes = ReadBytes(path);
  std::thread writer([&] {
    std::ofstream out(fifo, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  });
  const ULog piped = ReadULog(fifo);
  writer.join();
  const ULog file = ReadULog(path);
  EXPECT_EQ(piped.size_bytes, file.size_bytes);
  EXPECT_EQ(piped.MessageCounts(), file.MessageCounts());
  EXPECT_EQ(piped.warnings.Describe(), file.warnings.Describe());
  ASSERT_EQ(piped.topics.size(), file.topics.size());
  for (std::size_t k = 0; k < file.topics.size(); ++k) {
    EXPECT_TRUE(piped.topics[k].bodies == file.topics[k].bodies) << file.topics[k].name;
  }
}

}  // namespace
}  // namespace plumb::io

// MAVLink tlog reader (io/mavlink/mavlink_tlog.h) and its session (io/mavlink/mavlink_session.h):
// the real ../shared/data/mavlink log against golden data from an independent Python decoder
// (tests/data/mavlink/decode_golden.py, see README.md there), the CRC against known values,
// hand-built v1/v2 frames (truncated payloads, signatures, unknown ids, several systems), damaged
// copies of the real log, and the session with ArduPilot's correction undone.
#include <gtest/gtest.h>

#include <algorithm>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "io/io_test_util.h"
#include "io/tlog_builder.h"
#include "plumb/core/error.h"
#include "plumb/io/mavlink/mavlink_session.h"
#include "plumb/io/mavlink/mavlink_tlog.h"

namespace plumb::io {
namespace {

using testing::ReadBytes;

using testing::Bytes;
using testing::Append;
using testing::FrameSpec;
using testing::GpsRawInt;
using testing::Heartbeat;
using testing::kT0_us;
using testing::kUnknownId;
using testing::ParamValue;
using testing::Payload;
using testing::RawImu;
using testing::Record;
using testing::ScaledImu;

const std::string kLogName = "plane385_disarmed.tlog";
const std::string kLog = std::string(PLUMB_SHARED_DATA_DIR) + "/mavlink/" + kLogName;
const std::string kGolden =
    std::string(PLUMB_SOURCE_DIR) + "/tests/data/mavlink/" + kLogName + ".golden.json";

nlohmann::json ReadGolden() {
  std::ifstream in(kGolden);
  EXPECT_TRUE(in.good()) << kGolden;
  return nlohmann::json::parse(in, nullptr, true, false);
}

MavlinkLog Parse(const Bytes& b) { return ParseTlog(b.data(), b.size(), "test.tlog"); }

// Every input byte is in an accepted record, skipped, or in the dropped truncated record.
void ExpectBytesAccounted(const MavlinkLog& log) {
  EXPECT_EQ(log.record_bytes + log.warnings.bytes_skipped + log.warnings.truncated_bytes,
            log.size_bytes);
}

// --- CRC ----------------------------------------------------------------------------------------

TEST(MavlinkTlog, CrcMatchesKnownValues) {
  // CRC-16/MCRF4XX check value (the catalogue's "123456789" -> 0x6F91).
  const std::string check = "123456789";
  EXPECT_EQ(MavlinkCrc(reinterpret_cast<const std::uint8_t*>(check.data()), check.size()),
            0x6F91);
  // The first frame of plane385_disarmed.tlog, copied by hand: a v1 HEARTBEAT from the ground
  // station (sys 255), CRC bytes a1 df = 0xDFA1 with HEARTBEAT's CRC_EXTRA 50.
  const Bytes frame = {0xFE, 0x09, 0x00, 0xFF, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                       0x06, 0x08, 0x00, 0x00, 0x03};
  std::uint16_t crc = MavlinkCrc(frame.data() + 1, frame.size() - 1);
  const std::uint8_t extra = static_cast<std::uint8_t>(MavlinkCrcExtra(kMavHeartbeat));
  EXPECT_EQ(extra, 50);
  EXPECT_EQ(MavlinkCrc(&extra, 1, crc), 0xDFA1);
  EXPECT_EQ(MavlinkCrcExtra(1u << 20), -1);
}

// The sliced CRC (8-byte steps, then slices of 4, 2 and 1) against the bit-by-bit definition
// (reflected polynomial 0x8408), for every length up to 40 and every start state tried.
TEST(MavlinkTlog, CrcEqualsTheBitwiseDefinitionAtEveryLength) {
  const auto bitwise = [](const std::uint8_t* data, std::size_t size, std::uint16_t crc) {
    for (std::size_t k = 0; k < size; ++k) {
      crc = static_cast<std::uint16_t>(crc ^ data[k]);
      for (int bit = 0; bit < 8; ++bit) {
        crc = static_cast<std::uint16_t>((crc & 1u) ? (crc >> 1) ^ 0x8408u : crc >> 1);
      }
    }
    return crc;
  };
  Bytes data(40);
  for (std::size_t k = 0; k < data.size(); ++k) {
    data[k] = static_cast<std::uint8_t>(k * 37 + 11);
  }
  for (const std::uint16_t start : {std::uint16_t{0xFFFF}, std::uint16_t{0x1234},
                                    std::uint16_t{0}}) {
    for (std::size_t size = 0; size <= data.size(); ++size) {
      EXPECT_EQ(MavlinkCrc(data.data(), size, start), bitwise(data.data(), size, start))
          << size << " bytes from " << start;
    }
  }
}

// The generated table (scripts/gen-mavlink-dialect computes every CRC_EXTRA from the fields
// and checks it against the package) against values the MAVLink project's generated C headers
// state (MAVLINK_MSG_ID_<NAME>_CRC, _MIN_LEN, _LEN), typed here, and the dialect file of the
// package each message is in.
TEST(MavlinkTlog, GeneratedTableHasTheDialectsKnownValues) {
  struct Known {
    std::uint32_t id;
    const char* name;
    int crc_extra;
    int min_length;
    int max_length;
    const char* dialect;
  };
  const Known known[] = {
      {0, "HEARTBEAT", 50, 9, 9, "minimal"},
      {22, "PARAM_VALUE", 220, 25, 25, "common"},
      {24, "GPS_RAW_INT", 24, 30, 52, "common"},
      {26, "SCALED_IMU", 170, 22, 24, "common"},
      {27, "RAW_IMU", 144, 26, 29, "common"},
      {105, "HIGHRES_IMU", 93, 62, 63, "common"},
      {116, "SCALED_IMU2", 76, 22, 24, "common"},
      {129, "SCALED_IMU3", 46, 22, 24, "common"},
      {253, "STATUSTEXT", 83, 51, 54, "common"},
      {300, "PROTOCOL_VERSION", 217, 22, 22, "common"},
      {150, "SENSOR_OFFSETS", 134, 42, 42, "ardupilotmega"},
      {152, "MEMINFO", 208, 4, 8, "ardupilotmega"},
      {163, "AHRS", 127, 28, 28, "ardupilotmega"},
      {182, "AHRS3", 229, 40, 40, "ardupilotmega"},
      {193, "EKF_STATUS_REPORT", 71, 22, 26, "ardupilotmega"},
  };
  for (const Known& k : known) {
    const MavlinkMessageInfo* m = FindMavlinkMessage(k.id);
    ASSERT_NE(m, nullptr) << k.name;
    EXPECT_EQ(m->id, k.id);
    EXPECT_STREQ(m->name, k.name);
    EXPECT_EQ(m->crc_extra, k.crc_extra) << k.name;
    EXPECT_EQ(MavlinkCrcExtra(k.id), k.crc_extra) << k.name;
    EXPECT_EQ(m->min_length, k.min_length) << k.name;
    EXPECT_EQ(m->max_length, k.max_length) << k.name;
    EXPECT_STREQ(m->dialect, k.dialect) << k.name;
    EXPECT_EQ(MavlinkMessageName(k.id), k.name);
  }
  // The table: sorted by id, names unique, lengths consistent, the lookups agree with it.
  const std::vector<MavlinkMessageInfo>& all = MavlinkMessages();
  ASSERT_GT(all.size(), 250u);  // common alone has over 200 messages
  std::set<std::string> names;
  std::set<std::string> dialects;
  for (std::size_t k = 0; k < all.size(); ++k) {
    if (k > 0) EXPECT_LT(all[k - 1].id, all[k].id);
    EXPECT_TRUE(names.insert(all[k].name).second) << all[k].name;
    dialects.insert(all[k].dialect);
    EXPECT_GT(all[k].min_length, 0) << all[k].name;
    EXPECT_LE(all[k].min_length, all[k].max_length) << all[k].name;
    EXPECT_EQ(FindMavlinkMessage(all[k].id), &all[k]);
  }
  for (const char* d : {"minimal", "standard", "common", "ardupilotmega", "uavionix", "icarous"}) {
    EXPECT_EQ(dialects.count(d), 1u) << d;
  }
  EXPECT_EQ(dialects.size(), 6u);
  EXPECT_EQ(FindMavlinkMessage(kUnknownId), nullptr);
  EXPECT_EQ(MavlinkMessageName(kUnknownId), "MSG199");
  EXPECT_EQ(MavlinkCrcExtra(kUnknownId), -1);
  EXPECT_NE(MavlinkDefinitionsSource().find("common, ardupilotmega"), std::string::npos);
  EXPECT_NE(MavlinkDefinitionsSource().find("mavlink-mappings "), std::string::npos);
}

/// X.25 bit by bit, the textbook form (independent of the library's sliced tables).
std::uint16_t BitwiseX25(const Bytes& data) {
  std::uint16_t crc = 0xFFFF;
  for (std::uint8_t byte : data) {
    crc ^= byte;
    for (int k = 0; k < 8; ++k) crc = (crc & 1u) ? (crc >> 1) ^ 0x8408u : crc >> 1;
  }
  return crc;
}

TEST(MavlinkTlog, SlicedCrcEqualsTheBitwiseOneForEveryLength) {
  std::mt19937_64 rng(31337);
  for (std::size_t n = 0; n <= 80; ++n) {
    Bytes data(n);
    for (auto& b : data) b = static_cast<std::uint8_t>(rng());
    EXPECT_EQ(MavlinkCrc(data.data(), data.size()), BitwiseX25(data)) << "length " << n;
  }
}

// --- the real log against the golden JSON -------------------------------------------------------

void ExpectImuEq(const MavlinkInt16Imu& r, const nlohmann::json& g) {
  EXPECT_DOUBLE_EQ(r.log_time_s, g["log_time_s"].get<double>());
  EXPECT_EQ(r.time_us, g["time_us"].get<std::uint64_t>());
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(r.acc[k], g["acc"][k].get<int>());
    EXPECT_EQ(r.gyr[k], g["gyr"][k].get<int>());
    EXPECT_EQ(r.mag[k], g["mag"][k].get<int>());
  }
  EXPECT_EQ(r.temperature_cdegc, g["temperature_cdegc"].get<int>());
  EXPECT_EQ(r.id, g["id"].get<int>());
  EXPECT_EQ(r.system_id, g["sysid"].get<int>());
  EXPECT_EQ(r.component_id, g["compid"].get<int>());
}

void ExpectStreamEq(const std::vector<MavlinkInt16Imu>& v, const nlohmann::json& g) {
  ASSERT_EQ(v.size(), g["count"].get<std::size_t>());
  if (v.empty()) return;
  ExpectImuEq(v.front(), g["first"]);
  ExpectImuEq(v.back(), g["last"]);
}

void ExpectGpsEq(const MavlinkGpsRawInt& r, const nlohmann::json& g) {
  EXPECT_DOUBLE_EQ(r.log_time_s, g["log_time_s"].get<double>());
  EXPECT_EQ(r.time_us, g["time_us"].get<std::uint64_t>());
  EXPECT_EQ(r.lat_e7, g["lat_e7"].get<std::int32_t>());
  EXPECT_EQ(r.lon_e7, g["lon_e7"].get<std::int32_t>());
  EXPECT_EQ(r.alt_mm, g["alt_mm"].get<std::int32_t>());
  EXPECT_EQ(r.fix_type, g["fix_type"].get<int>());
}

TEST(MavlinkTlog, RealLogMatchesIndependentDecoder) {
  PLUMB_SKIP_IF_ABSENT(kLog);
  const nlohmann::json g = ReadGolden();
  const MavlinkLog log = ReadTlog(kLog);
  EXPECT_EQ(log.size_bytes, g["size_bytes"].get<std::size_t>());
  EXPECT_EQ(log.frames_v1, g["frames_v1"].get<std::size_t>());
  EXPECT_EQ(log.frames_v2, g["frames_v2"].get<std::size_t>());
  EXPECT_EQ(log.warnings.crc_failures, g["crc_failures"].get<std::size_t>());
  EXPECT_EQ(log.warnings.bytes_skipped, g["bytes_skipped"].get<std::size_t>());
  EXPECT_EQ(log.warnings.unchecked_frames, g["unchecked_frames"].get<std::size_t>());
  // Every frame of this ArduPilot log is of the common or ardupilotmega dialect: all checked.
  EXPECT_EQ(log.warnings.unchecked_frames, 0u);
  EXPECT_EQ(log.checked_frames, log.frames_v1 + log.frames_v2);
  for (const auto& [id, n] : log.message_counts) {
    EXPECT_NE(FindMavlinkMessage(id), nullptr) << "id " << id;
  }
  EXPECT_EQ(log.warnings.truncated_bytes, g["truncated_bytes"].get<std::size_t>());
  ExpectBytesAccounted(log);
  ASSERT_EQ(log.message_counts.size(), g["message_counts"].size());
  for (const auto& [id, n] : log.message_counts) {
    EXPECT_EQ(n, g["message_counts"][std::to_string(id)].get<std::size_t>()) << "id " << id;
  }
  ExpectStreamEq(log.raw_imu, g["RAW_IMU"]);
  ExpectStreamEq(log.scaled_imu, g["SCALED_IMU"]);
  ExpectStreamEq(log.scaled_imu2, g["SCALED_IMU2"]);
  ExpectStreamEq(log.scaled_imu3, g["SCALED_IMU3"]);
  ASSERT_EQ(log.gps_raw_int.size(), g["GPS_RAW_INT"]["count"].get<std::size_t>());
  ExpectGpsEq(log.gps_raw_int.front(), g["GPS_RAW_INT"]["first"]);
  ExpectGpsEq(log.gps_raw_int.back(), g["GPS_RAW_INT"]["last"]);
  // HEARTBEAT tuples (sysid, compid, autopilot, type).
  std::set<std::array<int, 4>> beats;
  for (const MavlinkHeartbeat& h : log.heartbeat) {
    beats.insert({h.system_id, h.component_id, h.autopilot, h.type});
  }
  ASSERT_EQ(beats.size(), g["HEARTBEAT"].size());
  for (const auto& t : g["HEARTBEAT"]) {
    EXPECT_TRUE(beats.count({t[0].get<int>(), t[1].get<int>(), t[2].get<int>(), t[3].get<int>()}));
  }
  // Parameters: distinct names and a few values (exact doubles of the sent floats).
  const std::map<std::string, double> params = TlogParams(log);
  EXPECT_EQ(params.size(), g["param_count"].get<std::size_t>());
  for (const auto& [name, value] : g["params"].items()) {
    ASSERT_TRUE(params.count(name)) << name;
    EXPECT_EQ(params.at(name), value.get<double>()) << name;
  }
  // Named message counts for `plumb info`.
  bool raw_named = false;
  for (const auto& [name, n] : log.MessageCounts()) raw_named |= name == "RAW_IMU" && n == 301;
  EXPECT_TRUE(raw_named);
}

// --- damaged copies of the real log -------------------------------------------------------------

TEST(MavlinkTlog, FlippedPayloadByteFailsTheCrcAndCostsOneFrame) {
  PLUMB_SKIP_IF_ABSENT(kLog);
  Bytes b = ReadBytes(kLog);
  const MavlinkLog clean = Parse(b);
  // The 10th RAW_IMU record: find it by walking the v1 records of this all-v1 file.
  std::size_t pos = 0, seen = 0, record = 0, record_size = 0;
  while (pos + 14 <= b.size()) {
    const std::size_t size = 8 + 6 + b[pos + 9] + 2;
    if (b[pos + 13] == kMavRawImu && ++seen == 10) {
      record = pos;
      record_size = size;
      break;
    }
    pos += size;
  }
  ASSERT_GT(record_size, 0u);
  b[record + 8 + 6 + 9] ^= 0x10;  // a byte of zacc
  const MavlinkLog log = Parse(b);
  EXPECT_EQ(log.warnings.crc_failures, 1u);
  EXPECT_EQ(log.warnings.first_crc_failure_offset, record);
  EXPECT_EQ(log.warnings.bytes_skipped, record_size);
  EXPECT_EQ(log.warnings.skip_runs, 1u);
  EXPECT_EQ(log.raw_imu.size(), clean.raw_imu.size() - 1);
  EXPECT_EQ(log.scaled_imu2.size(), clean.scaled_imu2.size());
  EXPECT_EQ(log.frames_v1, clean.frames_v1 - 1);
  ExpectBytesAccounted(log);
}

TEST(MavlinkTlog, EveryTruncationKeepsTheCompleteRecords) {
  PLUMB_SKIP_IF_ABSENT(kLog);
  const Bytes b = ReadBytes(kLog);
  const MavlinkLog clean = Parse(b);
  for (std::size_t cut = 40; cut < b.size(); cut += 997) {
    const MavlinkLog log = ParseTlog(b.data(), cut, "cut.tlog");
    ExpectBytesAccounted(log);
    EXPECT_EQ(log.warnings.bytes_skipped, 0u) << "cut " << cut;
    EXPECT_EQ(log.warnings.crc_failures, 0u) << "cut " << cut;
    EXPECT_LE(log.warnings.truncated_records, 1u);
    EXPECT_LE(log.raw_imu.size(), clean.raw_imu.size());
    // The records kept are the clean log's first ones.
    for (std::size_t i = 0; i < log.raw_imu.size(); ++i) {
      ASSERT_EQ(log.raw_imu[i].time_us, clean.raw_imu[i].time_us) << "cut " << cut;
    }
    if (log.warnings.truncated_records == 1) {
      EXPECT_FALSE(log.warnings.Describe(log.message_counts).empty());
    }
  }
}

TEST(MavlinkTlog, GarbageBetweenRecordsIsSkippedAndCounted) {
  PLUMB_SKIP_IF_ABSENT(kLog);
  const Bytes b = ReadBytes(kLog);
  const MavlinkLog clean = Parse(b);
  // Insert runs of random bytes (including start bytes) every ~5000 bytes at record starts.
  std::mt19937_64 rng(20240905);
  Bytes damaged;
  std::size_t pos = 0, inserted = 0, runs = 0;
  while (pos < b.size()) {
    const std::size_t size = 8 + 6 + b[pos + 9] + 2;
    if (pos / 5000 != (pos + size) / 5000) {
      const std::size_t n = 1 + rng() % 40;
      for (std::size_t k = 0; k < n; ++k) {
        damaged.push_back(k % 7 == 3 ? 0xFE : static_cast<std::uint8_t>(rng()));
      }
      inserted += n;
      ++runs;
    }
    damaged.insert(damaged.end(), b.begin() + static_cast<std::ptrdiff_t>(pos),
                   b.begin() + static_cast<std::ptrdiff_t>(pos + size));
    pos += size;
  }
  const MavlinkLog log = Parse(damaged);
  // Every CRC-checked frame survives. A frame of an id without a known CRC_EXTRA right before
  // a garbage run is not followed by a record, so it is skipped with the run (at most one per
  // run): the contract keeps unchecked frames only between records.
  for (const auto& [id, n] : clean.message_counts) {
    if (MavlinkCrcExtra(id) >= 0) EXPECT_EQ(log.message_counts.at(id), n) << "id " << id;
  }
  EXPECT_GE(log.frames_v1 + runs, clean.frames_v1);
  EXPECT_GE(log.warnings.bytes_skipped, inserted);
  EXPECT_EQ(log.warnings.skip_runs, runs);
  EXPECT_EQ(log.warnings.crc_failures, 0u);
  EXPECT_EQ(log.raw_imu.size(), clean.raw_imu.size());
  EXPECT_EQ(log.param_value.size(), clean.param_value.size());
  ExpectBytesAccounted(log);
}

TEST(MavlinkTlog, RandomBitFlipsNeverCrashAndKeepMostRecords) {
  PLUMB_SKIP_IF_ABSENT(kLog);
  const Bytes b = ReadBytes(kLog);
  const MavlinkLog clean = Parse(b);
  std::mt19937_64 rng(77);
  for (int trial = 0; trial < 20; ++trial) {
    Bytes d = b;
    const int flips = 1 + trial * 3;
    for (int k = 0; k < flips; ++k) d[rng() % d.size()] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
    const MavlinkLog log = Parse(d);
    ExpectBytesAccounted(log);
    // Each flip costs at most the frame it hits and, for a time or length byte, its neighbour.
    EXPECT_GE(log.frames_v1 + 2 * static_cast<std::size_t>(flips), clean.frames_v1);
    EXPECT_LE(log.raw_imu.size(), clean.raw_imu.size());
    FlightLogSelection sel;
    const Session s = TlogSession(log, sel);
    EXPECT_GT(s.series.size(), 250u);
  }
}

// --- hand-built frames --------------------------------------------------------------------------

TEST(MavlinkTlog, V1AndV2FramesWithTruncatedPayloadsAndSignatures) {
  Bytes t;
  // v1 RAW_IMU without extensions (26 bytes), as ArduPilot 3.x sends it.
  Bytes raw26 = RawImu(1000000, {10, -20, -1000, 1, 2, 3, 4, 5, 6});
  raw26.resize(26);
  Append(&t, Record({kMavRawImu, raw26, 1, 1, false}));
  // v2 RAW_IMU with zmag = 0, id = 0, temperature = 0: the sender drops 5 trailing zero bytes.
  const Bytes raw_v2 = RawImu(1250000, {11, -21, -1001, 1, 2, 3, 4, 5, 0});
  const Bytes rec_v2 = Record({kMavRawImu, raw_v2, 1, 1, true, false, true, kT0_us + 250000});
  EXPECT_EQ(rec_v2[9], 23);  // payload length on the wire: ymag's high byte is 0 too
  Append(&t, rec_v2);
  // Signed v2 SCALED_IMU2 with a temperature: the 13-byte signature is skipped.
  Append(&t, Record({kMavScaledImu2, ScaledImu(1500, {-5, 6, -990, 7, 8, 9, 1, 1, 1}, 3550), 1,
                     1, true, true, true, kT0_us + 500000}));
  // v2 message with a 24-bit id nobody knows, then a v1 frame of an unknown 8-bit id.
  Append(&t, Record({0x012345, {1, 2, 3}, 1, 1, true, false, true, kT0_us + 600000}));
  ASSERT_EQ(FindMavlinkMessage(kUnknownId), nullptr);
  Append(&t, Record({kUnknownId, {9, 9}, 1, 1, false, false, true, kT0_us + 700000}));
  // v2 HIGHRES_IMU, full length.
  Payload h;
  h.Put<std::uint64_t>(2000000);
  for (float x : {0.1f, -0.2f, -9.7f, 0.01f, 0.02f, -0.03f, 0.2f, 0.0f, 0.4f, 1013.0f, 0.0f,
                  12.0f, 31.5f}) {
    h.Put(x);
  }
  h.Put<std::uint16_t>(0x1FFF).Put<std::uint8_t>(1);
  Append(&t, Record({kMavHighresImu, h.b, 1, 1, true, false, true, kT0_us + 800000}));

  const MavlinkLog log = Parse(t);
  EXPECT_EQ(log.frames_v1, 2u);
  EXPECT_EQ(log.frames_v2, 4u);
  EXPECT_EQ(log.frames_signed, 1u);
  EXPECT_EQ(log.warnings.unchecked_frames, 2u);
  EXPECT_EQ(log.message_counts.at(0x012345), 1u);
  EXPECT_EQ(log.message_counts.at(kUnknownId), 1u);
  EXPECT_EQ(log.checked_frames, 4u);
  EXPECT_EQ(log.warnings.bytes_skipped, 0u);
  ExpectBytesAccounted(log);
  ASSERT_EQ(log.raw_imu.size(), 2u);
  EXPECT_EQ(log.raw_imu[0].acc[2], -1000);
  EXPECT_EQ(log.raw_imu[0].mag[2], 6);
  EXPECT_EQ(log.raw_imu[1].time_us, 1250000u);
  EXPECT_EQ(log.raw_imu[1].acc[0], 11);
  EXPECT_EQ(log.raw_imu[1].mag[1], 5);
  EXPECT_EQ(log.raw_imu[1].mag[2], 0);  // zero-extended
  EXPECT_EQ(log.raw_imu[1].temperature_cdegc, 0);
  ASSERT_EQ(log.scaled_imu2.size(), 1u);
  EXPECT_EQ(log.scaled_imu2[0].time_us, 1500000u);
  EXPECT_EQ(log.scaled_imu2[0].temperature_cdegc, 3550);
  EXPECT_DOUBLE_EQ(log.scaled_imu2[0].log_time_s, (kT0_us + 500000) * 1e-6);
  ASSERT_EQ(log.highres_imu.size(), 1u);
  EXPECT_EQ(log.highres_imu[0].acc[2], -9.7f);
  EXPECT_EQ(log.highres_imu[0].temperature_degc, 31.5f);
  EXPECT_EQ(log.highres_imu[0].fields_updated, 0x1FFF);
  EXPECT_EQ(log.highres_imu[0].id, 1);
  bool unchecked_said = false;
  for (const auto& w : log.warnings.Describe(log.message_counts)) {
    unchecked_said |= w.find("MSG74565 (id 74565) x1") != std::string::npos;
  }
  EXPECT_TRUE(unchecked_said);
}

TEST(MavlinkTlog, UnknownIdFollowedByGarbageIsNotAFrame) {
  ASSERT_EQ(FindMavlinkMessage(kUnknownId), nullptr);
  Bytes t = Record({kUnknownId, {1, 2, 3, 4}, 1, 1, false});
  t.insert(t.end(), {0x01, 0x02, 0x03});  // no record after the unknown frame
  Append(&t, Record({kMavHeartbeat, Heartbeat(3), 1, 1, false}));
  const MavlinkLog log = Parse(t);
  EXPECT_EQ(log.message_counts.count(kUnknownId), 0u);
  EXPECT_EQ(log.heartbeat.size(), 1u);
  EXPECT_EQ(log.warnings.bytes_skipped, 8u + 6u + 4u + 2u + 3u);
  ExpectBytesAccounted(log);
}

TEST(MavlinkTlog, NoFrameIsAnInputErrorAtByteZero) {
  const Bytes junk(1000, 0x55);
  testing::ExpectInputError([&] { ParseTlog(junk.data(), junk.size(), "junk.tlog"); },
                            "junk.tlog", "byte 0", {"no MAVLink frame"});
  testing::ExpectInputError([&] { ParseTlog(nullptr, 0, "empty.tlog"); }, "empty.tlog",
                            "byte 0", {"not a MAVLink .tlog"});
  testing::ExpectInputError([] { ReadTlog("/nonexistent/x.tlog"); }, "/nonexistent/x.tlog",
                            "byte 0", {"cannot open"});
}

// --- vehicles, parameters, site -----------------------------------------------------------------

/// A small ArduPilot tlog: system 1 with RAW_IMU at 10 Hz and parameters, a GCS heartbeat.
Bytes SmallArdupilotLog(std::size_t samples) {
  Bytes t;
  Append(&t, Record({kMavHeartbeat, Heartbeat(8), 255, 0}));
  Append(&t, Record({kMavHeartbeat, Heartbeat(kMavAutopilotArdupilotMega), 1, 1}));
  const std::pair<const char*, float> params[] = {
      {"INS_ACCOFFS_X", 0.5f}, {"INS_ACCOFFS_Y", -0.25f}, {"INS_ACCOFFS_Z", 1.0f},
      {"INS_ACCSCAL_X", 1.25f}, {"INS_ACCSCAL_Y", 0.5f}, {"INS_ACCSCAL_Z", 2.0f},
      {"INS_GYROFFS_X", 0.125f}, {"INS_GYROFFS_Y", 0.0f}, {"INS_GYROFFS_Z", -0.5f},
      {"AHRS_ORIENTATION", 0.0f}};
  for (const auto& [name, value] : params) {
    Append(&t, Record({kMavParamValue, ParamValue(name, value, 9), 1, 1}));
  }
  for (std::size_t i = 0; i < samples; ++i) {
    const std::uint64_t t_us = 5000000 + i * 100000;
    Append(&t, Record({kMavRawImu, RawImu(t_us, {0, 0, -1000, 100, 0, -200, 0, 0, 0}), 1, 1,
                       false, false, true, kT0_us + t_us}));
  }
  return t;
}

TEST(MavlinkSession, ArdupilotRawImuIsMilliGAndTheCorrectionIsUndone) {
  const MavlinkLog log = Parse(SmallArdupilotLog(20));
  const std::vector<ImuStreamInfo> streams = TlogImuStreams(log);
  ASSERT_EQ(streams.size(), 1u);
  EXPECT_EQ(streams[0].name, "RAW_IMU");
  EXPECT_EQ(streams[0].instance, 0);
  EXPECT_NEAR(streams[0].rate_hz, 10.0, 1e-9);
  EXPECT_DOUBLE_EQ(streams[0].t_start_s, 5.0);
  EXPECT_EQ(streams[0].applied, "INS_ACCOFFS/INS_ACCSCAL, INS_GYROFFS");
  EXPECT_TRUE(streams[0].undoable);
  FlightLogSelection as_logged;
  as_logged.undo_correction = false;
  const Session logged = TlogSession(log, as_logged);
  EXPECT_NEAR(logged.series.acc[0].z(), -9.80665, 1e-6);  // -1000 mG
  EXPECT_NEAR(logged.series.gyr[0].x(), 0.1, 1e-7);       // 100 mrad/s
  const Session raw = TlogSession(log, FlightLogSelection{});
  // acc_board = logged ./ SCAL + OFFS; gyr_board = logged + OFFS.
  EXPECT_NEAR(raw.series.acc[0].x(), 0.0 / 1.25 + 0.5, 1e-6);
  EXPECT_NEAR(raw.series.acc[0].y(), 0.0 / 0.5 - 0.25, 1e-6);
  EXPECT_NEAR(raw.series.acc[0].z(), -9.80665 / 2.0 + 1.0, 1e-6);
  EXPECT_NEAR(raw.series.gyr[0].x(), 0.1 + 0.125, 1e-6);
  EXPECT_NEAR(raw.series.gyr[0].z(), -0.2 - 0.5, 1e-6);
  bool reconstructed = false;
  for (const auto& w : raw.warnings) reconstructed |= w.message.find("reconstructed") != std::string::npos;
  EXPECT_TRUE(reconstructed);
  EXPECT_FALSE(raw.site.has_value());
}

TEST(MavlinkSession, WithoutHeartbeatArdupilotIsRecognisedByItsParameters) {
  Bytes t = SmallArdupilotLog(4);
  const std::size_t heartbeat_records = 2 * (8 + 6 + 9 + 2);
  t.erase(t.begin(), t.begin() + static_cast<std::ptrdiff_t>(heartbeat_records));
  const MavlinkLog log = Parse(t);
  EXPECT_TRUE(log.heartbeat.empty());
  EXPECT_EQ(TlogVehicle(log)->autopilot, kMavAutopilotArdupilotMega);
  EXPECT_EQ(TlogSession(log, FlightLogSelection{}).series.acc_unit, "m/s^2");
}

TEST(MavlinkSession, TheAutopilotIsTheSystemSendingMostImuFrames) {
  Bytes t = SmallArdupilotLog(10);
  // System 2 (a PX4 vehicle) sends 3 RAW_IMU frames and a PX4 heartbeat.
  Append(&t, Record({kMavHeartbeat, Heartbeat(kMavAutopilotPx4), 2, 1}));
  for (int i = 0; i < 3; ++i) {
    Append(&t, Record({kMavRawImu, RawImu(100 + i, {1, 2, 3, 4, 5, 6, 7, 8, 9}), 2, 1}));
  }
  const MavlinkLog log = Parse(t);
  const std::optional<MavlinkVehicle> v = TlogVehicle(log);
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(v->system_id, 1);
  EXPECT_EQ(v->autopilot, kMavAutopilotArdupilotMega);
  EXPECT_EQ(v->imu_frames, 10u);
  EXPECT_EQ(v->other_sources, 1u);
  const std::vector<ImuStreamInfo> streams = TlogImuStreams(log);
  ASSERT_EQ(streams.size(), 1u);
  EXPECT_EQ(streams[0].samples, 10u);
  const Session s = TlogSession(log, FlightLogSelection{});
  EXPECT_EQ(s.series.size(), 10u);
  bool said = false;
  for (const auto& w : s.warnings) said |= w.message.find("other system") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(MavlinkSession, NonArdupilotRawImuIsCountsAndPx4IntParamsAreBitCast) {
  Bytes t;
  Append(&t, Record({kMavHeartbeat, Heartbeat(kMavAutopilotPx4), 1, 1}));
  std::int32_t bits = 42;
  float as_float = 0.0f;
  std::memcpy(&as_float, &bits, sizeof(bits));
  Append(&t, Record({kMavParamValue, ParamValue("CAL_ACC0_ID", as_float, 6), 1, 1}));
  Append(&t, Record({kMavParamValue, ParamValue("CAL_ACC0_XOFF", 0.25f, 9), 1, 1}));
  for (int i = 0; i < 5; ++i) {
    Append(&t, Record({kMavRawImu, RawImu(1000 + 1000 * i, {100, 200, 300, 1, 2, 3, 0, 0, 0}),
                       1, 1}));
  }
  const MavlinkLog log = Parse(t);
  const std::map<std::string, double> params = TlogParams(log);
  EXPECT_EQ(params.at("CAL_ACC0_ID"), 42.0);
  EXPECT_EQ(params.at("CAL_ACC0_XOFF"), 0.25);
  const Session s = TlogSession(log, FlightLogSelection{});
  EXPECT_EQ(s.series.acc_unit, "counts");
  EXPECT_EQ(s.series.acc[0].y(), 200.0f);
  EXPECT_EQ(s.series.gyr[0].z(), 3.0f);
  EXPECT_EQ(TlogImuStreams(log)[0].applied, "");
}

TEST(MavlinkSession, ParametersTakeTheLastValueOfEachNameFromTheVehicle) {
  Bytes t = SmallArdupilotLog(5);
  Append(&t, Record({kMavParamValue, ParamValue("INS_ACCOFFS_X", 0.5f, 9), 1, 1}));
  Append(&t, Record({kMavParamValue, ParamValue("INS_ACCOFFS_Y", 0.25f, 9), 1, 1}));
  Append(&t, Record({kMavParamValue, ParamValue("INS_ACCOFFS_X", 0.75f, 9), 1, 1}));
  Append(&t, Record({kMavParamValue, ParamValue("INS_ACCOFFS_X", 9.0f, 9), 9, 1}));  // other system
  Append(&t, Record({kMavParamValue, ParamValue("", 1.0f, 9), 1, 1}));  // no name: ignored
  Append(&t, Record({kMavParamValue, ParamValue("INS_ACCOFFS_Y_LONGER16", 2.0f, 9), 1, 1}));
  const MavlinkLog log = Parse(t);
  const std::map<std::string, double> params = TlogParams(log);
  EXPECT_EQ(params.at("INS_ACCOFFS_X"), 0.75);
  EXPECT_EQ(params.at("INS_ACCOFFS_Y"), 0.25);
  EXPECT_EQ(params.count(""), 0u);
  EXPECT_EQ(params.at("INS_ACCOFFS_Y_LO"), 2.0);  // param_id holds 16 characters
  EXPECT_EQ(params.size(), 11u);  // SmallArdupilotLog sends ten
}

TEST(MavlinkSession, SiteIsTheMedianOf3dFixes) {
  Bytes t = SmallArdupilotLog(5);
  Append(&t, Record({kMavGpsRawInt, GpsRawInt(0, 0, 0, 1), 1, 1}));  // no fix: ignored
  Append(&t, Record({kMavGpsRawInt, GpsRawInt(-320918845, 1158802882, 3630, 3), 1, 1}));
  Append(&t, Record({kMavGpsRawInt, GpsRawInt(-320918000, 1158802000, 4000, 4), 1, 1}));
  Append(&t, Record({kMavGpsRawInt, GpsRawInt(-320919000, 1158803000, 5000, 3), 1, 1}));
  Append(&t, Record({kMavGpsRawInt, GpsRawInt(100000000, 100000000, 0, 3), 9, 1}));  // other system
  const MavlinkLog log = Parse(t);
  const std::optional<SiteInput> site = SiteFromTlog(log);
  ASSERT_TRUE(site.has_value());
  EXPECT_EQ(site->source, "gps");
  EXPECT_NEAR(site->lat_deg, -32.0918845, 1e-9);
  EXPECT_NEAR(site->lon_deg, 115.8802882, 1e-9);
  EXPECT_NEAR(site->height_m, 4.0, 1e-9);
  EXPECT_TRUE(TlogSession(log, FlightLogSelection{}).site.has_value());
}

TEST(MavlinkSession, Wrapped32BitMicrosecondsAreUnwrapped) {
  Bytes t;
  Append(&t, Record({kMavHeartbeat, Heartbeat(kMavAutopilotArdupilotMega), 1, 1}));
  const std::uint64_t wrap = 1ull << 32;
  for (std::uint64_t t_us : {wrap - 200000, wrap - 100000, std::uint64_t{0}, std::uint64_t{100000}}) {
    Append(&t, Record({kMavRawImu, RawImu(t_us, {0, 0, -1000, 0, 0, 0, 0, 0, 0}), 1, 1}));
  }
  const Session s = TlogSession(Parse(t), FlightLogSelection{});
  ASSERT_EQ(s.series.size(), 4u);
  EXPECT_NEAR(s.series.t_s[2] - s.series.t_s[1], 0.1, 1e-9);
  EXPECT_NEAR(s.series.t_s[3], (wrap + 100000) * 1e-6, 1e-9);
}

// Issue 35 item 7: a time far ahead costs that sample alone (not every later one), a time that
// goes back costs one, and the warning counts them with the first one's time.
TEST(MavlinkSession, BadTimesCostOneSampleEachAndAreSaid) {
  Bytes t;
  Append(&t, Record({kMavHeartbeat, Heartbeat(kMavAutopilotArdupilotMega), 1, 1}));
  for (std::uint64_t t_us : {std::uint64_t{100000}, std::uint64_t{200000},
                             std::uint64_t{900000000000}, std::uint64_t{300000},
                             std::uint64_t{400000}, std::uint64_t{350000},
                             std::uint64_t{500000}, std::uint64_t{600000}}) {
    Append(&t, Record({kMavRawImu, RawImu(t_us, {0, 0, -1000, 0, 0, 0, 0, 0, 0}), 1, 1}));
  }
  const Session s = TlogSession(Parse(t), FlightLogSelection{});
  const std::vector<double> kept = {0.1, 0.2, 0.3, 0.35, 0.5, 0.6};
  ASSERT_EQ(s.series.size(), kept.size());
  for (std::size_t k = 0; k < kept.size(); ++k) EXPECT_NEAR(s.series.t_s[k], kept[k], 1e-12);
  const std::string said =
      "RAW_IMU instance 0: dropped 2 sample(s) whose time did not increase past the last kept "
      "one, or ran ahead of the next (a reboot or a corrupted time); the first with time "
      "900000.000000 s";
  const auto dropped = std::find_if(s.warnings.begin(), s.warnings.end(),
                                    [&](const Notice& n) { return n.message == said; });
  ASSERT_NE(dropped, s.warnings.end()) << ::testing::PrintToString(Messages(s.warnings));
  EXPECT_EQ(dropped->code, "samples_out_of_order");
}

// --- the real log as a session ------------------------------------------------------------------

TEST(MavlinkSession, RealLogStreamsAndSessions) {
  PLUMB_SKIP_IF_ABSENT(kLog);
  const MavlinkLog log = ReadTlog(kLog);
  EXPECT_TRUE(LooksLikeTlog(kLog));
  const std::vector<ImuStreamInfo> streams = TlogImuStreams(log);
  ASSERT_EQ(streams.size(), 3u);
  const char* names[3] = {"RAW_IMU", "SCALED_IMU2", "SCALED_IMU3"};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(streams[k].name, names[k]);
    EXPECT_EQ(streams[k].instance, k);
    EXPECT_EQ(streams[k].samples, 301u);
    EXPECT_NEAR(streams[k].rate_hz, 3.5, 0.1);  // README: about 3.6 Hz
    EXPECT_TRUE(streams[k].undoable);
    EXPECT_FALSE(streams[k].has_temperature);  // v1 frames: no temperature extension
  }
  // The GPS never had a 3D fix in this log (golden fix3d_count = 0): no site.
  EXPECT_EQ(ReadGolden()["GPS_RAW_INT"]["fix3d_count"].get<int>(), 0);
  EXPECT_FALSE(SiteFromTlog(log).has_value());

  const std::map<std::string, double> params = TlogParams(log);
  for (int k = 0; k < 3; ++k) {
    FlightLogSelection sel;
    sel.imu = k;
    sel.undo_correction = false;
    const Session logged = TlogSession(log, sel);
    sel.undo_correction = true;
    const Session raw = TlogSession(log, sel);
    ASSERT_EQ(logged.series.size(), 301u);
    ASSERT_EQ(raw.series.size(), 301u);
    // Disarmed on the bench: the first 20 samples (~6 s) are still. ArduPilot's corrected
    // output reads about g there (IMU2, 0.97 g, is the worst calibrated); the undone one
    // differs by the offsets and scales.
    double logged_norm = 0.0;
    for (int i = 0; i < 20; ++i) logged_norm += logged.series.acc[i].cast<double>().norm() / 20;
    EXPECT_NEAR(logged_norm, 9.80665, k == 0 ? 0.05 : 0.35) << names[k];
    const std::string suffix = k == 0 ? "" : std::to_string(k + 1);
    for (int a = 0; a < 3; ++a) {
      const std::string axis = std::string("_") + "XYZ"[a];
      const double scal = params.at("INS_ACC" + suffix + "SCAL" + axis);
      const double offs = params.at("INS_ACC" + suffix + "OFFS" + axis);
      const double gyr = params.at("INS_GYR" + suffix + "OFFS" + axis);
      EXPECT_NEAR(raw.series.acc[10][a], logged.series.acc[10][a] / scal + offs, 1e-5);
      EXPECT_NEAR(raw.series.gyr[10][a], logged.series.gyr[10][a] + gyr, 1e-6);
    }
    double raw_norm = 0.0;
    for (int i = 0; i < 20; ++i) raw_norm += raw.series.acc[i].cast<double>().norm() / 20;
    EXPECT_NEAR(raw_norm, 9.8, 2.5) << names[k];  // IMU2's INS_ACC2OFFS_Z is 1.55 m/s^2
    // Time base: the message's own time since boot (RAW_IMU time_usec ~1545 s).
    EXPECT_NEAR(raw.series.t_s.front(), 1545.32, 0.01);
  }
  // The summary `plumb info` shows.
  const FlightLogSummary summary = TlogSummary(log);
  EXPECT_EQ(summary.format, "mavlink-tlog");
  EXPECT_EQ(summary.format_detail,
            "MAVLink v1 8164 frames, v2 0 frames (0 signed), 8164 CRC-checked, ArduPilot "
            "(system 1, component 1)");
  EXPECT_EQ(summary.imus.size(), 3u);
  EXPECT_FALSE(summary.site.has_value());
  EXPECT_EQ(summary.params.at("INS_ACC2OFFS_Z"), params.at("INS_ACC2OFFS_Z"));
  EXPECT_EQ(summary.params.count("SYSID_THISMAV"), 0u);
  EXPECT_EQ(summary.messages.size(), log.message_counts.size());
  EXPECT_TRUE(summary.warnings.empty());  // every frame CRC-checked, none skipped
  bool meminfo_named = false;
  for (const auto& [name, n] : summary.messages) meminfo_named |= name == "MEMINFO" && n == 295;
  EXPECT_TRUE(meminfo_named);
  // A time window.
  FlightLogSelection window;
  window.from_s = 1560.0;
  window.to_s = 1580.0;
  const Session part = TlogSession(log, window);
  EXPECT_GE(part.series.t_s.front(), 1560.0);
  EXPECT_LE(part.series.t_s.back(), 1580.0);
  EXPECT_GT(part.series.duration_s(), 18.5);  // samples every ~0.29 s
  // Absent streams and empty windows are input errors naming the log.
  FlightLogSelection missing;
  missing.imu = 3;
  EXPECT_THROW(TlogSession(log, missing), InputError);
  FlightLogSelection by_name;
  by_name.stream = "SCALED_IMU3";  // its only instance (2), whatever imu says
  EXPECT_EQ(TlogSession(log, by_name).source, kLog + " (SCALED_IMU3 instance 2)");
  by_name.stream = "HIGHRES_IMU";
  EXPECT_THROW(TlogSession(log, by_name), InputError);
  FlightLogSelection empty;
  empty.from_s = 1e9;
  EXPECT_THROW(TlogSession(log, empty), InputError);
}

TEST(MavlinkSession, LooksLikeTlogSniffsContent) {
  testing::TempDir dir;
  const Bytes rec = Record({kMavHeartbeat, Heartbeat(3), 1, 1});
  EXPECT_TRUE(LooksLikeTlog(dir.Write("a.bin", std::string(rec.begin(), rec.end()))));
  EXPECT_FALSE(LooksLikeTlog(dir.Write("b.tlog", "\xA3\x95\x80 a DataFlash header")));
  EXPECT_FALSE(LooksLikeTlog(dir.File("absent.tlog")));
}

}  // namespace
}  // namespace plumb::io

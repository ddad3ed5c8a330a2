// ArduPilot DataFlash reader: every real .bin under ../shared/data/ardupilot against golden data
// from an independent Python decoder (tests/data/ardupilot/decode_golden.py, see README.md
// there), damaged copies of real logs, and small hand-built logs for each format character.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "dataflash_builder.h"
#include "io_test_util.h"
#include "plumb/core/error.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/common/log_common.h"

namespace plumb::io {
namespace {

using testing::ReadBytes;
std::string SharedLog(const std::string& name) {
  return testing::SharedLogPath("ardupilot", name);
}
nlohmann::json ReadGolden(const std::string& name) {
  return testing::ReadGoldenJson("ardupilot", name);
}

using testing::Bytes;

// Every input byte is in a decoded record, skipped, or in the dropped truncated record.
void ExpectBytesAccounted(const DataflashLog& log) {
  std::size_t in_records = 0;
  for (const DataflashType& t : log.types) in_records += t.rows * t.length;
  EXPECT_EQ(in_records + log.warnings.bytes_skipped + log.warnings.truncated_bytes,
            log.size_bytes);
}

// --- real logs against the golden JSON -------------------------------------------------------

void ExpectSampleEq(const ImuSeries& s, std::size_t i, const nlohmann::json& g) {
  EXPECT_EQ(s.t_s[i], g["t_s"].get<double>()) << "sample " << i;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(s.acc[i][k], static_cast<float>(g["acc"][k].get<double>())) << "sample " << i;
    EXPECT_EQ(s.gyr[i][k], static_cast<float>(g["gyr"][k].get<double>())) << "sample " << i;
  }
  if (g["temp_c"].is_null()) {
    EXPECT_FALSE(s.has_temperature());
  } else {
    ASSERT_TRUE(s.has_temperature());
    EXPECT_EQ(s.temp_c[i], static_cast<float>(g["temp_c"].get<double>())) << "sample " << i;
  }
}

void ExpectImuMatchesGolden(const DataflashLog& log, const nlohmann::json& golden) {
  const std::vector<DataflashImuInfo> infos = DataflashImuInstances(log);
  ASSERT_EQ(infos.size(), golden["imu"].size());
  for (const DataflashImuInfo& info : infos) {
    const nlohmann::json& g = golden["imu"][std::to_string(info.instance)];
    const ImuSeries s = ImuFromDataflash(log, info.instance);
    ASSERT_EQ(s.size(), g["samples"].get<std::size_t>()) << "instance " << info.instance;
    EXPECT_EQ(info.samples, s.size());  // no log here has repeated IMU times
    EXPECT_GT(info.rate_hz, 0.0);
    ExpectSampleEq(s, 0, g["first"]);
    ExpectSampleEq(s, s.size() - 1, g["last"]);
  }
}

void ExpectCountsMatchGolden(const DataflashLog& log, const nlohmann::json& golden) {
  std::map<std::string, std::size_t> counts;
  for (const auto& [name, n] : log.MessageCounts()) counts[name] += n;
  std::map<std::string, std::size_t> expected;
  for (const auto& [name, n] : golden["message_counts"].items()) {
    expected[name] = n.get<std::size_t>();
  }
  EXPECT_EQ(counts, expected);
}

void ExpectWarningsMatchGolden(const DataflashLog& log, const nlohmann::json& golden) {
  EXPECT_EQ(log.size_bytes, golden["size_bytes"].get<std::size_t>());
  EXPECT_EQ(log.warnings.bytes_skipped, golden["bytes_skipped"].get<std::size_t>());
  EXPECT_EQ(log.warnings.truncated_records, golden["truncated_records"].get<std::size_t>());
  EXPECT_EQ(log.warnings.truncated_bytes, golden["truncated_bytes"].get<std::size_t>());
  EXPECT_EQ(log.warnings.fmt_length_mismatches,
            golden["fmt_length_mismatches"].get<std::size_t>());
  ExpectBytesAccounted(log);
}

void ExpectParamsMatchGolden(const DataflashLog& log, const nlohmann::json& golden) {
  EXPECT_EQ(log.params.size(), golden["param_count"].get<std::size_t>());
  for (const auto& [name, value] : golden["params"].items()) {
    ASSERT_TRUE(log.params.count(name)) << name;
    EXPECT_EQ(log.params.at(name), value.get<double>()) << name;
  }
}

void ExpectExtrasMatchGolden(const DataflashLog& log, const nlohmann::json& golden) {
  if (golden.contains("first_isbh")) {
    const DataflashType* isbh = log.Find("ISBH");
    ASSERT_NE(isbh, nullptr);
    for (const auto& [column, value] : golden["first_isbh"].items()) {
      const int c = isbh->ColumnIndex(column);
      ASSERT_GE(c, 0) << column;
      EXPECT_EQ(isbh->Value(0, c), value.get<double>()) << column;
    }
  }
  if (golden.contains("last_gps")) {
    const DataflashType* gps = log.Find("GPS");
    ASSERT_NE(gps, nullptr);
    for (const char* column : {"Lat", "Lng", "Alt"}) {
      EXPECT_DOUBLE_EQ(gps->Column(column).back(), golden["last_gps"][column].get<double>())
          << column;
    }
  }
}

class DataflashRealLog : public ::testing::TestWithParam<const char*> {};

TEST_P(DataflashRealLog, MatchesIndependentDecoder) {
  const std::string path = SharedLog(GetParam());
  PLUMB_SKIP_IF_ABSENT(path);
  const nlohmann::json golden = ReadGolden(GetParam());
  const DataflashLog log = ReadDataflash(path);
  ExpectCountsMatchGolden(log, golden);
  ExpectWarningsMatchGolden(log, golden);
  ExpectParamsMatchGolden(log, golden);
  ExpectImuMatchesGolden(log, golden);
  ExpectExtrasMatchGolden(log, golden);
}

INSTANTIATE_TEST_SUITE_P(
    AllBins, DataflashRealLog,
    ::testing::Values("plane408_centre_point.BIN", "plane408_pilot_pos.BIN",
                      "copter36_chibios.bin", "copter364_fmuv5.bin",
                      "copter344_pixhawk1_oldformat.bin", "copter462_truncated_isbd.bin",
                      "plane382_pymavlink_test.BIN"));

TEST(Dataflash, ColumnUnitsComeFromFmtuUnitMult) {
  const std::string path = SharedLog("copter462_truncated_isbd.bin");
  PLUMB_SKIP_IF_ABSENT(path);
  const DataflashLog log = ReadDataflash(path);
  const DataflashType* imu = log.Find("IMU");
  ASSERT_NE(imu, nullptr);
  const DataflashColumn& gyr_x = imu->columns[imu->ColumnIndex("GyrX")];
  const DataflashColumn& time = imu->columns[imu->ColumnIndex("TimeUS")];
  EXPECT_EQ(gyr_x.unit, "rad/s");
  EXPECT_EQ(time.unit, "s");
  // The log stores the float 1e-6 widened to double (9.99999997e-07).
  EXPECT_FLOAT_EQ(static_cast<float>(time.multiplier), 1e-6f);
}

// --- damaged copies of a real log ------------------------------------------------------------

// Records of the damaged log are a prefix of the intact log's records, type by type.
void ExpectPrefixOf(const DataflashLog& part, const DataflashLog& whole) {
  for (const DataflashType& t : part.types) {
    const DataflashType* w = whole.Find(t.name);
    ASSERT_NE(w, nullptr) << t.name;
    ASSERT_LE(t.rows, w->rows) << t.name;
    for (std::size_t r = 0; r < t.rows && t.bodies_kept; ++r) {
      ASSERT_EQ(std::memcmp(t.bodies.Row(r), w->bodies.Row(r), t.body_size), 0) << t.name << r;
    }
  }
}

TEST(Dataflash, TruncatedCopyKeepsEveryCompleteRecord) {
  const std::string path = SharedLog("copter364_fmuv5.bin");
  PLUMB_SKIP_IF_ABSENT(path);
  const Bytes full = ReadBytes(path);
  const DataflashLog whole = ParseDataflash(full.data(), full.size(), path);
  ASSERT_FALSE(whole.warnings.any());
  const std::size_t cut = full.size() / 2 + 7;
  const DataflashLog part = ParseDataflash(full.data(), cut, "first half");
  EXPECT_EQ(part.warnings.truncated_records, 1u);
  EXPECT_GT(part.warnings.truncated_bytes, 0u);
  EXPECT_EQ(part.warnings.bytes_skipped, 0u);
  ExpectBytesAccounted(part);
  ExpectPrefixOf(part, whole);
  const ImuSeries s = ImuFromDataflash(part, 0);
  EXPECT_GT(s.size(), 100u);
  EXPECT_LT(s.size(), whole.Find("IMU")->rows);
}

TEST(Dataflash, EveryTruncationOfASmallLogDecodesItsPrefix) {
  const std::string path = SharedLog("plane382_pymavlink_test.BIN");
  PLUMB_SKIP_IF_ABSENT(path);
  const Bytes full = ReadBytes(path);
  const DataflashLog whole = ParseDataflash(full.data(), full.size(), path);
  std::mt19937_64 rng(20240505);
  std::uniform_int_distribution<std::size_t> length(100, full.size());
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t cut = length(rng);
    const DataflashLog part = ParseDataflash(full.data(), cut, "cut");
    EXPECT_EQ(part.warnings.bytes_skipped, 0u) << "cut " << cut;
    ExpectBytesAccounted(part);
    ExpectPrefixOf(part, whole);
  }
}

TEST(Dataflash, GarbledCopyKeepsGoodRecordsAndCountsSkippedBytes) {
  const std::string path = SharedLog("copter36_chibios.bin");
  PLUMB_SKIP_IF_ABSENT(path);
  const Bytes clean = ReadBytes(path);
  const DataflashLog whole = ParseDataflash(clean.data(), clean.size(), path);
  Bytes garbled = clean;
  std::mt19937_64 rng(42);
  // Leave the first 64 KiB (the FMT block) intact, garble 200 bytes after it.
  std::uniform_int_distribution<std::size_t> where(65536, garbled.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int k = 0; k < 200; ++k) garbled[where(rng)] = static_cast<std::uint8_t>(byte(rng));
  const DataflashLog log = ParseDataflash(garbled.data(), garbled.size(), "garbled");
  EXPECT_GT(log.warnings.bytes_skipped, 0u);
  EXPECT_GT(log.warnings.skip_runs, 0u);
  EXPECT_GE(log.warnings.first_skip_offset, 65536u);
  EXPECT_FALSE(log.warnings.Describe().empty());
  ExpectBytesAccounted(log);
  const std::size_t imu_rows = log.Find("IMU")->rows;
  EXPECT_GT(imu_rows, whole.Find("IMU")->rows * 9 / 10);
  const ImuSeries s = ImuFromDataflash(log, 0);
  EXPECT_GT(s.size(), whole.Find("IMU")->rows * 9 / 10);
}

TEST(Dataflash, RandomlyDamagedLogsNeverCrash) {
  const std::string path = SharedLog("copter462_truncated_isbd.bin");
  PLUMB_SKIP_IF_ABSENT(path);
  const Bytes clean = ReadBytes(path);
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::size_t> where(0, clean.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  int parsed = 0;
  for (int trial = 0; trial < 50; ++trial) {
    Bytes damaged = clean;
    for (int k = 0; k < 2000; ++k) damaged[where(rng)] = static_cast<std::uint8_t>(byte(rng));
    try {
      const DataflashLog log = ParseDataflash(damaged.data(), damaged.size(), "damaged");
      ExpectBytesAccounted(log);
      for (const DataflashImuInfo& info : DataflashImuInstances(log)) {
        try {
          EXPECT_LE(ImuFromDataflash(log, info.instance).size(), info.samples);
        } catch (const InputError&) {
          // A damaged FMT can drop the time or Acc columns: a clear error is fine.
        }
      }
      ++parsed;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("no FMT"), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(parsed, 25);
}

// --- errors ----------------------------------------------------------------------------------

TEST(Dataflash, MissingFileIsAnInputError) {
  try {
    ReadDataflash("/nonexistent/plumb/log.bin");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/plumb/log.bin");
    EXPECT_EQ(e.where(), "byte 0");
  }
}

TEST(Dataflash, InputWithoutFmtIsAnInputError) {
  Bytes noise(4096);
  std::mt19937_64 rng(3);
  for (std::uint8_t& b : noise) b = static_cast<std::uint8_t>(rng());
  EXPECT_THROW(ParseDataflash(noise.data(), noise.size(), "noise"), InputError);
  EXPECT_THROW(ParseDataflash(noise.data(), 0, "empty"), InputError);
}

// --- hand-built logs -------------------------------------------------------------------------

using testing::Append;
using testing::FmtRecord;
using testing::Put;
using testing::PutFixed;

TEST(Dataflash, DecodesEveryFormatCharacterWithItsScale) {
  Bytes log = FmtRecord(200, 3 + 1 + 2 + 2 + 4 + 4 + 4 + 8 + 8 + 4, "TST", "bcCeLfdQn",
                        "B8,C1,C2,E1,Lat,F,D,Q,Nm");
  Bytes rec = {0xA3, 0x95, 200};
  Put<std::int8_t>(&rec, -5);
  Put<std::int16_t>(&rec, -1234);
  Put<std::uint16_t>(&rec, 65000);
  Put<std::int32_t>(&rec, -100);
  Put<std::int32_t>(&rec, -353626273);
  Put<float>(&rec, 1.5f);
  Put<double>(&rec, -2.25);
  Put<std::uint64_t>(&rec, 123456789012ull);
  PutFixed(&rec, "ab", 4);
  Append(&log, rec);
  const DataflashLog d = ParseDataflash(log.data(), log.size(), "built");
  EXPECT_FALSE(d.warnings.any());
  const DataflashType* t = d.Find("TST");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->rows, 1u);
  EXPECT_EQ(t->Value(0, 0), -5.0);
  EXPECT_EQ(t->Value(0, 1), -1234 * 0.01);
  EXPECT_EQ(t->Value(0, 2), 65000 * 0.01);
  EXPECT_EQ(t->Value(0, 3), -100 * 0.01);
  EXPECT_EQ(t->Value(0, 4), -353626273 * 1e-7);
  EXPECT_EQ(t->Value(0, 5), 1.5);
  EXPECT_EQ(t->Value(0, 6), -2.25);
  EXPECT_EQ(t->Value(0, 7), 123456789012.0);
  EXPECT_TRUE(std::isnan(t->Value(0, 8)));
  EXPECT_EQ(t->Text(0, 8), "ab");
}

TEST(Dataflash, TrustsFmtLengthAndKeepsFirstFmt) {
  // Declared 3 + 4 + 4 bytes of fields but length 15: 4 trailing bytes per record.
  Bytes log = FmtRecord(201, 15, "LNG", "If", "A,B");
  Append(&log, FmtRecord(201, 11, "LNG", "If", "A,B"));  // conflicting redefinition: ignored
  Append(&log, FmtRecord(202, 2, "BAD", "B", "X"));       // length < 3: ignored
  Append(&log, FmtRecord(203, 7, "UNK", "Bx", "A,B"));    // unknown 'x': A decodable only
  for (std::uint32_t k = 0; k < 3; ++k) {
    Bytes rec = {0xA3, 0x95, 201};
    Put<std::uint32_t>(&rec, k);
    Put<float>(&rec, 0.5f * k);
    Put<std::uint32_t>(&rec, 0xA3A395A3u);  // header-like padding must not matter
    Append(&log, rec);
  }
  Append(&log, Bytes{0xA3, 0x95, 203, 9, 1, 2, 3});
  const DataflashLog d = ParseDataflash(log.data(), log.size(), "built");
  EXPECT_EQ(d.warnings.fmt_length_mismatches, 1u);
  EXPECT_EQ(d.warnings.fmt_conflicts, 1u);
  EXPECT_EQ(d.warnings.fmt_invalid, 1u);
  EXPECT_EQ(d.warnings.fmt_unknown_chars, 1u);
  EXPECT_EQ(d.warnings.bytes_skipped, 0u);
  const DataflashType* t = d.Find("LNG");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->Column("B"), (std::vector<double>{0.0, 0.5, 1.0}));
  const DataflashType* u = d.Find("UNK");
  ASSERT_NE(u, nullptr);
  ASSERT_EQ(u->columns.size(), 1u);
  EXPECT_EQ(u->Value(0, 0), 9.0);
  EXPECT_THROW(t->Column("Z"), Error);
}

TEST(Dataflash, ImuInstancesFromTheIField) {
  Bytes log = FmtRecord(210, 3 + 8 + 1 + 24, "IMU", "QBffffff",
                        "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ");
  for (int k = 0; k < 6; ++k) {
    Bytes rec = {0xA3, 0x95, 210};
    Put<std::uint64_t>(&rec, 1000000 + 2000 * (k / 2));  // both instances at 500 Hz
    Put<std::uint8_t>(&rec, static_cast<std::uint8_t>(k % 2));
    for (int a = 0; a < 6; ++a) Put<float>(&rec, static_cast<float>(10 * k + a));
    Append(&log, rec);
  }
  const DataflashLog d = ParseDataflash(log.data(), log.size(), "built");
  const std::vector<DataflashImuInfo> infos = DataflashImuInstances(d);
  ASSERT_EQ(infos.size(), 2u);
  EXPECT_EQ(infos[1].instance, 1);
  EXPECT_EQ(infos[1].samples, 3u);
  EXPECT_NEAR(infos[1].rate_hz, 500.0, 1e-9);
  const ImuSeries s = ImuFromDataflash(d, 1);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s.t_s[2], 1004000 * 1e-6);
  EXPECT_EQ(s.gyr[2], Vec3f(50, 51, 52));
  EXPECT_EQ(s.acc[2], Vec3f(53, 54, 55));
  EXPECT_FALSE(s.has_temperature());
  EXPECT_THROW(ImuFromDataflash(d, 2), InputError);
}

// --- speed (printed, never asserted) ---------------------------------------------------------

TEST(Dataflash, ReportsReadSpeed) {
  const std::string path = SharedLog("copter36_chibios.bin");
  PLUMB_SKIP_IF_ABSENT(path);
  const Bytes one = ReadBytes(path);
  Bytes big;
  for (int k = 0; k < 30; ++k) Append(&big, one);
  const auto start = std::chrono::steady_clock::now();
  const DataflashLog log = ParseDataflash(big.data(), big.size(), "repeated");
  const auto parsed = std::chrono::steady_clock::now();
  const ImuSeries s = ImuFromDataflash(log, 0);
  const auto done = std::chrono::steady_clock::now();
  const double parse_s = std::chrono::duration<double>(parsed - start).count();
  const double imu_s = std::chrono::duration<double>(done - parsed).count();
  const double mb = static_cast<double>(big.size()) / 1e6;
  std::printf("[ speed    ] %.0f MB parsed in %.3f s = %.0f MB/s; IMU %zu samples in %.3f s\n",
              mb, parse_s, mb / parse_s, s.size(), imu_s);
  EXPECT_GT(s.size(), 0u);
}

}  // namespace
}  // namespace plumb::io

namespace plumb::io {
namespace {

// A file of several read chunks: ReadDataflash (reading forward in chunks, records straddling
// the chunks' ends, resyncs near them) decodes exactly what the in-memory parser does.
TEST(Dataflash, ReadingInBoundedMemoryKeepsEveryByte) {
  using testing::Bytes;
  Bytes log = testing::FmtRecord(201, 3 + 4 + 4 + 4, "BIG", "Iff", "TimeUS,A,B");
  Bytes rec = {0xA3, 0x95, 201};
  const std::size_t target = (std::size_t{5} << 20) + 4096 + 7;
  log.reserve(target + 64);
  for (std::uint32_t k = 0; log.size() < target; ++k) {
    rec.resize(3);
    testing::Put<std::uint32_t>(&rec, k);
    testing::Put<float>(&rec, 0.25f * static_cast<float>(k % 1000));
    testing::Put<float>(&rec, -1.0f * static_cast<float>(k % 77));
    testing::Append(&log, rec);
    if (k % 10007 == 0) testing::Append(&log, Bytes{0x55, 0xA3});  // a resync now and then
  }
  testing::Append(&log, Bytes{0xA3, 0x95, 201, 1, 2});  // a truncated last record
  ::plumb::testing::TempDir dir;
  const std::string path = dir.File("big.bin");
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(log.data()), static_cast<std::streamsize>(log.size()));
  }
  const DataflashLog from_file = ReadDataflash(path);
  const DataflashLog in_memory = ParseDataflash(log.data(), log.size(), path);
  ASSERT_EQ(from_file.types.size(), in_memory.types.size());
  for (std::size_t k = 0; k < in_memory.types.size(); ++k) {
    EXPECT_EQ(from_file.types[k].rows, in_memory.types[k].rows) << k;
    EXPECT_TRUE(from_file.types[k].bodies == in_memory.types[k].bodies) << k;
  }
  EXPECT_EQ(from_file.warnings.bytes_skipped, in_memory.warnings.bytes_skipped);
  EXPECT_EQ(from_file.warnings.skip_runs, in_memory.warnings.skip_runs);
  EXPECT_EQ(from_file.warnings.Describe(), in_memory.warnings.Describe());
  EXPECT_EQ(in_memory.warnings.truncated_records, 1u);
  EXPECT_EQ(from_file.size_bytes, log.size());
  EXPECT_GT(in_memory.Find("BIG")->rows, target / 16);
  EXPECT_GT(in_memory.warnings.skip_runs, 20u);
}

}  // namespace
}  // namespace plumb::io

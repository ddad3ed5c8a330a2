// Every IMU stream of a DataFlash log (DataflashImuStreams / DataflashStream, dataflash.h):
// IMU/IMU2, ACC/GYR paired or separate, the ISBH/ISBD batch sampler on the real ArduCopter 4.6
// log against the independent Python decoder's golden values, and hand-built logs.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "dataflash_builder.h"
#include "io_test_util.h"
#include "plumb/core/error.h"
#include "plumb/io/ardupilot/dataflash.h"

namespace plumb::io {
namespace {

std::string SharedLog(const std::string& name) {
  return testing::SharedLogPath("ardupilot", name);
}

using testing::Bytes;

using testing::Append;
using testing::FmtRecord;
using testing::Put;
using testing::PutFixed;

// ACC/GYR as ArduPilot 4.x logs them ("QBQfff": TimeUS, I, SampleUS, X, Y, Z), 1 kHz.
constexpr std::uint8_t kAcc = 161, kGyr = 162;
constexpr std::uint8_t kRawLength = 3 + 8 + 1 + 8 + 12;

Bytes RawRecord(std::uint8_t type, std::uint8_t instance, std::uint64_t sample_us, float base) {
  Bytes r = {0xA3, 0x95, type};
  Put<std::uint64_t>(&r, sample_us + 7);
  Put<std::uint8_t>(&r, instance);
  Put<std::uint64_t>(&r, sample_us);
  for (int a = 0; a < 3; ++a) Put<float>(&r, base + static_cast<float>(a));
  return r;
}

/// A log with ACC+GYR of instance 0 at the same times and, for instance 1, GYR at other times.
DataflashLog RawLog() {
  Bytes log = FmtRecord(kAcc, kRawLength, "ACC", "QBQfff", "TimeUS,I,SampleUS,AccX,AccY,AccZ");
  Append(&log, FmtRecord(kGyr, kRawLength, "GYR", "QBQfff", "TimeUS,I,SampleUS,GyrX,GyrY,GyrZ"));
  for (std::uint64_t k = 0; k < 5; ++k) {
    Append(&log, RawRecord(kAcc, 0, 1000000 + 1000 * k, 10.0f * k));
    Append(&log, RawRecord(kGyr, 0, 1000000 + 1000 * k + 100, -10.0f * k));
    Append(&log, RawRecord(kAcc, 1, 1000000 + 1000 * k, 1.0f));
    Append(&log, RawRecord(kGyr, 1, 1000000 + 500 * k, 2.0f));  // 2 kHz: not paired
  }
  return ParseDataflash(log.data(), log.size(), "raw.bin");
}

TEST(DataflashStreams, AccAndGyrArePairedOnlyWhenTheirTimesMatch) {
  const DataflashLog log = RawLog();
  std::vector<std::string> listed;
  for (const ImuStreamInfo& s : DataflashImuStreams(log)) {
    listed.push_back(s.name + "/" + std::to_string(s.instance));
  }
  EXPECT_EQ(listed,
            (std::vector<std::string>{"ACC+GYR/0", "ACC/0", "GYR/0", "ACC/1", "GYR/1"}));
  FlightLogSelection pair;  // default of instance 0: the pair
  const ImuSeries s = DataflashStream(log, pair);
  ASSERT_EQ(s.size(), 5u);
  EXPECT_EQ(s.t_s[2], 1002000 * 1e-6);  // accelerometer times (SampleUS)
  EXPECT_EQ(s.acc[2], Vec3f(20, 21, 22));
  EXPECT_EQ(s.gyr[2], Vec3f(-20, -19, -18));
  // Instance 1: GYR at 2 kHz cannot be paired: no ACC+GYR, the default is ACC.
  FlightLogSelection one;
  one.imu = 1;
  const ImuSeries acc_only = DataflashStream(log, one);
  EXPECT_FALSE(acc_only.has_gyro());
  EXPECT_EQ(acc_only.size(), 5u);
  one.stream = "ACC+GYR";
  testing::ExpectInputError([&] { DataflashStream(log, one); }, "raw.bin", "",
                            {"no ACC+GYR of IMU instance 1"});
  one.stream = "GYR";
  testing::ExpectInputError([&] { DataflashStream(log, one); }, "raw.bin", "",
                            {"gyroscope samples only", "select IMU"});
}

// PARM: the last value of each name wins, a name filling its 16 characters (no NUL) included;
// a reader told not to keep PARM collects no parameters (and does not fail).
TEST(DataflashStreams, ParametersTakeTheLastValueOfEachName) {
  Bytes log = FmtRecord(129, 3 + 16 + 4, "PARM", "Nf", "Name,Value");
  const auto parm = [&](const std::string& name, float value) {
    Bytes r = {0xA3, 0x95, 129};
    PutFixed(&r, name, 16);
    Put<float>(&r, value);
    Append(&log, r);
  };
  parm("INS_ACCOFFS_X", 0.5f);
  parm("SIXTEEN_CHARS_AB", 1.0f);
  parm("INS_ACCOFFS_X", 0.25f);
  parm("SIXTEEN_CHARS_AB", 2.0f);
  parm("INS_ACCOFFS_Y", -1.0f);
  const DataflashLog d = ParseDataflash(log.data(), log.size(), "parm.bin");
  const std::map<std::string, double> expected = {
      {"INS_ACCOFFS_X", 0.25}, {"INS_ACCOFFS_Y", -1.0}, {"SIXTEEN_CHARS_AB", 2.0}};
  EXPECT_EQ(d.params, expected);
  RecordFilter no_parm;
  no_parm.keep = [](std::string_view name) { return name != "PARM"; };
  const DataflashLog without = ParseDataflash(log.data(), log.size(), "parm.bin", no_parm);
  EXPECT_TRUE(without.params.empty());
  EXPECT_EQ(without.Find("PARM")->rows, 5u);
}

TEST(DataflashStreams, StreamsSayWhatArduPilotAppliedAndWhetherItCanBeUndone) {
  Bytes log = FmtRecord(kAcc, kRawLength, "ACC", "QBQfff", "TimeUS,I,SampleUS,AccX,AccY,AccZ");
  Append(&log, FmtRecord(129, 3 + 16 + 4, "PARM", "Nf", "Name,Value"));
  const auto parm = [&](const std::string& name, float value) {
    Bytes r = {0xA3, 0x95, 129};
    PutFixed(&r, name, 16);
    Put<float>(&r, value);
    Append(&log, r);
  };
  for (const char* axis : {"_X", "_Y", "_Z"}) {
    parm(std::string("INS_ACCOFFS") + axis, 0.1f);
    parm(std::string("INS_ACCSCAL") + axis, 1.01f);
  }
  parm("AHRS_ORIENTATION", 2);
  parm("INS_TCAL1_ENABLE", 1);
  for (std::uint64_t k = 0; k < 3; ++k) Append(&log, RawRecord(kAcc, 0, 1000 * k + 1000, 0.0f));
  const DataflashLog d = ParseDataflash(log.data(), log.size(), "applied.bin");
  const std::vector<ImuStreamInfo> streams = DataflashImuStreams(d);
  ASSERT_EQ(streams.size(), 1u);
  EXPECT_EQ(streams[0].applied, "INS_ACCOFFS/INS_ACCSCAL, AHRS_ORIENTATION=2 (YAW_90), INS_TCAL1");
  // The temperature calibration is on and ACC has no temperature: not undoable.
  EXPECT_FALSE(streams[0].undoable);
  EXPECT_FALSE(streams[0].has_gyro);
  EXPECT_NEAR(streams[0].rate_hz, 1000.0, 1e-6);
}

// --- the batch sampler ------------------------------------------------------------------------

TEST(DataflashStreams, BatchSamplerMatchesIndependentDecoder) {
  const std::string path = SharedLog("copter462_truncated_isbd.bin");
  PLUMB_SKIP_IF_ABSENT(path);
  std::ifstream in(std::string(PLUMB_SOURCE_DIR) +
                   "/tests/data/ardupilot/copter462_truncated_isbd.bin.golden.json");
  const nlohmann::json golden = nlohmann::json::parse(in)["isbd"]["1/0"];
  const DataflashLog log = ReadDataflash(path);
  std::optional<ImuStreamInfo> isbd;
  for (const ImuStreamInfo& s : DataflashImuStreams(log)) {
    if (s.name == "ISBD_GYR") isbd = s;
  }
  ASSERT_TRUE(isbd.has_value());
  EXPECT_EQ(isbd->instance, 0);
  EXPECT_EQ(isbd->samples, golden["samples"].get<std::size_t>());
  EXPECT_FLOAT_EQ(static_cast<float>(isbd->rate_hz), 2000.315f);  // the log's README: 2000.3 Hz
  EXPECT_FALSE(isbd->has_accel);
  EXPECT_EQ(isbd->applied, "INS_GYROFFS");
  EXPECT_DOUBLE_EQ(isbd->t_start_s, golden["first"]["t_s"].get<double>());
  EXPECT_DOUBLE_EQ(isbd->t_end_s, golden["last"]["t_s"].get<double>());
  FlightLogSelection gyro_only;
  gyro_only.stream = "ISBD_GYR";
  testing::ExpectInputError([&] { DataflashStream(log, gyro_only); }, path, "",
                            {"gyroscope samples only"});
}

TEST(DataflashStreams, BatchSamplerValuesAreInt16OverMultiplier) {
  // One accelerometer batch of 40 samples in two ISBD records, mul 100, 400 Hz.
  Bytes log = FmtRecord(164, 31, "ISBH", "QHBBHHQf",
                        "TimeUS,N,type,instance,mul,smp_cnt,SampleUS,smp_rate");
  Append(&log, FmtRecord(165, 207, "ISBD", "QHHaaa", "TimeUS,N,seqno,x,y,z"));
  Bytes h = {0xA3, 0x95, 164};
  Put<std::uint64_t>(&h, 5000000);
  Put<std::uint16_t>(&h, 3);    // N
  Put<std::uint8_t>(&h, 0);     // accelerometer
  Put<std::uint8_t>(&h, 2);     // instance
  Put<std::uint16_t>(&h, 100);  // mul
  Put<std::uint16_t>(&h, 40);   // smp_cnt
  Put<std::uint64_t>(&h, 4000000);
  Put<float>(&h, 400.0f);
  Append(&log, h);
  for (std::uint16_t seq = 0; seq < 2; ++seq) {
    Bytes d = {0xA3, 0x95, 165};
    Put<std::uint64_t>(&d, 5000100 + seq);
    Put<std::uint16_t>(&d, 3);
    Put<std::uint16_t>(&d, seq);
    for (int axis = 0; axis < 3; ++axis) {
      for (int k = 0; k < 32; ++k) {
        Put<std::int16_t>(&d, static_cast<std::int16_t>((axis + 1) * (seq * 32 + k)));
      }
    }
    Append(&log, d);
  }
  const DataflashLog d = ParseDataflash(log.data(), log.size(), "isb.bin");
  FlightLogSelection selection;
  selection.imu = 2;
  const ImuSeries s = DataflashStream(d, selection);
  ASSERT_EQ(s.size(), 40u);  // samples 40..63 of the second record are past smp_cnt
  EXPECT_FALSE(s.has_gyro());
  EXPECT_DOUBLE_EQ(s.t_s[39], 4.0 + 39 / 400.0);
  EXPECT_FLOAT_EQ(s.acc[39].x(), 39 / 100.0f);
  EXPECT_FLOAT_EQ(s.acc[39].z(), 3 * 39 / 100.0f);
}

// --- IMU messages ---------------------------------------------------------------------------

TEST(DataflashStreams, OldFormatImuAndImu2AreInstancesZeroAndOne) {
  const std::string path = SharedLog("plane408_centre_point.BIN");
  PLUMB_SKIP_IF_ABSENT(path);
  const DataflashLog log = ReadDataflash(path);
  FlightLogSelection imu2;
  imu2.stream = "IMU2";  // names its instance by itself
  const std::optional<ImuStreamInfo> info = FindDataflashStream(log, imu2);
  ASSERT_TRUE(info.has_value());
  EXPECT_EQ(info->instance, 1);
  EXPECT_TRUE(info->has_temperature);
  EXPECT_TRUE(info->undoable);
  const ImuSeries s = DataflashStream(log, imu2);
  EXPECT_EQ(s.size(), info->samples);
  imu2.from_s = s.t_s.front() + 10.0;
  imu2.to_s = s.t_s.front() + 20.0;
  const ImuSeries part = DataflashStream(log, imu2);
  EXPECT_GE(part.t_s.front(), *imu2.from_s);
  EXPECT_LE(part.t_s.back(), *imu2.to_s);
  imu2.stream = "IMU7";
  testing::ExpectInputError([&] { DataflashStream(log, imu2); }, path, "", {"no IMU7"});
}

}  // namespace
}  // namespace plumb::io

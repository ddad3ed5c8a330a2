// ArduPilot TEXT logs (.log): the two real logs under ../shared/data/ardupilot against golden
// data from the independent Python decoder (tests/data/ardupilot/decode_golden.py), and small
// hand-written logs for each rule of ParseDataflashText (dataflash.h).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "io_test_util.h"
#include "plumb/core/error.h"
#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"

namespace plumb::io {
namespace {

std::string SharedLog(const std::string& name) {
  return testing::SharedLogPath("ardupilot", name);
}
nlohmann::json ReadGolden(const std::string& name) {
  return testing::ReadGoldenJson("ardupilot", name);
}

DataflashLog Parse(const std::string& text) {
  return ParseDataflashText(text.data(), text.size(), "built.log");
}

// --- real logs against the golden JSON -------------------------------------------------------

void ExpectSampleEq(const ImuSeries& s, std::size_t i, const nlohmann::json& g) {
  EXPECT_EQ(s.t_s[i], g["t_s"].get<double>()) << "sample " << i;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(s.acc[i][k], static_cast<float>(g["acc"][k].get<double>())) << "sample " << i;
    EXPECT_EQ(s.gyr[i][k], static_cast<float>(g["gyr"][k].get<double>())) << "sample " << i;
  }
  EXPECT_EQ(s.has_temperature(), !g["temp_c"].is_null());
}

void ExpectCountsAndWarnings(const DataflashLog& log, const nlohmann::json& golden) {
  const auto message_counts = log.MessageCounts();
  const std::map<std::string, std::size_t> counts(message_counts.begin(), message_counts.end());
  EXPECT_EQ(counts, (golden["message_counts"].get<std::map<std::string, std::size_t>>()));
  EXPECT_EQ(log.size_bytes, golden["size_bytes"].get<std::size_t>());
  EXPECT_EQ(log.warnings.text_header_lines, golden["text_header_lines"].get<std::size_t>());
  EXPECT_EQ(log.warnings.text_bad_lines, golden["text_bad_lines"].get<std::size_t>());
  EXPECT_EQ(log.warnings.text_first_bad_line, golden["text_first_bad_line"].get<std::size_t>());
  EXPECT_EQ(log.warnings.text_mode_names, golden["text_mode_names"].get<std::size_t>());
}

void ExpectParams(const DataflashLog& log, const nlohmann::json& golden) {
  EXPECT_EQ(log.params.size(), golden["param_count"].get<std::size_t>());
  for (const auto& [name, value] : golden["params"].items()) {
    ASSERT_TRUE(log.params.count(name)) << name;
    if (value.is_string()) {
      EXPECT_TRUE(std::isnan(log.params.at(name))) << name << " should stay NaN";
    } else {
      EXPECT_EQ(log.params.at(name), value.get<double>()) << name;
    }
  }
}

void ExpectImu(const DataflashLog& log, const nlohmann::json& golden) {
  for (const auto& [instance, g] : golden["imu"].items()) {
    const ImuSeries s = ImuFromDataflash(log, std::stoi(instance));
    ASSERT_EQ(s.size(), g["samples"].get<std::size_t>()) << "instance " << instance;
    ExpectSampleEq(s, 0, g["first"]);
    ExpectSampleEq(s, s.size() - 1, g["last"]);
  }
  for (const auto& name : golden["imu_defined_without_rows"]) {
    const DataflashType* t = log.Find(name.get<std::string>());
    ASSERT_NE(t, nullptr) << name;
    EXPECT_EQ(t->rows, 0u) << name;
  }
  if (golden.contains("last_gps")) {
    const DataflashType* gps = log.Find("GPS");
    ASSERT_NE(gps, nullptr);
    for (const char* column : {"Lat", "Lng", "Alt"}) {
      EXPECT_EQ(gps->Column(column).back(), golden["last_gps"][column].get<double>()) << column;
    }
  }
}

class DataflashTextRealLog : public ::testing::TestWithParam<const char*> {};

TEST_P(DataflashTextRealLog, MatchesIndependentDecoder) {
  const std::string path = SharedLog(GetParam());
  PLUMB_SKIP_IF_ABSENT(path);
  EXPECT_TRUE(LooksLikeDataflashText(path));
  EXPECT_FALSE(LooksLikeDataflash(path));
  const nlohmann::json golden = ReadGolden(GetParam());
  const DataflashLog log = ReadDataflashText(path);
  ExpectCountsAndWarnings(log, golden);
  ExpectParams(log, golden);
  ExpectImu(log, golden);
}

INSTANTIATE_TEST_SUITE_P(BothLogs, DataflashTextRealLog,
                         ::testing::Values("copter311_nan.log", "copter31_no_imu_rows.log"));

TEST(DataflashText, BinaryLogsAreNotTextLogs) {
  const std::string path = SharedLog("plane382_pymavlink_test.BIN");
  PLUMB_SKIP_IF_ABSENT(path);
  EXPECT_FALSE(LooksLikeDataflashText(path));
  EXPECT_FALSE(LooksLikeDataflashText("/nonexistent/plumb/log.log"));
}

TEST(DataflashText, LogWithImuFmtButNoRowsSaysSoClearly) {
  const std::string path = SharedLog("copter31_no_imu_rows.log");
  PLUMB_SKIP_IF_ABSENT(path);
  const DataflashLog log = ReadDataflashText(path);
  const std::vector<ImuStreamInfo> streams = DataflashImuStreams(log);
  ASSERT_EQ(streams.size(), 1u);
  EXPECT_EQ(streams[0].name, "IMU");
  EXPECT_EQ(streams[0].samples, 0u);
  testing::ExpectInputError([&] { ImuFromDataflash(log, 0); }, path, "",
                            {"defines IMU", "no IMU rows"});
  testing::ExpectInputError([&] { ArdupilotSession(log, FlightLogSelection{}); }, path, "",
                            {"defines IMU", "no IMU rows"});
}

TEST(DataflashText, NanLogGivesASessionWithTheInsCorrectionUndone) {
  const std::string path = SharedLog("copter311_nan.log");
  PLUMB_SKIP_IF_ABSENT(path);
  const DataflashLog log = ReadDataflashText(path);
  FlightLogSelection second;
  second.imu = 1;
  const Session s = ArdupilotSession(log, second);
  EXPECT_EQ(s.series.size(), 705u);
  const ImuSeries logged = ImuFromDataflash(log, 1);
  const double scal = log.params.at("INS_ACC2SCAL_Z");
  const double offs = log.params.at("INS_ACC2OFFS_Z");
  EXPECT_NEAR(s.series.acc[0].z(), logged.acc[0].z() / scal + offs, 1e-5);
}

// --- hand-written logs -----------------------------------------------------------------------

const char* const kFmtHeader =
    "ArduCopter V3.1\r\n"
    "\r\n"
    "FMT, 128, 89, FMT, BBnNZ, Type,Length,Name,Format\r\n"
    "FMT, 129, 23, PARM, Nf, Name,Value\r\n";

TEST(DataflashText, EncodesEveryFormatCharacterAsTheBinaryLayout) {
  const std::string text = std::string(kFmtHeader) +
                           "FMT, 200, 42, TST, bcCeLfdQnM, B8,C1,C2,E1,Lat,F,D,Q,Nm,Mode\n"
                           "TST, -5, -12.34, 650.00, -1.00, -35.3626273, 1.5, -2.25, "
                           "123456789012, ab, 7\n"
                           "TST, 1, 0, 0, 0, 0, NaN, nan, 0, , Stabilize\n";
  const DataflashLog d = Parse(text);
  const DataflashType* t = d.Find("TST");
  ASSERT_NE(t, nullptr);
  ASSERT_EQ(t->rows, 2u);
  EXPECT_EQ(t->Value(0, 0), -5.0);
  EXPECT_EQ(t->Value(0, 1), -1234 * 0.01);
  EXPECT_EQ(t->Value(0, 2), 65000 * 0.01);
  EXPECT_EQ(t->Value(0, 3), -100 * 0.01);
  EXPECT_EQ(t->Value(0, 4), -353626273 * 1e-7);
  EXPECT_EQ(t->Value(0, 5), 1.5);
  EXPECT_EQ(t->Value(0, 6), -2.25);
  EXPECT_EQ(t->Value(0, 7), 123456789012.0);
  EXPECT_EQ(t->Text(0, 8), "ab");
  EXPECT_EQ(t->Value(0, 9), 7.0);
  EXPECT_TRUE(std::isnan(t->Value(1, 5)));  // NaN stays NaN
  EXPECT_TRUE(std::isnan(t->Value(1, 6)));
  EXPECT_EQ(t->Value(1, 9), 255.0);  // a mode name
  EXPECT_EQ(d.warnings.text_mode_names, 1u);
  EXPECT_EQ(d.warnings.text_header_lines, 1u);
  EXPECT_EQ(d.warnings.text_bad_lines, 0u);
}

TEST(DataflashText, MalformedLinesAreSkippedAndCountedWithTheFirstLineNumber) {
  const std::string text = std::string(kFmtHeader) +                      // lines 1-4
                           "FMT, 131, 31, IMU, Iffffff, TimeMS,GyrX,GyrY,GyrZ,AccX,AccY,AccZ\n"
                           "IMU, 100, 0, 0, 0, 0, 0, -9.8\n"              // 6 good
                           "IMU, 120, 0, 0, 0, 0, oops, -9.8\n"           // 7 bad value
                           "IMU, 140, 0, 0, 0, 0, 0\n"                    // 8 too few
                           "IMU, 160, 0, 0, 0, 0, 0, -9.8, 4\n"           // 9 too many
                           "XYZ, 1, 2\n"                                  // 10 no FMT
                           "IMU, -1, 0, 0, 0, 0, 0, -9.8\n"               // 11 I < 0
                           "IMU, 1.5, 0, 0, 0, 0, 0, -9.8\n"              // 12 not integral
                           "IMU, 180, 0, 0, 0, 0, 0, 1e39\n"              // 13 beyond float
                           "PARM, INS_ACCOFFS_X, 0.5\n"                   // 14 good
                           "PARM, A_NAME_LONGER_THAN_16, 1\n"             // 15 truncated name
                           "IMU, 200, 0, 0, 0, 0, 0, -9.8, \n";           // 16 good (trailing)
  const DataflashLog d = Parse(text);
  EXPECT_EQ(d.warnings.text_bad_lines, 7u);
  EXPECT_EQ(d.warnings.text_first_bad_line, 7u);
  EXPECT_NE(d.warnings.text_first_bad_what.find("AccY"), std::string::npos)
      << d.warnings.text_first_bad_what;
  ASSERT_NE(d.Find("IMU"), nullptr);
  EXPECT_EQ(d.Find("IMU")->Column("TimeMS"), (std::vector<double>{100, 200}));
  EXPECT_EQ(d.params.at("INS_ACCOFFS_X"), 0.5);
  EXPECT_EQ(d.params.count("A_NAME_LONGER_TH"), 1u);
  bool described = false;
  for (const std::string& w : d.warnings.Describe()) {
    described = described || w.find("line 7") != std::string::npos;
  }
  EXPECT_TRUE(described);
}

TEST(DataflashText, ANumericModeMustBeAValidModeNumber) {
  const std::string text = std::string(kFmtHeader) +
                           "FMT, 3, 6, MODE, Mh, Mode,ThrCrs\n"
                           "MODE, 5, 424\n"          // good
                           "MODE, 300, 424\n"        // a number, out of range: bad
                           "MODE, 1.5, 424\n"        // a number, not integral: bad
                           "MODE, LOITER, 424\n";    // a name: 255
  const DataflashLog d = Parse(text);
  ASSERT_NE(d.Find("MODE"), nullptr);
  EXPECT_EQ(d.Find("MODE")->Column("Mode"), (std::vector<double>{5, 255}));
  EXPECT_EQ(d.warnings.text_bad_lines, 2u);
  EXPECT_EQ(d.warnings.text_first_bad_line, 7u);
  EXPECT_EQ(d.warnings.text_mode_names, 1u);
}

TEST(DataflashText, LastTextColumnTakesTheRestOfTheLine) {
  const std::string text = std::string(kFmtHeader) +
                           "FMT, 132, 67, MSG, Z, Message\n"
                           "MSG, Frame: QUAD, armed, ok\n"
                           "FMT, 10, 3, STRT, , \n"
                           "STRT\n";
  const DataflashLog d = Parse(text);
  ASSERT_NE(d.Find("MSG"), nullptr);
  EXPECT_EQ(d.Find("MSG")->Text(0, 0), "Frame: QUAD, armed, ok");
  ASSERT_NE(d.Find("STRT"), nullptr);
  EXPECT_EQ(d.Find("STRT")->rows, 1u);
  EXPECT_EQ(d.warnings.text_bad_lines, 0u);
}

TEST(DataflashText, FmtRulesMatchTheBinaryReader) {
  const std::string text = std::string(kFmtHeader) +
                           "FMT, 201, 15, LNG, If, A,B\n"      // length 15 > 3 + 8: mismatch
                           "FMT, 201, 11, LNG, If, A,B\n"      // redefinition: ignored
                           "FMT, 202, 2, BAD, B, X\n"          // length < 3: ignored
                           "FMT, 203, 7, TOOLONG, B, X\n"      // name > 4: malformed
                           "FMT, 204, 7, LNG, B, X\n"          // known name, new id: ignored
                           "LNG, 3, 0.5\n";
  const DataflashLog d = Parse(text);
  EXPECT_EQ(d.warnings.fmt_length_mismatches, 1u);
  EXPECT_EQ(d.warnings.fmt_conflicts, 2u);
  EXPECT_EQ(d.warnings.fmt_invalid, 1u);
  EXPECT_EQ(d.warnings.text_bad_lines, 1u);
  const DataflashType* t = d.Find("LNG");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->length, 15u);
  EXPECT_EQ(t->Column("B"), (std::vector<double>{0.5}));
}

TEST(DataflashText, InputWithoutFmtIsAnInputError) {
  testing::ExpectInputError([] { Parse("hello\nworld\n"); }, "built.log", "line 2",
                            {"no valid FMT line"});
  testing::ExpectInputError([] { Parse(""); }, "built.log", "line 1", {"no valid FMT line"});
  testing::ExpectInputError([] { ReadDataflashText("/nonexistent/plumb/log.log"); },
                            "/nonexistent/plumb/log.log", "", {"cannot open"});
}

TEST(DataflashText, RandomlyDamagedLogsNeverCrash) {
  const std::string path = SharedLog("copter311_nan.log");
  PLUMB_SKIP_IF_ABSENT(path);
  std::ifstream in(path, std::ios::binary);
  const std::string clean((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::size_t> where(0, clean.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  int parsed = 0;
  for (int trial = 0; trial < 30; ++trial) {
    std::string damaged = clean;
    for (int k = 0; k < 300; ++k) damaged[where(rng)] = static_cast<char>(byte(rng));
    try {
      const DataflashLog log = ParseDataflashText(damaged.data(), damaged.size(), "damaged");
      EXPECT_GT(log.warnings.text_bad_lines, 0u);
      for (const ImuStreamInfo& info : DataflashImuStreams(log)) {
        FlightLogSelection selection;
        selection.imu = info.instance;
        selection.stream = info.name;
        try {
          EXPECT_LE(DataflashStream(log, selection).size(), info.samples);
        } catch (const InputError&) {
        }
      }
      ++parsed;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("no valid FMT"), std::string::npos) << e.what();
    }
  }
  EXPECT_GT(parsed, 20);
}

}  // namespace
}  // namespace plumb::io

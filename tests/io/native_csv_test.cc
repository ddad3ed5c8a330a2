#include "plumb/io/text/native_csv.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "io_test_util.h"
#include "plumb/core/error.h"

namespace plumb::io {
namespace {

using testing::ExpectInputError;
using testing::TempDir;

// A deterministic session: unix-like times with jitter, values over many magnitudes.
Session RandomSession(std::size_t n, bool gyro, bool temperature) {
  std::mt19937_64 rng(20240611);
  std::normal_distribution<float> unit(0.0f, 1.0f);
  std::uniform_real_distribution<double> jitter_s(0.0, 1e-4);
  Session s;
  double t_s = 1535630275.916451;
  for (std::size_t i = 0; i < n; ++i) {
    t_s += 0.01 + jitter_s(rng);
    s.series.t_s.push_back(t_s);
    const float magnitude = std::pow(10.0f, static_cast<float>(i % 13) - 6.0f);
    s.series.acc.emplace_back(9.80665f * unit(rng), magnitude * unit(rng), -9.8f + unit(rng));
    if (gyro) s.series.gyr.emplace_back(magnitude * unit(rng), 1e-3f * unit(rng), unit(rng));
    if (temperature) s.series.temp_c.push_back(25.0f + unit(rng));
  }
  return s;
}

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void ExpectIdentical(const ImuSeries& a, const ImuSeries& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.gyr.size(), b.gyr.size());
  ASSERT_EQ(a.temp_c.size(), b.temp_c.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.t_s[i], b.t_s[i]) << "sample " << i;
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(SameBits(a.acc[i][k], b.acc[i][k])) << "sample " << i << " acc " << k;
      if (a.has_gyro()) ASSERT_TRUE(SameBits(a.gyr[i][k], b.gyr[i][k])) << "sample " << i;
    }
    if (a.has_temperature()) ASSERT_TRUE(SameBits(a.temp_c[i], b.temp_c[i])) << "sample " << i;
  }
}

TEST(NativeCsv, RoundTripIsBitExact) {
  TempDir dir;
  const Session written = RandomSession(5000, true, true);
  const std::string path = dir.File("session.csv");
  WriteNativeCsv(path, written);
  const Session read = ReadNativeCsv(path);
  EXPECT_EQ(read.source, path);
  EXPECT_TRUE(read.warnings.empty());
  ExpectIdentical(written.series, read.series);
}

TEST(NativeCsv, TheBoardsOtherImusRoundTripBitExact) {
  // SPEC 6: IMU k in acc{k}_x.. on IMU 0's time column; one without gyroscope, one with.
  TempDir dir;
  Session written = RandomSession(2000, true, true);
  Session second = RandomSession(2000, false, true);
  Session third = RandomSession(2000, true, false);
  second.series.t_s = third.series.t_s = written.series.t_s;
  std::reverse(second.series.acc.begin(), second.series.acc.end());
  written.other_imus = {BoardImu{1, "", second.series, {}}, BoardImu{2, "", third.series, {}}};
  const std::string path = dir.File("board.csv");
  WriteNativeCsv(path, written);
  const Session read = ReadNativeCsv(path);
  ExpectIdentical(written.series, read.series);
  ASSERT_EQ(read.other_imus.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(read.other_imus[i].instance, static_cast<int>(i + 1));
    ExpectIdentical(written.other_imus[i].series, read.other_imus[i].series);
  }
  EXPECT_EQ(read.other_imus[0].name, "acc1_x..");
}

TEST(NativeCsv, AnotherImuOnOtherStampsIsNotWritten) {
  TempDir dir;
  Session written = RandomSession(10, true, false);
  Session other = RandomSession(10, true, false);
  other.series.t_s[4] += 1e-3;
  written.other_imus = {BoardImu{1, "", other.series, {}}};
  const std::string path = dir.File("board.csv");
  try {
    WriteNativeCsv(path, written);
    ADD_FAILURE() << "written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("IMU 1's stamps are not IMU 0's"), std::string::npos);
  }
}

TEST(NativeCsv, AnotherImusColumnsByNameAndTheFirstGapEndsThem) {
  // acc1 and acc2 in any order; acc4 without acc3 is not read as an IMU.
  TempDir dir;
  const std::string path = dir.Write("board.csv",
                                     "\xEF\xBB\xBF# board\n"
                                     "acc2_z,time_s,acc_x,acc_y,acc_z,acc1_x,acc1_y,acc1_z,acc2_x,"
                                     "acc2_y,acc4_x,temp1_c\n"
                                     "-9.5,0.5,0.1,0.2,-9.8,1,2,3,4,5,6,30.5\n"
                                     "-9.6,0.6,0.1,0.2,-9.8,1,2,3,4,5,6,30.75\n");
  const Session s = ReadNativeCsv(path);
  ASSERT_EQ(s.other_imus.size(), 2u);
  EXPECT_EQ(s.other_imus[0].series.acc[1], Vec3f(1, 2, 3));
  EXPECT_EQ(s.other_imus[0].series.temp_c[1], 30.75f);
  EXPECT_EQ(s.other_imus[1].series.acc[0], Vec3f(4, 5, -9.5f));
  EXPECT_FALSE(s.other_imus[1].series.has_temperature());
  EXPECT_DOUBLE_EQ(s.other_imus[1].series.t_s[1], 0.6);
}

TEST(NativeCsv, AnotherImuMissingAnAxisIsAnErrorNamingIt) {
  TempDir dir;
  const std::string path = dir.Write("board.csv",
                                     "time_s,acc_x,acc_y,acc_z,acc1_x,acc1_y\n"
                                     "0.5,0.1,0.2,-9.8,1,2\n");
  try {
    ReadNativeCsv(path);
    ADD_FAILURE() << "read";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find("acc1_z"), std::string::npos) << e.what();
  }
}

TEST(NativeCsv, RoundTripAccelerometerOnly) {
  TempDir dir;
  const Session written = RandomSession(300, false, false);
  const std::string path = dir.File("acc_only.csv");
  WriteNativeCsv(path, written);
  const Session read = ReadNativeCsv(path);
  EXPECT_FALSE(read.series.has_gyro());
  EXPECT_FALSE(read.series.has_temperature());
  ExpectIdentical(written.series, read.series);
}

TEST(NativeCsv, ReadsColumnsByNameInAnyOrder) {
  TempDir dir;
  const std::string path = dir.Write("reordered.csv",
                                     "acc_z,time_s,temp_c,acc_x,acc_y\r\n"
                                     "-9.8,0.5,31.5,0.1,0.2\r\n"
                                     "# a comment line\r\n"
                                     "\r\n"
                                     "-9.7,0.6,31.25,0.3,0.4");
  const Session s = ReadNativeCsv(path);
  ASSERT_EQ(s.series.size(), 2u);
  EXPECT_FALSE(s.series.has_gyro());
  EXPECT_DOUBLE_EQ(s.series.t_s[1], 0.6);
  EXPECT_EQ(s.series.acc[1], Vec3f(0.3f, 0.4f, -9.7f));
  EXPECT_EQ(s.series.temp_c[0], 31.5f);
}

TEST(NativeCsv, ByteOrderMarkAndNanRowsOnRequest) {
  TempDir dir;
  const std::string path = dir.Write("bom.csv",
                                     "\xEF\xBB\xBFtime_s,acc_x,acc_y,acc_z\n"
                                     "1,0,0,-9.8\n2,NaN,0,-9.8\n3,0,0,-9.8\n");
  TextTableOptions options = NativeCsvOptions();
  options.allow_nan_rows = true;
  const Session s = ReadTextTable(path, options);
  ASSERT_EQ(s.series.size(), 2u);
  EXPECT_EQ(s.series.t_s[1], 3.0);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].code, "nan_rows_skipped");
  EXPECT_NE(s.warnings[0].message.find("skipped 1 rows with NaN or infinite values (first at line 3)"),
            std::string::npos)
      << s.warnings[0].message;
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 3", {"NaN or infinite"});
}

TEST(NativeCsv, WriteRejectsInconsistentSeries) {
  TempDir dir;
  Session s = RandomSession(10, true, false);
  s.series.gyr.pop_back();
  const std::string path = dir.File("bad.csv");
  EXPECT_THROW(WriteNativeCsv(path, s), Error);
  EXPECT_FALSE(std::filesystem::exists(path));
}

// --- bad input (SPEC section 8) -------------------------------------------------------------

constexpr const char* kHeader = "time_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n";
constexpr const char* kRow1 = "0.00,0.1,0.2,-9.8,0.01,0.02,0.03\n";
constexpr const char* kRow2 = "0.01,0.1,0.2,-9.8,0.01,0.02,0.03\n";

// Writes a native CSV whose line 4 (after the header and two good rows) is `bad_row`.
std::string WithBadRow(const TempDir& dir, const std::string& bad_row) {
  return dir.Write("bad.csv", std::string(kHeader) + kRow1 + kRow2 + bad_row + "\n");
}

TEST(NativeCsvBadInput, MissingFile) {
  TempDir dir;
  const std::string path = dir.File("absent.csv");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "", {"cannot open", "No such file"});
}

TEST(NativeCsvBadInput, EmptyFile) {
  TempDir dir;
  const std::string path = dir.Write("empty.csv", "");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "", {"empty file"});
  const std::string blank = dir.Write("blank.csv", "\n  \n");
  ExpectInputError([&] { ReadNativeCsv(blank); }, blank, "", {"empty file"});
}

TEST(NativeCsvBadInput, HeaderWithoutDataRows) {
  TempDir dir;
  const std::string path = dir.Write("header_only.csv", kHeader);
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 1",
                   {"no data rows after the header (line 1)"});
}

TEST(NativeCsvBadInput, WrongColumnsAreNamed) {
  TempDir dir;
  const std::string path = dir.Write("wrong.csv", std::string("time,ax,ay,az\n") + "0,1,2,3\n");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 1",
                   {"expected a column named 'time_s'", "found columns: time, ax, ay, az"});
}

TEST(NativeCsvBadInput, IncompleteGyroscopeTriad) {
  TempDir dir;
  const std::string path =
      dir.Write("partial.csv", std::string("time_s,acc_x,acc_y,acc_z,gyr_x\n") + "0,1,2,3,4\n");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 1",
                   {"expected a column named 'gyr_y'"});
}

TEST(NativeCsvBadInput, NonNumericFieldNamesLineAndColumn) {
  TempDir dir;
  const std::string path = WithBadRow(dir, "0.02,0.1,abc,-9.8,0.01,0.02,0.03");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 4",
                   {"column 3 'acc_y'", "expected a number, found 'abc'"});
}

TEST(NativeCsvBadInput, EmptyFieldIsNotANumber) {
  TempDir dir;
  const std::string path = WithBadRow(dir, "0.02,0.1,0.2,,0.01,0.02,0.03");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 4", {"column 4 'acc_z'", "found ''"});
}

TEST(NativeCsvBadInput, NanIsRejectedWithItsLine) {
  TempDir dir;
  const std::string path = WithBadRow(dir, "0.02,0.1,0.2,-9.8,nan,0.02,0.03");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 4",
                   {"column 5 'gyr_x'", "NaN or infinite"});
}

TEST(NativeCsvBadInput, InfinityIsRejectedWithItsLine) {
  TempDir dir;
  const std::string path = WithBadRow(dir, "0.02,0.1,0.2,-inf,0.01,0.02,0.03");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 4",
                   {"column 4 'acc_z'", "NaN or infinite"});
}

TEST(NativeCsvBadInput, RepeatedTimeNamesBothLines) {
  TempDir dir;
  const std::string path = WithBadRow(dir, "0.01,0.1,0.2,-9.8,0.01,0.02,0.03");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 4",
                   {"time 0.01 s repeats the previous row's 0.01 s (line 3)"});
}

TEST(NativeCsvBadInput, TimeGoingBackwards) {
  TempDir dir;
  const std::string path = WithBadRow(dir, "0.005,0.1,0.2,-9.8,0.01,0.02,0.03");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 4",
                   {"time 0.005 s is before the previous row's 0.01 s (line 3)"});
}

TEST(NativeCsvBadInput, TooFewColumnsOnARow) {
  TempDir dir;
  const std::string path = WithBadRow(dir, "0.02,0.1,0.2,-9.8,0.01");
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "line 4",
                   {"expected at least 7 columns, found 5"});
}

TEST(NativeCsvBadInput, ReadingAFolderIsAnError) {
  TempDir dir;
  const std::string path = dir.path().string();
  ExpectInputError([&] { ReadNativeCsv(path); }, path, "", {"folder"});
}

}  // namespace
}  // namespace plumb::io

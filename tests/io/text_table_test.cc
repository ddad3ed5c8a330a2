#include "plumb/io/text/text_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "io_test_util.h"
#include "plumb/core/error.h"

namespace plumb::io {
namespace {

using testing::ExpectInputError;
using testing::TempDir;

// Options for `t ax ay az gx gy gz` tables by index.
TextTableOptions SevenColumns() {
  TextTableOptions o;
  o.time = 0;
  o.acc.axes = {1, 2, 3};
  o.gyr.axes = {4, 5, 6};
  return o;
}

TEST(TextTable, DetectsEachDelimiter) {
  const TextTableOptions o = SevenColumns();
  for (const char* row :
       {"1,2,3,4,5,6,7", "1;2;3;4;5;6;7", "1\t2\t3\t4\t5\t6\t7", "  1  2 3\t 4 5 6 7  "}) {
    const Session s = ParseTextTable(row, "mem", o);
    ASSERT_EQ(s.series.size(), 1u) << row;
    EXPECT_EQ(s.series.t_s[0], 1.0) << row;
    EXPECT_EQ(s.series.acc[0], Vec3f(2, 3, 4)) << row;
    EXPECT_EQ(s.series.gyr[0], Vec3f(5, 6, 7)) << row;
  }
}

TEST(TextTable, NamesFromTheCommentLineBeforeTheData) {
  TextTableOptions o;
  o.time = "time";
  o.acc.axes = {"tx", "ty", "tz"};
  o.gyr.axes = {"wx", "wy", "wz"};
  const Session s = ParseTextTable(
      "# recorded by someone\n# time tx ty tz wx wy wz mx\n"
      "10.5 1 2 3 4 5 6 7 \n10.6 1 2 3 4 5 6 7 \n",
      "mem", o);
  ASSERT_EQ(s.series.size(), 2u);
  EXPECT_EQ(s.series.t_s[1], 10.6);
  EXPECT_EQ(s.series.gyr[1], Vec3f(4, 5, 6));
}

TEST(TextTable, SkippedPreambleHeaderRowAndUnits) {
  TextTableOptions o;
  o.skip_lines = 2;
  o.header_row = true;
  o.time = "t_us";
  o.time_unit_s = 1e-6;
  o.acc.axes = {"ax", "ay", "az"};
  o.acc.SetOffset(32768);
  o.acc.SetScale(9.80665 / 16384);
  o.gyr.axes = {"gx", "gy", "gz"};
  o.gyr.SetScale(M_PI / 180.0);
  o.temp.column = "temp";
  o.temp.scale = 0.5;
  const Session s = ParseTextTable(
      "Fs,100\nnot,a,table,line\nt_us,gx,gy,gz,ax,ay,az,temp\n"
      "1500000,90,-180,0,49152,32768,16384,50\n",
      "mem", o);
  ASSERT_EQ(s.series.size(), 1u);
  EXPECT_DOUBLE_EQ(s.series.t_s[0], 1.5);
  EXPECT_FLOAT_EQ(s.series.acc[0].x(), 9.80665f);
  EXPECT_FLOAT_EQ(s.series.acc[0].y(), 0.0f);
  EXPECT_FLOAT_EQ(s.series.acc[0].z(), -9.80665f);
  EXPECT_FLOAT_EQ(s.series.gyr[0].x(), static_cast<float>(M_PI / 2));
  EXPECT_FLOAT_EQ(s.series.gyr[0].y(), static_cast<float>(-M_PI));
  EXPECT_FLOAT_EQ(s.series.temp_c[0], 25.0f);
}

TEST(TextTable, TimeFromTheSampleRate) {
  TextTableOptions o;
  o.acc.axes = {0, 1, 2};
  o.rate_hz = 200.0;
  o.allow_nan_rows = true;
  const Session s = ParseTextTable("1 2 3\n1 NaN 3\n1 2 3\n", "mem", o);
  ASSERT_EQ(s.series.size(), 2u);
  EXPECT_FALSE(s.series.has_gyro());
  EXPECT_DOUBLE_EQ(s.series.t_s[0], 0.0);
  EXPECT_DOUBLE_EQ(s.series.t_s[1], 0.01);  // the dropped row keeps its time slot
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].message.find("skipped 1 rows"), std::string::npos)
      << s.warnings[0].message;
  EXPECT_NE(s.warnings[0].message.find("line 2"), std::string::npos) << s.warnings[0].message;
  EXPECT_EQ(s.warnings[0].code, "nan_rows_skipped");
  EXPECT_TRUE(s.warnings[0].options.empty());
}

TEST(TextTable, AxisMapTurnsFluIntoFrd) {
  TextTableOptions o = SevenColumns();
  o.acc.axis_map = {1, -2, -3};
  o.gyr.axis_map = {2, 3, -1};
  const Session s = ParseTextTable("0,1,2,3,4,5,6", "mem", o);
  EXPECT_EQ(s.series.acc[0], Vec3f(1, -2, -3));
  EXPECT_EQ(s.series.gyr[0], Vec3f(5, 6, -4));
}

TEST(TextTable, ChunkBoundariesAndLongLinesDoNotChangeTheResult) {
  // More than one 1 MiB chunk of rows, and a comment line longer than a chunk.
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> value(-40000, 40000);
  std::string text = "#" + std::string(1500000, 'x') + "\n";
  const int rows = 60000;
  for (int i = 0; i < rows; ++i) {
    text += std::to_string(i);
    for (int k = 0; k < 6; ++k) text += " " + std::to_string(value(rng));
    text += "\n";
  }
  TempDir dir;
  const std::string path = dir.Write("big.txt", text);
  const TextTableOptions o = SevenColumns();
  const Session from_file = ReadTextTable(path, o);
  const Session from_text = ParseTextTable(text, path, o);
  ASSERT_EQ(from_file.series.size(), static_cast<std::size_t>(rows));
  EXPECT_EQ(from_file.series.t_s, from_text.series.t_s);
  EXPECT_EQ(from_file.series.acc, from_text.series.acc);
  EXPECT_EQ(from_file.series.gyr, from_text.series.gyr);
  EXPECT_EQ(from_file.series.t_s.back(), rows - 1.0);
}

TEST(TextTable, OptionMistakesArePlumbErrors) {
  TextTableOptions no_acc;
  no_acc.rate_hz = 100;
  EXPECT_THROW(ParseTextTable("1 2 3", "mem", no_acc), Error);
  TextTableOptions no_time;
  no_time.acc.axes = {0, 1, 2};
  EXPECT_THROW(ParseTextTable("1 2 3", "mem", no_time), Error);
  TextTableOptions twice = SevenColumns();
  twice.gyr.axes = {3, 4, 5};
  EXPECT_THROW(ParseTextTable("1 2 3 4 5 6 7", "mem", twice), Error);
  TextTableOptions bad_map = SevenColumns();
  bad_map.acc.axis_map = {1, 1, 3};
  EXPECT_THROW(ParseTextTable("1 2 3 4 5 6 7", "mem", bad_map), Error);
}

TEST(TextTableBadInput, NamedColumnWithoutHeader) {
  TextTableOptions o;
  o.rate_hz = 100;
  o.acc.axes = {"ax", "ay", "az"};
  ExpectInputError([&] { ParseTextTable("1 2 3\n", "mem.txt", o); }, "mem.txt", "",
                   {"'ax' is given by name", "no header row"});
}

TEST(TextTableBadInput, NonNumericFieldWithoutHeaderNamesTheQuantity) {
  const TextTableOptions o = SevenColumns();
  ExpectInputError([&] { ParseTextTable("0 1 2 3 4 5 6\n\n1 1 2 3 4 x5 6\n", "m.txt", o); },
                   "m.txt", "line 3", {"column 6 (gyr y)", "found 'x5'"});
}

TEST(TextTableBadInput, NanInTheTimeColumn) {
  const TextTableOptions o = SevenColumns();
  ExpectInputError([&] { ParseTextTable("0 1 2 3 4 5 6\nnan 1 2 3 4 5 6\n", "m.txt", o); }, "m.txt",
                   "line 2", {"column 1 (time)", "NaN or infinite"});
}

// imu_tk's two-file layout.
TextTableOptions SplitOptions() {
  TextTableOptions o;
  o.time = 0;
  o.acc.axes = {1, 2, 3};
  o.gyr.axes = {1, 2, 3};
  return o;
}

TEST(SplitTables, JoinsFilesWithSharedTimes) {
  TempDir dir;
  const std::string acc = dir.Write("acc.txt", "0.01 1 2 3\n0.02 4 5 6\n");
  const std::string gyr = dir.Write("gyr.txt", "0.01 7 8 9\n0.02 10 11 12\n");
  const Session s = ReadSplitTables(acc, gyr, SplitOptions());
  ASSERT_EQ(s.series.size(), 2u);
  EXPECT_EQ(s.series.acc[1], Vec3f(4, 5, 6));
  EXPECT_EQ(s.series.gyr[1], Vec3f(10, 11, 12));
  EXPECT_EQ(s.source, acc + " + " + gyr);
}

TEST(SplitTables, MismatchedTimeNamesTheLine) {
  TempDir dir;
  const std::string acc = dir.Write("acc.txt", "0.01 1 2 3\n0.02 4 5 6\n0.03 4 5 6\n");
  const std::string gyr = dir.Write("gyr.txt", "# gyro\n0.01 7 8 9\n0.025 1 1 1\n0.03 1 1 1\n");
  ExpectInputError([&] { ReadSplitTables(acc, gyr, SplitOptions()); }, gyr, "line 3",
                   {"sample 1: time 0.025 s differs from 0.02 s at " + acc + " line 2"});
}

TEST(SplitTables, ErrorsInTheGyroscopeFileNameTheGyroscopeAxis) {
  TempDir dir;
  const std::string acc = dir.Write("acc.txt", "0.01 1 2 3\n0.02 4 5 6\n");
  const std::string gyr = dir.Write("gyr.txt", "0.01 7 8 9\n0.02 10 1l 12\n");
  ExpectInputError([&] { ReadSplitTables(acc, gyr, SplitOptions()); }, gyr, "line 2",
                   {"column 3 (gyr y): expected a number, found '1l'"});
}

TEST(SplitTables, DifferentLengthsNameTheFirstExtraRow) {
  TempDir dir;
  const std::string acc = dir.Write("acc.txt", "0.01 1 2 3\n0.02 4 5 6\n0.03 4 5 6\n");
  const std::string gyr = dir.Write("gyr.txt", "0.01 7 8 9\n0.02 1 1 1\n");
  ExpectInputError([&] { ReadSplitTables(acc, gyr, SplitOptions()); }, acc, "line 3",
                   {"has 3 samples", "has 2"});
}

}  // namespace
}  // namespace plumb::io

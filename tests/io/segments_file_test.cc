#include "plumb/io/text/segments_file.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "io_test_util.h"
#include "plumb/core/error.h"

namespace plumb::io {
namespace {

using testing::ExpectInputError;
using testing::TempDir;

// `n` samples at 10 Hz starting at t = 100 s.
ImuSeries TenHertz(std::size_t n) {
  ImuSeries s;
  for (std::size_t i = 0; i < n; ++i) {
    s.t_s.push_back(100.0 + 0.1 * static_cast<double>(i));
    s.acc.emplace_back(0.0f, 0.0f, -9.8f);
  }
  return s;
}

TEST(SegmentsFile, CsvInSecondsWithLabels) {
  TempDir dir;
  const std::string path = dir.Write("seg.csv",
                                     "# stated by hand\nstart_s,end_s,label\n"
                                     "102.0,103.0,level\n100.0,101.05,upside_down\n"
                                     "104.0,105.0,x_rot\n");
  const GivenSections given = ReadGivenSections(path, TenHertz(100));
  ASSERT_EQ(given.still.size(), 2u);
  EXPECT_EQ(given.still[0].label, "upside_down");  // sorted by start
  EXPECT_EQ(given.still[0].begin, 0u);
  EXPECT_EQ(given.still[0].end, 11u);  // 100.0 .. 101.0 inclusive
  EXPECT_EQ(given.still[1].label, "level");
  EXPECT_EQ(given.still[1].begin, 20u);
  EXPECT_EQ(given.still[1].end, 31u);
  ASSERT_EQ(given.motion.size(), 1u);
  EXPECT_EQ(given.motion[0].label, "x_rot");
  EXPECT_EQ(given.motion[0].begin, 40u);
  EXPECT_EQ(ReadSegments(path, TenHertz(100)).size(), 2u);
}

TEST(SegmentsFile, CsvWithoutHeaderGetsDefaultLabels) {
  TempDir dir;
  const std::string path = dir.Write("seg.csv", "100.5,101.5\n103,104\n");
  const std::vector<StillSegment> still = ReadSegments(path, TenHertz(100));
  ASSERT_EQ(still.size(), 2u);
  EXPECT_EQ(still[0].label, "still #1");
  EXPECT_EQ(still[1].label, "still #2");
  EXPECT_EQ(still[1].begin, 30u);
  EXPECT_EQ(still[1].end, 41u);
}

TEST(SegmentsFile, CsvOfSampleIndicesAsImucalSavesIt) {
  TempDir dir;
  const std::string path = dir.Write("seg.csv", ",start,end\nx_p,5,20\nx_rot,30,40\n");
  const GivenSections given = ReadGivenSections(path, TenHertz(100));
  ASSERT_EQ(given.still.size(), 1u);
  EXPECT_EQ(given.still[0].label, "x_p");
  EXPECT_EQ(given.still[0].begin, 5u);
  EXPECT_EQ(given.still[0].end, 20u);
  ASSERT_EQ(given.motion.size(), 1u);
  EXPECT_EQ(given.motion[0].end, 40u);
}

TEST(SegmentsFile, JsonSectionList) {
  TempDir dir;
  const std::string path = dir.Write(
      "list.json", R"({"z_p": {"start": 50, "end": 60}, "a": {"start_s": 100.0, "end_s": 100.3},
                       "z_rot": {"start": 70, "end": 80}})");
  const GivenSections given = ReadGivenSections(path, TenHertz(100));
  ASSERT_EQ(given.still.size(), 2u);
  EXPECT_EQ(given.still[0].label, "a");
  EXPECT_EQ(given.still[0].end, 4u);
  EXPECT_EQ(given.still[1].label, "z_p");
  ASSERT_EQ(given.motion.size(), 1u);
  EXPECT_EQ(given.motion[0].label, "z_rot");
}

TEST(SegmentsFile, ImucalExampleSectionList) {
  const std::string path =
      std::string(PLUMB_SHARED_DATA_DIR) + "/ferraris/imucal/example_ferraris_session_list.json";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  const GivenSections given = ReadGivenSections(path, TenHertz(10376));
  ASSERT_EQ(given.still.size(), 6u);
  ASSERT_EQ(given.motion.size(), 3u);
  const char* still_labels[] = {"x_p", "x_a", "y_p", "y_a", "z_p", "z_a"};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(given.still[i].label, still_labels[i]);
  EXPECT_EQ(given.still[0].begin, 540u);
  EXPECT_EQ(given.still[0].end, 1271u);
  EXPECT_EQ(given.still[5].begin, 5376u);
  EXPECT_EQ(given.still[5].end, 5983u);
  EXPECT_EQ(given.motion[0].label, "x_rot");
  EXPECT_EQ(given.motion[2].label, "z_rot");
  EXPECT_EQ(given.motion[2].begin, 9205u);
  EXPECT_EQ(given.motion[2].end, 9512u);
}

TEST(SegmentsFileBadInput, OverlappingStillSegments) {
  TempDir dir;
  const std::string path = dir.Write("seg.csv", "start_s,end_s\n100,102\n101.5,103\n");
  ExpectInputError([&] { ReadSegments(path, TenHertz(100)); }, path, "line 3",
                   {"overlaps 'still #1' (line 2)"});
}

TEST(SegmentsFileBadInput, OutsideTheSession) {
  TempDir dir;
  const std::string path = dir.Write("seg.csv", "start_s,end_s\n100,102\n105,120\n");
  ExpectInputError([&] { ReadSegments(path, TenHertz(100)); }, path, "line 3",
                   {"outside the session's time range 100..109.9 s"});
  const std::string json = dir.Write("seg.json", R"({"x_p": {"start": 90, "end": 101}})");
  ExpectInputError([&] { ReadSegments(json, TenHertz(100)); }, json, "section 'x_p'",
                   {"0 <= start < end <= 100"});
}

TEST(SegmentsFileBadInput, MalformedJson) {
  TempDir dir;
  const std::string path = dir.Write("seg.json", R"({"x_p": {"start": 1,)");
  ExpectInputError([&] { ReadSegments(path, TenHertz(100)); }, path, "line 1, column 21",
                   {"not valid JSON: syntax error while parsing object key - unexpected end of input"});
  const std::string shape = dir.Write("shape.json", R"({"x_p": [1, 2]})");
  ExpectInputError([&] { ReadSegments(shape, TenHertz(100)); }, shape, "section 'x_p'",
                   {"expected {\"start\": index"});
}

TEST(SegmentsFileBadInput, CsvProblems) {
  TempDir dir;
  const std::string columns = dir.Write("c.csv", "from,to\n1,2\n");
  ExpectInputError([&] { ReadSegments(columns, TenHertz(100)); }, columns, "line 1",
                   {"expected columns start_s,end_s[,label]", "found from,to"});
  const std::string text = dir.Write("t.csv", "start_s,end_s\n100,abc\n");
  ExpectInputError([&] { ReadSegments(text, TenHertz(100)); }, text, "line 2",
                   {"column 2: expected a number, found 'abc'"});
  const std::string empty = dir.Write("e.csv", "\n");
  ExpectInputError([&] { ReadSegments(empty, TenHertz(100)); }, empty, "", {"empty file"});
  const std::string missing = dir.File("absent.csv");
  ExpectInputError([&] { ReadSegments(missing, TenHertz(100)); }, missing, "", {"cannot open"});
}

}  // namespace
}  // namespace plumb::io

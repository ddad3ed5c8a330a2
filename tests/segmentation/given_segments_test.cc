#include "plumb/segmentation/given_segments.h"

#include <string>

#include <gtest/gtest.h>

#include "plumb/core/error.h"

namespace plumb::segmentation {
namespace {

ImuSeries HundredSamples() {
  ImuSeries s;
  for (int i = 0; i < 100; ++i) {
    s.t_s.push_back(0.01 * i);
    s.acc.emplace_back(0.0F, 0.0F, -9.8F);
  }
  return s;
}

StillSegment Segment(std::size_t begin, std::size_t end, const std::string& label = "") {
  StillSegment s;
  s.begin = begin;
  s.end = end;
  s.label = label;
  return s;
}

/// The message of the plumb::Error thrown by ValidateSegments, or "" when none is thrown.
std::string ValidationError(const std::vector<StillSegment>& segments,
                            std::size_t min_samples = 2) {
  try {
    ValidateSegments(HundredSamples(), segments, min_samples);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(GivenSegments, AcceptsOrderedSegmentsAndLabelsThem) {
  const SegmentationResult r =
      UseGivenSegments(HundredSamples(), {Segment(0, 40, "level"), Segment(40, 100)});
  ASSERT_EQ(r.segments.size(), 2U);
  EXPECT_EQ(r.segments[0].label, "level");
  EXPECT_EQ(r.segments[1].label, "still #2");
  EXPECT_EQ(r.report.method, "given");
  EXPECT_EQ(ValidationError({}), "");
}

TEST(GivenSegments, NamesTheBrokenRule) {
  EXPECT_NE(ValidationError({Segment(10, 10, "x+")}).find(
                "given still segment 1 (\"x+\") [10, 10): begin must be below end"),
            std::string::npos);
  EXPECT_NE(ValidationError({Segment(0, 20), Segment(90, 101)}).find(
                "given still segment 2 [90, 101): ends past the series, which has 100 samples"),
            std::string::npos);
  EXPECT_NE(ValidationError({Segment(0, 30), Segment(20, 50)}).find(
                "given still segment 2 [20, 50): overlaps given still segment 1 [0, 30)"),
            std::string::npos);
  EXPECT_NE(ValidationError({Segment(50, 60), Segment(0, 30)}).find(
                "starts before given still segment 1 [50, 60)"),
            std::string::npos);
  EXPECT_NE(ValidationError({Segment(0, 5)}, 10).find("has 5 samples, at least 10 needed"),
            std::string::npos);
}

}  // namespace
}  // namespace plumb::segmentation

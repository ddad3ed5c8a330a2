#include "plumb/segmentation/given_segments.h"

#include <string>
#include <utility>

#include "plumb/core/error.h"

namespace plumb::segmentation {
namespace {

std::string Describe(const std::vector<StillSegment>& segments, std::size_t k) {
  const StillSegment& s = segments[k];
  std::string text = "given still segment " + std::to_string(k + 1);
  if (!s.label.empty()) text += " (\"" + s.label + "\")";
  return text + " [" + std::to_string(s.begin) + ", " + std::to_string(s.end) + ")";
}

}  // namespace

void ValidateSegments(const ImuSeries& series, const std::vector<StillSegment>& segments,
                      std::size_t min_samples) {
  if (min_samples < 1) throw Error("given segments: min_samples must be at least 1");
  const std::size_t n = series.size();
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const StillSegment& s = segments[k];
    if (s.begin >= s.end) {
      throw Error(Describe(segments, k) + ": begin must be below end (half-open sample range)");
    }
    if (s.end > n) {
      throw Error(Describe(segments, k) + ": ends past the series, which has " +
                  std::to_string(n) + " samples (indices 0.." +
                  (n == 0 ? std::string("none") : std::to_string(n - 1)) + ")");
    }
    if (s.count() < min_samples) {
      throw Error(Describe(segments, k) + ": has " + std::to_string(s.count()) +
                  " samples, at least " + std::to_string(min_samples) + " needed");
    }
    if (k > 0 && s.begin < segments[k - 1].end) {
      const bool before = s.begin < segments[k - 1].begin;
      throw Error(Describe(segments, k) + (before ? ": starts before " : ": overlaps ") +
                  Describe(segments, k - 1) +
                  "; segments must be in increasing order and must not overlap");
    }
  }
}

SegmentationResult UseGivenSegments(const ImuSeries& series, std::vector<StillSegment> segments,
                                    std::size_t min_samples) {
  ValidateSegments(series, segments, min_samples);
  SegmentationResult result;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    if (segments[k].label.empty()) segments[k].label = "still #" + std::to_string(k + 1);
  }
  result.segments = std::move(segments);
  result.report.method = "given";
  result.report.notes.push_back(std::to_string(result.segments.size()) +
                                " still segments given by the user, checked against the " +
                                std::to_string(series.size()) + " samples of the series");
  return result;
}

}  // namespace plumb::segmentation

// plumb/io/text/segments_file.h — still segments (and motion sections) stated by the user.
//
// Two formats, told apart by the first non-blank character ('{' = JSON):
//
// (a) CSV, one section per line, '#' comments and blank lines ignored. With a header row the
//     columns are found by name:
//       start_s,end_s[,label]   times in the session's clock, s; the section holds the samples
//                               with start_s <= t_s <= end_s
//       start,end[,label]       sample indices, half-open [start, end) (pandas iloc, as imucal
//                               saves its section list); an unnamed first column is the label
//     Without a header row the columns are start_s,end_s[,label].
// (b) JSON, imucal's section list: an object of sections keyed by label, each
//       {"start": i, "end": j}      sample indices, half-open [i, j)
//     or {"start_s": a, "end_s": b} session times, s, as in (a); e.g.
//       {"x_p": {"start": 540, "end": 1271}, ..., "x_rot": {"start": 6770, "end": 7093}}
//
// A label ending in "_rot" (imucal's x_rot, y_rot, z_rot) marks a rotation, i.e. a motion
// section, not a still segment. Unlabelled CSV rows get "still #k" (k from 1). Still segments
// are returned sorted by start and must not overlap; every section must hold at least one
// sample of the series. Errors are plumb::InputError naming the file, the line (CSV) or the
// section (JSON) and what was expected.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"

namespace plumb::io {

/// A section during which the IMU moves (e.g. a 360 deg turn about one axis).
struct MotionSection {
  std::size_t begin = 0;  ///< first sample index
  std::size_t end = 0;    ///< one past the last sample index
  std::string label;      ///< label from the file, e.g. "x_rot"
};

/// Everything a section file states, split into still segments and motion sections.
struct GivenSections {
  std::vector<StillSegment> still;    ///< sorted by begin, not overlapping
  std::vector<MotionSection> motion;  ///< sorted by begin
};

/// Reads a section file (either format) against the samples it refers to.
GivenSections ReadGivenSections(const std::string& path, const ImuSeries& series);

/// The still segments of a section file (motion sections dropped).
std::vector<StillSegment> ReadSegments(const std::string& path, const ImuSeries& series);

}  // namespace plumb::io

// plumb/segmentation/given_segments.h — still segments stated by the user.
#pragma once

#include <cstddef>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb::segmentation {

/// Checks user-given segments against the series: each inside [0, series.size()), with
/// begin < end and at least `min_samples` (>= 1) samples, in increasing order and not
/// overlapping. Throws plumb::Error naming the segment (index and label), its range and the
/// rule it breaks.
void ValidateSegments(const ImuSeries& series, const std::vector<StillSegment>& segments,
                      std::size_t min_samples = 2);

/// Validates the given segments and wraps them as a result (method "given"); segments without
/// a label are labelled "still #k" (k from 1).
SegmentationResult UseGivenSegments(const ImuSeries& series, std::vector<StillSegment> segments,
                                    std::size_t min_samples = 2);

}  // namespace plumb::segmentation

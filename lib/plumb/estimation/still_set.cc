#include "plumb/estimation/still_set.h"

#include <algorithm>
#include <string>

#include "plumb/core/error.h"

namespace plumb::estimation {
namespace {

/// The longest stretch without a sample in samples [first, last] of `series`.
SampleGap LongestGap(const ImuSeries& series, std::size_t first, std::size_t last) {
  SampleGap out;
  for (std::size_t i = first; i < last; ++i) {
    const double length = series.t_s[i + 1] - series.t_s[i];
    if (length > out.length_s) out = {series.t_s[i], length};
  }
  return out;
}

}  // namespace

std::vector<Vec3> StillSet::AtRestMeans(bool gyro) const {
  std::vector<Vec3> out;
  for (const auto& s : poses) {
    if (!s.spinning) out.push_back(gyro ? s.stats.gyr_mean : s.stats.acc_mean);
  }
  return out;
}

std::vector<StillSegment> StillSet::AtRestSegments() const {
  std::vector<StillSegment> out;
  for (const auto& s : poses) {
    if (!s.spinning) out.push_back(s.segment);
  }
  return out;
}

const MotionInterval& StillSet::MotionInto(std::size_t k) const {
  return *std::find_if(motions.begin(), motions.end(),
                       [&](const MotionInterval& m) { return m.from + 1 == k; });
}

bool StillSet::AnyAttitudeKnown() const {
  return std::any_of(poses.begin(), poses.end(),
                     [](const StillPose& s) { return s.known || s.heading_only; });
}

StillSet MakeStillSet(const ImuSeries& series, const std::vector<StillSegment>& segments,
                      bool earth_rate_seen, bool motion_on, const CalibrationOptions& options) {
  StillSet set;
  for (const auto& seg : segments) {
    if (seg.end > series.size() || seg.begin >= seg.end) {
      throw Error("still segment '" + seg.label + "' [" + std::to_string(seg.begin) + ", " +
                  std::to_string(seg.end) + ") is outside the " + std::to_string(series.size()) +
                  " samples");
    }
    if (static_cast<int>(seg.count()) < options.min_segment_samples) continue;
    StillPose s;
    s.segment = seg;
    s.stats = signal::ComputeSegmentStats(series, seg);
    s.known = seg.known_R_n_b.has_value();
    s.spinning = seg.spinning();
    set.poses.push_back(std::move(s));
  }
  if (set.poses.empty()) {
    throw InsufficientDataError(
        "no still segment of at least " + std::to_string(options.min_segment_samples) +
        " samples: record the IMU still (a minute level, or many still poses joined by turns)");
  }
  // A known tilt with a free heading: the heading is seen only through Earth rate, so it is
  // estimated when the still gyroscope residuals with a site are in the fit, else held.
  for (auto& s : set.poses) {
    if (s.known && s.segment.heading_free && earth_rate_seen) {
      s.known = false;
      s.heading_only = true;
    }
  }
  if (std::all_of(set.poses.begin(), set.poses.end(),
                  [](const StillPose& s) { return s.spinning; })) {
    throw InsufficientDataError("every segment turns at a stated rate: record still poses too");
  }
  // Motion intervals: from the last sample of a segment to the first of the next.
  for (std::size_t k = 0; k + 1 < set.poses.size(); ++k) {
    const std::size_t first = set.poses[k].segment.end - 1;
    const std::size_t last = set.poses[k + 1].segment.begin;
    const double gap = series.t_s[last] - series.t_s[first];
    if (!motion_on || last <= first) continue;
    const auto flown = std::find_if(
        options.log_motion.begin(), options.log_motion.end(), [&](const LogMotion& m) {
          return m.Covers(series.t_s[first], series.t_s[last]);
        });
    if (flown != options.log_motion.end()) {
      set.not_turns.push_back({k, first, last, *flown, std::nullopt});
      continue;
    }
    if (gap > options.max_motion_s) {
      set.not_turns.push_back({k, first, last, std::nullopt, std::nullopt});
      continue;
    }
    if (const SampleGap dropout = LongestGap(series, first, last);
        dropout.length_s > options.max_turn_gap_s) {
      set.not_turns.push_back({k, first, last, std::nullopt, dropout});
      continue;
    }
    set.motions.push_back({k, first, last, std::nullopt, std::nullopt});
  }
  set.joined_to_previous.assign(set.poses.size(), false);
  for (const auto& m : set.motions) set.joined_to_previous[m.from + 1] = true;
  return set;
}

void AssignHeadingGauge(StillSet& set, bool has_gyro) {
  auto& poses = set.poses;
  std::size_t k = 0;
  while (k < poses.size()) {
    std::size_t end = k + 1;
    while (end < poses.size() && set.joined_to_previous[end]) ++end;
    bool any_known = false;
    for (std::size_t j = k; j < end; ++j) {
      any_known = any_known || poses[j].known || poses[j].heading_only;
    }
    if (!any_known) poses[k].chain_head = true;
    k = end;
  }
  if (!has_gyro) {
    for (auto& s : poses) s.chain_head = !s.known && !s.heading_only;
  }
}

StillSegment SegmentOnBoardImu(const StillSegment& segment, const ImuSeries& series0,
                               const ImuSeries& series) {
  const double t_begin = series0.t_s[segment.begin];
  const double t_end = series0.t_s[segment.end - 1];
  const auto begin = std::lower_bound(series.t_s.begin(), series.t_s.end(), t_begin);
  const auto end = std::upper_bound(begin, series.t_s.end(), t_end);
  StillSegment own = segment;
  own.begin = static_cast<std::size_t>(begin - series.t_s.begin());
  own.end = static_cast<std::size_t>(end - series.t_s.begin());
  return own;
}

StillSet StillSetOnBoardImu(const StillSet& imu0, const ImuSeries& series0,
                            const ImuSeries& series, const std::string& name) {
  StillSet set;
  set.joined_to_previous = imu0.joined_to_previous;
  for (const StillPose& pose : imu0.poses) {
    StillPose own = pose;
    own.segment = SegmentOnBoardImu(pose.segment, series0, series);
    if (own.segment.count() < 2) {
      throw InsufficientDataError(name + " has " + std::to_string(own.segment.count()) +
                                  " samples in the still pose " + pose.segment.label + " (" +
                                  std::to_string(series0.t_s[pose.segment.begin]) + " .. " +
                                  std::to_string(series0.t_s[pose.segment.end - 1]) +
                                  " s): each IMU of the board needs at least 2 in every pose");
    }
    own.stats = signal::ComputeSegmentStats(series, own.segment);
    set.poses.push_back(std::move(own));
  }
  for (const MotionInterval& m : imu0.motions) {
    MotionInterval own = m;
    own.first = set.poses[m.from].segment.end - 1;
    own.last = set.poses[m.from + 1].segment.begin;
    set.motions.push_back(own);
  }
  return set;
}

}  // namespace plumb::estimation

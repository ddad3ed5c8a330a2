// plumb/estimation/still_set.h — stage 1 of the backend (docs/reference/model.md, "The
// method"): the still set.
//
// The still segments long enough to use, each with its statistics and its attitude unknown
// R_n_b; which attitudes are known (held), known but for the heading (estimated through Earth
// rate), or the heading gauge of their chain; and the motion intervals that join consecutive
// segments, integrated by the motion residual.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/core/types.h"
#include "plumb/estimation/fit_report.h"
#include "plumb/estimation/options.h"
#include "plumb/residuals/measurements.h"
#include "plumb/signal/segment_stats.h"

namespace plumb::estimation {

/// One still segment as the solver sees it.
struct StillPose {
  StillSegment segment;
  signal::SegmentStats stats;
  /// The starting attitude R_n_b (Initialize), stored as Ceres and Eigen's coefficients() do:
  /// x, y, z, w. CalibrationProblem keeps the current value (CalibrationProblem::R_n_b).
  std::array<double, 4> q{0, 0, 0, 1};
  bool known = false;         ///< attitude held constant
  bool heading_only = false;  ///< tilt known, heading estimated (residuals::HeadingManifold)
  bool chain_head = false;    ///< heading held as the gauge (residuals::TiltManifold)
  bool spinning = false;      ///< turning at a stated rate: gyroscope residual only
  /// The segment means and their whitening (set by CalibrationProblem from the noise model).
  residuals::StillMeasurement acc_measurement, gyr_measurement;

  Quat R_n_b() const { return Quat(q[3], q[0], q[1], q[2]); }
  void set_R_n_b(const Quat& R_n_b) { q = {R_n_b.x(), R_n_b.y(), R_n_b.z(), R_n_b.w()}; }
};

/// The samples [first, last] of the series between pose `from` and pose `from + 1`.
struct MotionInterval {
  std::size_t from = 0;
  std::size_t first = 0, last = 0;
  /// For a motion left out (StillSet::not_turns): what the log says the vehicle did in it, when
  /// that is the reason; empty when the motion is left out for its length or a gap.
  std::optional<LogMotion> flown;
  /// For a motion left out for a gap in its samples: the longest one.
  std::optional<SampleGap> gap;
};

struct StillSet {
  std::vector<StillPose> poses;          ///< in time order
  std::vector<MotionInterval> motions;   ///< in time order
  /// Motion between consecutive poses longer than CalibrationOptions::max_motion_s (no MEMS
  /// gyroscope integrates to its noise that long; a flight, a vehicle carried), or during
  /// which the log says the vehicle flew or moved (CalibrationOptions::log_motion: a flight's
  /// vibration and translation, which samples logged at tens of hertz do not resolve): not a
  /// turn, left out of the fit (the poses after it start a chain of their own).
  std::vector<MotionInterval> not_turns;
  std::vector<bool> joined_to_previous;  ///< per pose: a motion interval leads into it

  /// Mean accelerometer (or gyroscope) output of every pose at rest (not turning at a stated
  /// rate), in pose order, sensor units.
  std::vector<Vec3> AtRestMeans(bool gyro) const;
  /// The segments of the poses at rest.
  std::vector<StillSegment> AtRestSegments() const;
  /// The motion interval that ends at pose k (requires joined_to_previous[k]).
  const MotionInterval& MotionInto(std::size_t k) const;
  /// Some pose's attitude is known, at least its tilt.
  bool AnyAttitudeKnown() const;
};

/// Stage 1. The segments of at least options.min_segment_samples samples with their
/// statistics; a known tilt with a free heading is estimated when `earth_rate_seen` (the still
/// gyroscope residuals with a site), else held; with `motion_on`, consecutive segments closer
/// than options.max_motion_s are joined by a motion interval. Throws plumb::Error for a
/// segment outside the series, plumb::InsufficientDataError when no segment is usable or
/// every one turns at a stated rate.
StillSet MakeStillSet(const ImuSeries& series, const std::vector<StillSegment>& segments,
                      bool earth_rate_seen, bool motion_on, const CalibrationOptions& options);

/// IMU 0's still segment `segment` (of `series0`) as another IMU of the board samples it: its
/// samples in `series` stamped within the segment's first and last sample times (possibly
/// none).
StillSegment SegmentOnBoardImu(const StillSegment& segment, const ImuSeries& series0,
                               const ImuSeries& series);

/// IMU 0's poses and motion intervals as another IMU of the board samples them (SPEC 6): each
/// pose its samples stamped within the pose's first and last sample times, with their
/// statistics, each interval from the last sample of one pose to the first of the next; the
/// attitudes and their flags as IMU 0's (the problem's own). Throws
/// plumb::InsufficientDataError naming `name` when a pose holds fewer than 2 of its samples.
StillSet StillSetOnBoardImu(const StillSet& imu0, const ImuSeries& series0,
                            const ImuSeries& series, const std::string& name);

/// The gauge: the first pose of each motion-joined chain holds its heading unless a known
/// attitude in the chain fixes it; without a gyroscope every pose's heading is held.
void AssignHeadingGauge(StillSet& set, bool has_gyro);

}  // namespace plumb::estimation

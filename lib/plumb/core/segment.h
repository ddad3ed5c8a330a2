// plumb/core/segment.h — a still segment of a session, detected or given.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/types.h"

namespace plumb {

/// A half-open sample range [begin, end) during which the IMU is still, or turning at a known
/// rate. Attitude and rate are optional knowledge the user states (the paper's level, x-north
/// pose; a turntable rate); without them the backend estimates one attitude per segment.
struct StillSegment {
  std::size_t begin = 0;  ///< first sample index
  std::size_t end = 0;    ///< one past the last sample index
  std::string label;      ///< user label or "still #k"
  /// Known attitude R_n_b (body to NED) held constant in the fit, if stated.
  std::optional<Quat> known_R_n_b;
  /// With known_R_n_b: only its tilt (the direction of gravity in body axes) is known, e.g. a
  /// face of the paper's benchmark platform; the heading about the vertical is estimated
  /// (through Earth rate; held when Earth rate is not used). Also for a turning segment: the
  /// heading of its Earth-rate term.
  bool heading_free = false;
  /// Known mean angular rate relative to the Earth in body frame, rad/s: a turntable, or a
  /// turn of known angle about a known axis (angle / duration). A segment with a nonzero known
  /// rate is used for the gyroscope only (its specific force changes as it turns) and not for
  /// the noise estimate.
  std::optional<Vec3> known_omega_eb_b;

  /// True when the segment turns at a stated nonzero rate.
  bool spinning() const { return known_omega_eb_b && known_omega_eb_b->squaredNorm() > 0.0; }

  std::size_t count() const { return end - begin; }
};

/// Why the detector decided what it did, for the report.
struct SegmentationReport {
  std::string method;              ///< "detected" or "given"
  double init_still_s = 0.0;       ///< length of the initial still period used for the noise
  double threshold = 0.0;          ///< threshold on the normalised cost
  double window_s = 0.0;           ///< length of the moving window
  double min_still_s = 0.0;        ///< shortest still segment kept
  std::size_t rejected_short = 0;  ///< still runs dropped for being shorter than min_still_s
  std::vector<std::string> notes;  ///< human-readable remarks
};

}  // namespace plumb

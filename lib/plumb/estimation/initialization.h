// plumb/estimation/initialization.h — starting values for the backend.
//
// The fit is nonlinear in the attitudes and, for raw-count data, starts far from identity, so
// it is started from closed forms:
//  - accelerometer: a sphere fit |y - c| = r of the still means (four or more orientations
//    spread in 3-D) gives b_a = c and F = (r / g) I; otherwise F = (|y| / g) I, b_a = 0.
//  - attitudes: the gravity direction of each segment through that F and b_a gives the tilt;
//    along a chain joined by motion the heading is carried by the integrated gyroscope.
//  - gyroscope: b_g from the still means; a scalar scale s (E = s I) by a one-dimensional search
//    that best carries each segment's gravity direction to the next through the integrated
//    rate (so raw counts need no unit option).
#pragma once

#include <optional>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/jobs.h"
#include "plumb/core/types.h"
#include "plumb/estimation/still_set.h"
#include "plumb/model/model.h"

namespace plumb::estimation {

struct AccelGuess {
  double scale = 1.0;        ///< F = scale I
  Vec3 bias = Vec3::Zero();  ///< sensor units
  bool sphere_fit = false;   ///< whether the sphere fit was used
};

/// `means`: still accelerometer means, sensor units; `g`: gravity, m/s^2.
AccelGuess GuessAccel(const std::vector<Vec3>& means, double g);

/// R_n_b whose body-frame "down" is `down_b` (need not be unit) and whose x axis has
/// heading `heading_rad` from north (measured about NED down).
Quat AttitudeFromDown(const Vec3& down_b, double heading_rad);

/// Heading of the body x axis of R_n_b, rad.
double Heading(const Quat& R_n_b);

/// Rotates R_n_b about a horizontal axis so that its body "down" becomes `down_b`.
Quat CorrectTilt(const Quat& R_n_b, const Vec3& down_b);

/// Body-frame rotation dR = R_a^T R_b from integrating rates (y - bias) * scale over samples
/// [first, last] of `series` (trapezoidal increments, Earth rate ignored).
Quat IntegrateRaw(const ImuSeries& series, std::size_t first, std::size_t last,
                  const Vec3& bias, double scale);

/// The gyroscope scale s (rad/s per sensor unit) that best carries the down direction of
/// each still segment to the next through the motion between them.
/// `intervals`: (last sample of segment k, first sample of segment k+1);
/// `down_before`, `down_after`: unit down directions in the body frame at both ends.
/// Each value of the search integrates the intervals as jobs through `run_jobs` (the same
/// result without it).
double GuessGyroScale(const ImuSeries& series,
                      const std::vector<std::pair<std::size_t, std::size_t>>& intervals,
                      const std::vector<Vec3>& down_before, const std::vector<Vec3>& down_after,
                      const Vec3& bias, const JobRunner& run_jobs = {});

/// The starting values of stage 3 (file comment).
struct StartingValues {
  AccelGuess accel;
  double gyro_rad_per_unit = 1.0;  ///< scalar gyroscope scale s, rad/s per sensor unit
  Vec3 gyro_bias = Vec3::Zero();   ///< mean still gyroscope output, sensor units

  /// Unit "down" in the body frame of a pose, from its accelerometer mean through `accel`.
  Vec3 Down(const StillPose& pose) const;
};

/// Stage 3: starting values. Sets the base effects' blocks of `theta` (model.ZeroParameters()
/// on entry) from the closed forms, holds every fixed parameter at its nominal value, and sets
/// each pose's attitude: known ones as given, the others tilted from gravity with the heading
/// carried along each motion-joined chain by the integrated gyroscope (a chain's first pose:
/// `first_heading_deg` for the first pose when stated, else 0). The gyroscope scale's search
/// runs its jobs through `run_jobs`.
StartingValues Initialize(const ImuSeries& series, const model::Model& model, double g,
                          bool has_gyro, std::optional<double> first_heading_deg, StillSet& set,
                          model::ParameterBlocks& theta, const JobRunner& run_jobs = {});

}  // namespace plumb::estimation

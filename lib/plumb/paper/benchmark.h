// plumb/paper/benchmark.h — the seed paper's benchmark calibration (its section 4, after
// Ferraris et al.), as printed, on a session of still poses and turns.
//
// Conventions. The paper writes a_s = F a_p + b with a_p the gravity VECTOR in body axes, so an
// axis "parallel to gravity" points down and a specific-force accelerometer reads -g on it: the
// paper's coupling matrix is close to -I. plumb's forward model (SPEC section 1) is
// y_a = F f_b + b_a with f_b the specific force (= -a_p when still); so F = -F_paper up to the
// paper's normalisation by Q (below), and b_a = b. The gyroscope's rate is the same in both, so
// E = E_paper. Both are in the frame the poses define (the platform's faces): full 3x3.
//
// Accelerometer (section 4.1, 4.2):
//   b_i = (a_{i,p_i} + a_{i,ap_i}) / 2                                    Eq. (3)
//   U+ = [mean output in pose "x parallel", "y parallel", "z parallel"] (columns), U- the same
//   for the antiparallel poses; Q = mean of the column norms of U+      Eq. (4)
//   coupling (paper) = (U+ - U-) / (2 Q).
//   Forward: F = -(U+ - U-) / (2 g), g the local gravity (options.gravity_m_s2): the column
//   norms of U+ contain the bias and the scale errors, so Q is not g; Eq. (4) gives a matrix
//   whose column norms are near 1 whatever the sensor's true scale.
// Gyroscope (section 4.3, 4.4):
//   b(t) = b0 + b1 (t - t0_s), t0_s the first sample's time; x and y from the still periods with
//   z parallel to gravity (z down), z from those with z perpendicular to it; b1 from the first
//   and the last such periods (the paper's "at the start and the end"), 0 when there is one.
//   Without any z-down period (imucal's session has z up and z down once each, so it has one)
//   the z-up periods serve for x and y, with a note.
//   coupling (paper) column j = (integral of (output - b(t)) dt over every turn about axis j) /
//   (total angle about axis j). The paper divides "the result of integrating the gyroscope
//   output"; its reference (Ferraris) removes the bias first, which we do: otherwise the answer
//   would grow with the duration of the turns. Angles: the nominal angle of each turn is its
//   integrated angle rounded to a multiple of 90 deg (four 90 deg turns in the paper, one
//   360 deg turn per axis in imucal's sessions; both work).
// The paper ignores Earth rate, and so does this procedure (it appears in the gyroscope bias).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/core/segment.h"
#include "plumb/core/types.h"
#include "plumb/core/units.h"
#include "plumb/signal/segment_stats.h"

namespace plumb::paper {

/// Which body axis is along gravity in a still pose, found from the mean accelerometer output.
struct PoseClass {
  int axis = -1;          ///< 0 = x, 1 = y, 2 = z: the axis with the largest |mean|; -1 = none
  bool parallel = false;  ///< true: the axis points down (along gravity; it reads about -g)
  double tilt_rad = 0.0;  ///< angle between the mean output and that axis, rad, [0, pi/2]
  /// Angle of the z axis from the horizontal plane, rad, [0, pi/2] (0: z perpendicular).
  double z_elevation_rad = 0.0;
};

/// Classifies a mean accelerometer output (any units, specific-force convention: an axis
/// pointing down reads negative). Returns axis -1 for a zero or non-finite mean.
PoseClass ClassifyPose(const Vec3& acc_mean);

/// A still period with its statistics and pose.
struct StillPeriod {
  StillSegment segment;       ///< the samples [begin, end) and the label
  signal::SegmentStats stats;  ///< mean output, mean time
  PoseClass pose;              ///< which axis is along gravity
};

/// A stretch of samples during which the IMU turns (given, e.g. imucal's "x_rot", or the gap
/// between two still periods).
struct MotionRange {
  std::size_t begin = 0;  ///< first sample index
  std::size_t end = 0;    ///< one past the last sample index
  std::string label;      ///< e.g. "x_rot" or "turn after 'x up 90 deg'"
  /// The body axis turned about (0, 1, 2) when known: from the still pose around the turn
  /// (the axis along gravity), or from a label "x_rot", "y_rot", "z_rot"; -1: the axis with the
  /// largest integrated output.
  int axis = -1;
};

/// A turn used for the gyroscope coupling matrix.
struct TurnPeriod {
  MotionRange range;                  ///< samples integrated (trapezoid rule)
  int axis = -1;                      ///< 0, 1, 2: MotionRange::axis, else the largest integral
  Vec3 integral = Vec3::Zero();       ///< integral of (output - b(t)), gyro units times s
  double nominal_angle_rad = 0.0;     ///< integral along `axis` rounded to a multiple of pi/2
};

/// Options of the benchmark procedure.
struct PaperBenchmarkOptions {
  /// Local gravity, m/s^2, > 0: used only for the forward matrix F = -(U+ - U-) / (2 g).
  double gravity_m_s2 = units::kStandardGravity;
  /// Largest angle between a still pose's mean output and its nearest axis for the pose to
  /// count as "axis parallel / antiparallel to gravity"; also the largest elevation of z for
  /// "z perpendicular". rad, in (0, pi/4].
  double max_tilt_rad = 20.0 * units::kRadPerDeg;
};

/// What the benchmark procedure found, in the paper's convention and in plumb's forward one.
struct PaperBenchmarkResult {
  // --- the paper's convention (a_s = F a_p + b, a_p the gravity vector) ---
  Mat3 U_plus = Mat3::Zero();   ///< column j: mean output with axis j parallel to gravity
  Mat3 U_minus = Mat3::Zero();  ///< column j: mean output with axis j antiparallel
  double Q = 0.0;               ///< Eq. (4): mean column norm of U+, accelerometer units
  Vec3 accel_bias = Vec3::Zero();             ///< Eq. (3), accelerometer units
  Mat3 accel_coupling_paper = Mat3::Zero();   ///< (U+ - U-) / (2 Q), dimensionless, ~ -I
  Vec3 gyro_bias_b0 = Vec3::Zero();  ///< Eq. (5) b0: bias at t0_s, gyroscope units
  Vec3 gyro_bias_b1 = Vec3::Zero();  ///< Eq. (5) b1: bias drift, gyroscope units per s
  double t0_s = 0.0;                 ///< time origin of Eq. (5): the first sample's time, s
  Mat3 gyro_coupling_paper = Mat3::Zero();  ///< section 4.4, dimensionless (units/(rad/s))
  Vec3 total_angle_rad = Vec3::Zero();      ///< total nominal angle about each axis, rad
  // --- plumb's forward convention (y_a = F f_b + b_a, y_g = E omega_b + b_g + d_g (t - t0)) ---
  Mat3 F = Mat3::Identity();  ///< -(U+ - U-) / (2 g): accelerometer units per m/s^2
  Vec3 b_a = Vec3::Zero();    ///< = accel_bias
  Mat3 E = Mat3::Identity();  ///< = gyro_coupling_paper
  Vec3 b_g = Vec3::Zero();    ///< = gyro_bias_b0 (at t0_s)
  Vec3 gyro_bias_drift = Vec3::Zero();  ///< = gyro_bias_b1 (effect gyro_bias_drift, t_ref t0_s)
  double gravity_m_s2 = 0.0;  ///< g used for F
  // --- how the data was read ---
  std::vector<StillPeriod> still;           ///< every still period given, classified
  std::array<int, 3> parallel_index{{-1, -1, -1}};      ///< still[] used for U+ columns
  std::array<int, 3> antiparallel_index{{-1, -1, -1}};  ///< still[] used for U- columns
  std::vector<int> z_parallel_index;       ///< still[] used for the x and y gyroscope bias
  std::vector<int> z_perpendicular_index;  ///< still[] used for the z gyroscope bias
  std::vector<TurnPeriod> turns;           ///< turns used for the gyroscope coupling
  /// Choices made, for the report (codes: gyro_bias_from_up, the x and y gyroscope bias from
  /// z up; gyro_bias_drift_zero, b1 = 0 for want of a second period; turn_too_small).
  std::vector<Notice> notes;
};

/// Runs the benchmark procedure. `still` are the still periods (detected or given, labels kept);
/// `motion` the turn sections when given (e.g. imucal's x_rot, y_rot, z_rot); when empty, the
/// gaps between consecutive still periods whose poses agree (a turn about the vertical axis)
/// are the turns. Uses the first still period of each of the six accelerometer poses. Throws
/// plumb::InsufficientDataError naming the missing poses or turn axes, and plumb::Error when
/// the series has no gyroscope or its gyroscope is not in rad/s.
PaperBenchmarkResult CalibratePaperBenchmark(const ImuSeries& series,
                                             const std::vector<StillSegment>& still,
                                             const std::vector<MotionRange>& motion,
                                             const PaperBenchmarkOptions& options);

}  // namespace plumb::paper

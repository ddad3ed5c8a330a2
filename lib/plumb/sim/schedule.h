// plumb/sim/schedule.h — what the simulated IMU does: a sequence of still holds and turns.
//
// A schedule starts at an attitude R_n_b (body FRD to NED) and is a list of steps:
//   Still  {duration_s, label}           hold the current attitude;
//   Rotate {axis_b, angle_rad, duration_s}  turn about an axis fixed in the body frame.
// Turns follow a smooth profile with zero rate and zero angular acceleration at both ends
// (u = t / T in [0, 1]):
//
//   angle(t) = A (u - sin(2 pi u) / (2 pi))
//   rate(t)  = A / T (1 - cos(2 pi u))
//   accel(t) = A / T^2 2 pi sin(2 pi u)
//
// so rate and angular acceleration are continuous and known analytically (Motion). The IMU is
// turned about its own origin (the x accelerometer): there is no translation.
//
// Ready-made schedules: MultiPose (well-spread poses for the generalised calibration),
// PaperStatic (the seed paper's one-minute level, x-north hold) and PaperBenchmark (the seed
// paper's section 3.1 benchmark sequence); NamedSchedule picks one by name with the defaults
// every front end (plumb simulate, the Python module's simulate) offers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "plumb/core/types.h"

namespace plumb::sim {

/// Hold the current attitude.
struct Still {
  double duration_s = 0.0;  ///< length of the hold, s, > 0
  std::string label;        ///< name of the pose in reports, e.g. "x up"; "" = "still #k"
};

/// Turn about an axis fixed in the body frame with the smooth profile above.
struct Rotate {
  Vec3 axis_b = Vec3::UnitZ();  ///< rotation axis, body frame (normalised when added; |axis| > 0)
  double angle_rad = 0.0;       ///< signed turn angle, rad, right-hand rule about axis_b
  double duration_s = 0.0;      ///< length of the turn, s, > 0
};

/// One step of a schedule.
using Step = std::variant<Still, Rotate>;

/// The body's motion relative to NED at one instant (no Earth rate in it).
struct Motion {
  Quat R_n_b = Quat::Identity();      ///< attitude, body to NED
  Vec3 omega_nb_b = Vec3::Zero();     ///< angular rate of body wrt NED, body frame, rad/s
  Vec3 alpha_nb_b = Vec3::Zero();     ///< time derivative of omega_nb_b, rad/s^2
  std::size_t step = 0;               ///< index of the step this instant belongs to
};

/// Turn angle after t_s seconds of a turn of angle_rad lasting duration_s (t_s clamped to
/// [0, duration_s]), rad; and its first and second time derivatives (rad/s, rad/s^2).
double TurnAngle(double angle_rad, double duration_s, double t_s);
double TurnRate(double angle_rad, double duration_s, double t_s);
double TurnAcceleration(double angle_rad, double duration_s, double t_s);

/// A sequence of steps from a starting attitude. Steps are validated when added (plumb::Error
/// names the bad field); the attitude at the start of every step is kept for lookups.
class Schedule {
 public:
  /// An empty schedule starting at `start_R_n_b` (normalised).
  explicit Schedule(const Quat& start_R_n_b = Quat::Identity());

  /// Appends a step; throws plumb::Error if a duration is not finite and > 0, the axis is zero
  /// or not finite, or the angle is not finite.
  Schedule& Add(const Step& step);
  /// Appends Still{duration_s, label}.
  Schedule& Hold(double duration_s, const std::string& label = "");
  /// Appends Rotate{axis_b, angle_rad, duration_s}.
  Schedule& Turn(const Vec3& axis_b, double angle_rad, double duration_s);
  /// Appends the single-axis turn (angle in [0, pi]) from the current end attitude to
  /// `target_R_n_b`; appends nothing when they already agree to 1e-12 rad.
  Schedule& TurnTo(const Quat& target_R_n_b, double duration_s);

  const Quat& start_R_n_b() const { return start_R_n_b_; }
  const std::vector<Step>& steps() const { return steps_; }
  std::size_t size() const { return steps_.size(); }
  bool empty() const { return steps_.empty(); }
  /// Total duration, s.
  double duration_s() const { return start_s_.back(); }
  /// Start time of step i from the schedule start, s (i == size() gives the end).
  double step_start_s(std::size_t i) const { return start_s_.at(i); }
  /// Duration of step i, s.
  double step_duration_s(std::size_t i) const;
  /// Attitude at the start of step i (i == size() gives the end attitude).
  const Quat& step_start_R_n_b(std::size_t i) const { return start_R_n_b_of_step_.at(i); }
  const Quat& end_R_n_b() const { return start_R_n_b_of_step_.back(); }
  bool is_still(std::size_t i) const { return std::holds_alternative<Still>(steps_.at(i)); }

  /// Motion at time t_s from the schedule start (clamped to [0, duration_s()]).
  Motion At(double t_s) const;
  /// Motion at time t_s into step i (clamped to the step's duration).
  Motion AtStep(std::size_t i, double t_s) const;

 private:
  Quat start_R_n_b_;
  std::vector<Step> steps_;
  std::vector<double> start_s_{0.0};     ///< size() + 1 entries
  std::vector<Quat> start_R_n_b_of_step_;  ///< size() + 1 entries
};

/// The ready-made schedules' defaults (NamedSchedule): holds and turns, s, and multipose's
/// number of poses.
inline constexpr int kMultiPosePoses = 12;
inline constexpr double kMultiPoseStill_s = 5.0;
inline constexpr double kMultiPoseTurn_s = 2.0;
inline constexpr double kPaperStaticStill_s = 60.0;
inline constexpr double kPaperBenchmarkStill_s = 20.0;
inline constexpr double kPaperBenchmarkTurn_s = 3.0;

/// Well-spread still poses for the generalised calibration, joined by single-axis turns.
/// Pose 1 is level (z down, x north); poses 1-6 are the six faces (z, x, y down, then z, x, y
/// up), poses 7.. are tilts in between chosen by farthest-point sampling of the down direction
/// in the body frame; every pose but the first gets a random heading. Every pose is distinct,
/// and the schedule is the same for the same seed. Each pose is held still_s seconds; each
/// turn takes turn_s seconds. Throws plumb::Error unless 1 <= n_poses <= 10000 and the
/// durations are finite and > 0. With n_poses < 6 only the first n faces are visited.
Schedule MultiPose(int n_poses, double still_s, double turn_s, std::uint64_t seed);

/// The seed paper's static test (section 3.2): one still hold, level with x north
/// (R_n_b = identity), still_s seconds (the paper: about a minute).
Schedule PaperStatic(double still_s = kPaperStaticStill_s);

/// The seed paper's benchmark sequence (section 3.1), starting level with x north:
///  1. accelerometer: each axis parallel (down) and antiparallel (up) to gravity, still_s each
///     ("z down", "z up", "x down", "x up", "y down", "y up");
///  2. gyroscope: z parallel to gravity ("z down"), then perpendicular ("z west", y down),
///     still_s each;
///  3. for x, y, z: that axis pointing up, still_s, then four +90 deg turns about it
///     (anticlockwise seen from above), each of turn_s seconds and followed by still_s still
///     ("x up 0 deg", "x up 90 deg", ..., "x up 360 deg");
///  4. z parallel and perpendicular again.
/// Poses are joined by single-axis turns of turn_s seconds. 25 still holds in all.
Schedule PaperBenchmark(double still_s = kPaperBenchmarkStill_s,
                        double turn_s = kPaperBenchmarkTurn_s);

/// A ready-made schedule by name, as a front end is asked for it.
struct ScheduleRequest {
  std::string kind = "multipose";  ///< multipose, paper-static or paper-benchmark
  std::optional<int> poses;        ///< multipose only: the number of poses, 1..10000 (12)
  /// Each still hold, s, > 0 (multipose 5, paper-static 60, paper-benchmark 20).
  std::optional<double> still_s;
  /// Each turn, s, > 0 (multipose 2, paper-benchmark 3); paper-static has none.
  std::optional<double> turn_s;
  std::uint64_t seed = 1;  ///< multipose: the seed of the tilts and headings
};

/// How a front end names the request's fields in its errors (the command line its flags, the
/// Python module its keywords).
struct ScheduleOptionNames {
  std::string kind;   ///< the option that names the schedule
  std::string poses;  ///< ... the number of poses
  std::string turn;   ///< ... the length of a turn
};

/// The schedule `request` names, with the defaults above for what it leaves out. Throws
/// plumb::Error naming the options by `names` when the kind is unknown, poses is given for
/// another kind than multipose, or a turn length for paper-static (and as MultiPose,
/// PaperStatic and PaperBenchmark for bad numbers).
Schedule NamedSchedule(const ScheduleRequest& request, const ScheduleOptionNames& names);

}  // namespace plumb::sim

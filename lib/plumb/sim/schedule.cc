#include "plumb/sim/schedule.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb::sim {
namespace {

using units::kPi;
using units::kTwoPi;

void CheckDuration(double duration_s, const char* what) {
  if (!std::isfinite(duration_s) || duration_s <= 0.0) {
    throw Error(std::string(what) + " duration " + Number(duration_s) +
                " s must be finite and > 0");
  }
}

double Fraction(double duration_s, double t_s) {
  return std::clamp(t_s / duration_s, 0.0, 1.0);
}

Quat AxisAngle(const Vec3& axis, double angle_rad) {
  return Quat(Eigen::AngleAxisd(angle_rad, axis));
}

/// The attitude whose body-frame down direction is `down_b` (unit), with heading `yaw_rad`
/// about the NED down axis.
Quat PoseWithDown(const Vec3& down_b, double yaw_rad) {
  const Quat level = Quat::FromTwoVectors(down_b, Vec3::UnitZ());
  return (AxisAngle(Vec3::UnitZ(), yaw_rad) * level).normalized();
}

/// A unit vector in the body frame, farthest (largest smallest angle) from `taken` among
/// `candidates` random directions.
Vec3 FarthestDirection(const std::vector<Vec3>& taken, std::mt19937_64& rng, int candidates) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Vec3 best = Vec3::UnitZ();
  double best_cos = std::numeric_limits<double>::infinity();
  for (int c = 0; c < candidates; ++c) {
    Vec3 v(normal(rng), normal(rng), normal(rng));
    if (v.norm() < 1e-6) continue;
    v.normalize();
    double max_cos = -1.0;  // cosine to the nearest direction taken
    for (const Vec3& t : taken) max_cos = std::max(max_cos, v.dot(t));
    if (max_cos < best_cos) {
      best_cos = max_cos;
      best = v;
    }
  }
  return best;
}

}  // namespace

double TurnAngle(double angle_rad, double duration_s, double t_s) {
  const double u = Fraction(duration_s, t_s);
  return angle_rad * (u - std::sin(kTwoPi * u) / kTwoPi);
}

double TurnRate(double angle_rad, double duration_s, double t_s) {
  const double u = Fraction(duration_s, t_s);
  return angle_rad / duration_s * (1.0 - std::cos(kTwoPi * u));
}

double TurnAcceleration(double angle_rad, double duration_s, double t_s) {
  const double u = Fraction(duration_s, t_s);
  return angle_rad / (duration_s * duration_s) * kTwoPi * std::sin(kTwoPi * u);
}

Schedule::Schedule(const Quat& start_R_n_b)
    : start_R_n_b_(start_R_n_b.normalized()), start_R_n_b_of_step_{start_R_n_b_} {
  if (!start_R_n_b.coeffs().allFinite() || start_R_n_b.norm() < 1e-12) {
    throw Error("schedule start attitude must be a finite non-zero quaternion");
  }
}

Schedule& Schedule::Add(const Step& step) {
  Step checked = step;
  Quat end = end_R_n_b();
  double duration_s = 0.0;
  if (auto* still = std::get_if<Still>(&checked)) {
    CheckDuration(still->duration_s, "still step");
    duration_s = still->duration_s;
  } else {
    auto& turn = std::get<Rotate>(checked);
    CheckDuration(turn.duration_s, "turn");
    if (!turn.axis_b.allFinite() || turn.axis_b.norm() < 1e-12) {
      throw Error("turn axis must be a finite non-zero vector in the body frame");
    }
    if (!std::isfinite(turn.angle_rad)) throw Error("turn angle must be finite");
    turn.axis_b.normalize();
    duration_s = turn.duration_s;
    end = (end * AxisAngle(turn.axis_b, turn.angle_rad)).normalized();
  }
  steps_.push_back(std::move(checked));
  start_s_.push_back(start_s_.back() + duration_s);
  start_R_n_b_of_step_.push_back(end);
  return *this;
}

Schedule& Schedule::Hold(double duration_s, const std::string& label) {
  return Add(Still{duration_s, label});
}

Schedule& Schedule::Turn(const Vec3& axis_b, double angle_rad, double duration_s) {
  return Add(Rotate{axis_b, angle_rad, duration_s});
}

Schedule& Schedule::TurnTo(const Quat& target_R_n_b, double duration_s) {
  if (!target_R_n_b.coeffs().allFinite() || target_R_n_b.norm() < 1e-12) {
    throw Error("turn target attitude must be a finite non-zero quaternion");
  }
  const Eigen::AngleAxisd delta(end_R_n_b().conjugate() * target_R_n_b.normalized());
  if (std::abs(delta.angle()) < 1e-12) return *this;
  return Turn(delta.axis(), delta.angle(), duration_s);
}

double Schedule::step_duration_s(std::size_t i) const {
  return start_s_.at(i + 1) - start_s_.at(i);
}

Motion Schedule::AtStep(std::size_t i, double t_s) const {
  Motion m;
  m.step = i;
  m.R_n_b = start_R_n_b_of_step_.at(i);
  const auto* turn = std::get_if<Rotate>(&steps_.at(i));
  if (turn == nullptr) return m;
  const double angle = TurnAngle(turn->angle_rad, turn->duration_s, t_s);
  m.R_n_b = (m.R_n_b * AxisAngle(turn->axis_b, angle)).normalized();
  m.omega_nb_b = turn->axis_b * TurnRate(turn->angle_rad, turn->duration_s, t_s);
  m.alpha_nb_b = turn->axis_b * TurnAcceleration(turn->angle_rad, turn->duration_s, t_s);
  return m;
}

Motion Schedule::At(double t_s) const {
  if (steps_.empty()) {
    Motion m;
    m.R_n_b = start_R_n_b_;
    return m;
  }
  // The step whose [start, next start) holds t_s; the last step also holds its end.
  const auto it = std::upper_bound(start_s_.begin() + 1, start_s_.end() - 1, t_s);
  const std::size_t i = static_cast<std::size_t>(it - (start_s_.begin() + 1));
  return AtStep(i, t_s - start_s_[i]);
}

Schedule MultiPose(int n_poses, double still_s, double turn_s, std::uint64_t seed) {
  if (n_poses < 1 || n_poses > 10000) {
    throw Error("MultiPose needs 1 to 10000 poses (got " + std::to_string(n_poses) + ")");
  }
  CheckDuration(still_s, "MultiPose still");
  CheckDuration(turn_s, "MultiPose turn");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> heading(0.0, kTwoPi);
  const std::vector<std::pair<Vec3, std::string>> faces = {
      {Vec3::UnitZ(), "z down"},  {Vec3::UnitX(), "x down"},  {Vec3::UnitY(), "y down"},
      {-Vec3::UnitZ(), "z up"},   {-Vec3::UnitX(), "x up"},   {-Vec3::UnitY(), "y up"}};
  Schedule schedule;  // starts level, x north
  std::vector<Vec3> taken;
  for (int k = 0; k < n_poses; ++k) {
    Vec3 down_b;
    std::string label;
    if (k < static_cast<int>(faces.size())) {
      down_b = faces[static_cast<std::size_t>(k)].first;
      label = "pose " + std::to_string(k + 1) + " (" + faces[static_cast<std::size_t>(k)].second + ")";
    } else {
      down_b = FarthestDirection(taken, rng, 64);
      label = "pose " + std::to_string(k + 1);
    }
    taken.push_back(down_b);
    if (k > 0) schedule.TurnTo(PoseWithDown(down_b, heading(rng)), turn_s);
    schedule.Hold(still_s, label);
  }
  return schedule;
}

Schedule PaperStatic(double still_s) {
  CheckDuration(still_s, "PaperStatic still");
  Schedule schedule;
  schedule.Hold(still_s, "level, x north");
  return schedule;
}

Schedule PaperBenchmark(double still_s, double turn_s) {
  CheckDuration(still_s, "PaperBenchmark still");
  CheckDuration(turn_s, "PaperBenchmark turn");
  const double half = kPi / 2.0;
  const Quat z_down = Quat::Identity();
  const Quat z_up = AxisAngle(Vec3::UnitX(), kPi);
  const Quat x_down = AxisAngle(Vec3::UnitY(), -half);
  const Quat x_up = AxisAngle(Vec3::UnitY(), half);
  const Quat y_down = AxisAngle(Vec3::UnitX(), half);  // z then points west
  const Quat y_up = AxisAngle(Vec3::UnitX(), -half);

  Schedule schedule;
  auto visit = [&](const Quat& pose, const std::string& label) {
    schedule.TurnTo(pose, turn_s);
    schedule.Hold(still_s, label);
  };
  // 1. Accelerometer: each axis parallel and antiparallel to gravity.
  visit(z_down, "z down");
  visit(z_up, "z up");
  visit(x_down, "x down");
  visit(x_up, "x up");
  visit(y_down, "y down");
  visit(y_up, "y up");
  // 2. Gyroscope: z parallel, then perpendicular to gravity.
  visit(z_down, "z down (gyro)");
  visit(y_down, "z west (gyro)");
  // 3. Each axis up, turned +90 deg four times about itself.
  const std::vector<std::pair<Quat, char>> up = {{x_up, 'x'}, {y_up, 'y'}, {z_up, 'z'}};
  for (const auto& [pose, axis] : up) {
    const std::string name = std::string(1, axis) + " up";
    visit(pose, name + " 0 deg");
    const Vec3 axis_b = axis == 'x' ? Vec3::UnitX() : axis == 'y' ? Vec3::UnitY() : Vec3::UnitZ();
    for (int turn = 1; turn <= 4; ++turn) {
      schedule.Turn(axis_b, half, turn_s);
      schedule.Hold(still_s, name + " " + std::to_string(90 * turn) + " deg");
    }
  }
  // 4. z parallel and perpendicular again.
  visit(z_down, "z down (gyro, end)");
  visit(y_down, "z west (gyro, end)");
  return schedule;
}

Schedule NamedSchedule(const ScheduleRequest& r, const ScheduleOptionNames& names) {
  if (r.kind != "multipose" && r.kind != "paper-static" && r.kind != "paper-benchmark") {
    throw Error(names.kind + " must be multipose, paper-static or paper-benchmark (got '" +
                r.kind + "')");
  }
  if (r.kind != "multipose" && r.poses) {
    throw Error(names.poses + " applies to " + names.kind + " multipose only");
  }
  if (r.kind == "paper-static") {
    if (r.turn_s) throw Error(names.turn + " does not apply to " + names.kind + " paper-static");
    return PaperStatic(r.still_s.value_or(kPaperStaticStill_s));
  }
  if (r.kind == "paper-benchmark") {
    return PaperBenchmark(r.still_s.value_or(kPaperBenchmarkStill_s),
                          r.turn_s.value_or(kPaperBenchmarkTurn_s));
  }
  return MultiPose(r.poses.value_or(kMultiPosePoses), r.still_s.value_or(kMultiPoseStill_s),
                   r.turn_s.value_or(kMultiPoseTurn_s), r.seed);
}

}  // namespace plumb::sim

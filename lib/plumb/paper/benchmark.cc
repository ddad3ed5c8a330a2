// plumb/paper/benchmark.cc — see benchmark.h.
#include "plumb/paper/benchmark.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb::paper {
namespace {

constexpr double kHalfPi = units::kPi / 2.0;

std::string PoseName(int axis, bool parallel) {
  return std::string(kAxisName[axis]) + (parallel ? " parallel" : " antiparallel");
}

/// Gyroscope bias b0 + b1 (t - t0) of one axis from the first and last of `periods`.
void FitBiasLine(const std::vector<StillPeriod>& still, const std::vector<int>& periods,
                 int axis, double t0_s, double& b0, double& b1) {
  const StillPeriod& first = still[periods.front()];
  const StillPeriod& last = still[periods.back()];
  const double dt = last.stats.t_mid_s - first.stats.t_mid_s;
  b1 = 0.0;
  if (periods.size() >= 2 && dt > 0.0) {
    b1 = (last.stats.gyr_mean[axis] - first.stats.gyr_mean[axis]) / dt;
  }
  b0 = first.stats.gyr_mean[axis] - b1 * (first.stats.t_mid_s - t0_s);
}

/// Integral of (gyro - b0 - b1 (t - t0)) over samples [begin, end), trapezoid rule.
Vec3 IntegrateRate(const ImuSeries& s, std::size_t begin, std::size_t end,
                   const PaperBenchmarkResult& r) {
  Vec3 sum = Vec3::Zero();
  auto corrected = [&](std::size_t k) {
    return Vec3(s.gyr[k].cast<double>() - r.gyro_bias_b0 - r.gyro_bias_b1 * (s.t_s[k] - r.t0_s));
  };
  for (std::size_t k = begin + 1; k < end; ++k) {
    sum += 0.5 * (corrected(k - 1) + corrected(k)) * (s.t_s[k] - s.t_s[k - 1]);
  }
  return sum;
}

void ClassifyStill(const ImuSeries& series, const std::vector<StillSegment>& still,
                   double max_tilt_rad, PaperBenchmarkResult& r) {
  for (const StillSegment& seg : still) {
    StillPeriod p;
    p.segment = seg;
    p.stats = signal::ComputeSegmentStats(series, seg);
    p.pose = ClassifyPose(p.stats.acc_mean);
    r.still.push_back(p);
  }
  for (int i = 0; i < static_cast<int>(r.still.size()); ++i) {
    const PoseClass& pose = r.still[i].pose;
    if (pose.axis >= 0 && pose.tilt_rad <= max_tilt_rad) {
      auto& slot = pose.parallel ? r.parallel_index[pose.axis] : r.antiparallel_index[pose.axis];
      if (slot < 0) slot = i;
      if (pose.axis == 2 && pose.parallel) r.z_parallel_index.push_back(i);
    }
    if (pose.axis >= 0 && pose.z_elevation_rad <= max_tilt_rad) r.z_perpendicular_index.push_back(i);
  }
}

void AccelerometerClosedForm(const PaperBenchmarkOptions& options, PaperBenchmarkResult& r) {
  std::string missing;
  for (int j = 0; j < 3; ++j) {
    if (r.parallel_index[j] < 0) missing += " " + PoseName(j, true);
    if (r.antiparallel_index[j] < 0) missing += " " + PoseName(j, false);
  }
  if (!missing.empty()) {
    throw InsufficientDataError(
        "paper-benchmark accelerometer: no still pose with" + missing +
        " to gravity (record each axis pointing down and up, still, about 20 s each)");
  }
  for (int j = 0; j < 3; ++j) {
    r.U_plus.col(j) = r.still[r.parallel_index[j]].stats.acc_mean;
    r.U_minus.col(j) = r.still[r.antiparallel_index[j]].stats.acc_mean;
    r.accel_bias[j] = (r.U_plus(j, j) + r.U_minus(j, j)) / 2.0;  // Eq. (3)
  }
  r.Q = (r.U_plus.col(0).norm() + r.U_plus.col(1).norm() + r.U_plus.col(2).norm()) / 3.0;
  r.accel_coupling_paper = (r.U_plus - r.U_minus) / (2.0 * r.Q);
  r.gravity_m_s2 = options.gravity_m_s2;
  r.F = -(r.U_plus - r.U_minus) / (2.0 * options.gravity_m_s2);
  r.b_a = r.accel_bias;
}

void GyroscopeBias(double max_tilt_rad, PaperBenchmarkResult& r) {
  std::vector<int> xy = r.z_parallel_index;
  if (xy.empty()) {
    for (int i = 0; i < static_cast<int>(r.still.size()); ++i) {
      const PoseClass& pose = r.still[i].pose;
      if (pose.axis == 2 && !pose.parallel && pose.tilt_rad <= max_tilt_rad) xy.push_back(i);
    }
    if (!xy.empty()) {
      AddNotice(r.notes, "gyro_bias_from_up", "no still period with z parallel to gravity (down) for the x and y "
                        "gyroscope bias; used those with z antiparallel (up)");
    }
  }
  if (xy.empty() || r.z_perpendicular_index.empty()) {
    throw InsufficientDataError(
        "paper-benchmark gyroscope bias: needs still periods with z parallel to gravity and "
        "with z perpendicular to it (record both at the start and the end, 20 s each)");
  }
  for (int axis = 0; axis < 3; ++axis) {
    const std::vector<int>& periods = axis < 2 ? xy : r.z_perpendicular_index;
    FitBiasLine(r.still, periods, axis, r.t0_s, r.gyro_bias_b0[axis], r.gyro_bias_b1[axis]);
  }
  if (xy.size() < 2 || r.z_perpendicular_index.size() < 2) {
    AddNotice(r.notes, "gyro_bias_drift_zero", "only one still period of a kind for the gyroscope bias: b1 = 0 there");
  }
  r.b_g = r.gyro_bias_b0;
  r.gyro_bias_drift = r.gyro_bias_b1;
}

/// The gaps between consecutive still periods of the same pose: turns about the vertical.
std::vector<MotionRange> TurnsBetweenStill(const PaperBenchmarkResult& r) {
  std::vector<MotionRange> gaps;
  for (std::size_t i = 0; i + 1 < r.still.size(); ++i) {
    const PoseClass& a = r.still[i].pose;
    const PoseClass& b = r.still[i + 1].pose;
    if (a.axis < 0 || a.axis != b.axis || a.parallel != b.parallel) continue;
    MotionRange m;
    m.begin = r.still[i].segment.end - 1;  // from the last still sample ...
    m.end = r.still[i + 1].segment.begin + 1;  // ... to the first still sample after it
    m.label = "turn after '" + r.still[i].segment.label + "'";
    m.axis = a.axis;
    gaps.push_back(m);
  }
  return gaps;
}

void GyroscopeCoupling(const ImuSeries& series, const std::vector<MotionRange>& given,
                       PaperBenchmarkResult& r) {
  const std::vector<MotionRange> ranges = given.empty() ? TurnsBetweenStill(r) : given;
  Mat3 integral_sum = Mat3::Zero();
  for (const MotionRange& m : ranges) {
    if (m.end > series.size() || m.begin + 2 > m.end) {
      throw Error("paper-benchmark: turn '" + m.label + "' [" + std::to_string(m.begin) + ", " +
                  std::to_string(m.end) + ") is not a range of at least 2 samples inside the "
                  "series of " + std::to_string(series.size()));
    }
    TurnPeriod turn;
    turn.range = m;
    turn.integral = IntegrateRate(series, m.begin, m.end, r);
    turn.axis = m.axis;
    const bool labelled = m.label.size() >= 5 && m.label.compare(1, 4, "_rot") == 0 &&
                          m.label[0] >= 'x' && m.label[0] <= 'z';
    if (turn.axis < 0 && labelled) turn.axis = m.label[0] - 'x';
    if (turn.axis < 0 || turn.axis > 2) turn.integral.cwiseAbs().maxCoeff(&turn.axis);
    const double along = turn.integral[turn.axis];
    turn.nominal_angle_rad = std::round(along / kHalfPi) * kHalfPi;
    if (turn.nominal_angle_rad == 0.0) {
      AddNotice(r.notes, "turn_too_small", "'" + m.label + "' turned less than 45 deg: not used");
      continue;
    }
    r.turns.push_back(turn);
    integral_sum.col(turn.axis) += turn.integral;
    r.total_angle_rad[turn.axis] += turn.nominal_angle_rad;
  }
  std::string missing;
  for (int j = 0; j < 3; ++j) {
    if (r.total_angle_rad[j] == 0.0) missing += std::string(" ") + kAxisName[j];
  }
  if (!missing.empty()) {
    throw InsufficientDataError("paper-benchmark gyroscope coupling: no turn about" + missing +
                                " (turn about each axis while it points up: four 90 deg turns "
                                "with still periods between, or one 360 deg turn)");
  }
  for (int j = 0; j < 3; ++j) {
    r.gyro_coupling_paper.col(j) = integral_sum.col(j) / r.total_angle_rad[j];
  }
  r.E = r.gyro_coupling_paper;
}

}  // namespace

PoseClass ClassifyPose(const Vec3& acc_mean) {
  PoseClass pose;
  const double norm = acc_mean.norm();
  if (!std::isfinite(norm) || norm == 0.0) return pose;
  acc_mean.cwiseAbs().maxCoeff(&pose.axis);
  pose.parallel = acc_mean[pose.axis] < 0.0;
  pose.tilt_rad = std::acos(std::min(1.0, std::abs(acc_mean[pose.axis]) / norm));
  pose.z_elevation_rad = std::asin(std::min(1.0, std::abs(acc_mean.z()) / norm));
  return pose;
}

PaperBenchmarkResult CalibratePaperBenchmark(const ImuSeries& series,
                                             const std::vector<StillSegment>& still,
                                             const std::vector<MotionRange>& motion,
                                             const PaperBenchmarkOptions& options) {
  if (!series.has_gyro()) throw Error("paper-benchmark needs the gyroscope; the series has none");
  if (series.gyr_unit != "rad/s") {
    throw Error("paper-benchmark: the gyroscope must be in rad/s to find the turn angles; it is "
                "in '" + series.gyr_unit + "'");
  }
  if (!(options.gravity_m_s2 > 0.0) || !std::isfinite(options.gravity_m_s2)) {
    throw Error("paper-benchmark: gravity_m_s2 must be finite and > 0");
  }
  if (!(options.max_tilt_rad > 0.0) || !(options.max_tilt_rad <= kHalfPi / 2.0)) {
    throw Error("paper-benchmark: max_tilt_rad must be in (0, pi/4]");
  }
  PaperBenchmarkResult r;
  r.t0_s = series.t_s.front();
  ClassifyStill(series, still, options.max_tilt_rad, r);
  AccelerometerClosedForm(options, r);
  GyroscopeBias(options.max_tilt_rad, r);
  GyroscopeCoupling(series, motion, r);
  return r;
}

}  // namespace plumb::paper

#include "plumb/estimation/calibrator.h"

#include <ceres/ceres.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <memory>
#include <limits>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/observability.h"
#include "plumb/residuals/manifolds.h"
#include "plumb/residuals/motion_residual.h"
#include "plumb/residuals/still_residuals.h"
#include "plumb/residuals/velocity_residual.h"
#include "plumb/signal/correlation_time.h"
#include "plumb/signal/segment_stats.h"

namespace plumb::estimation {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kDegToRad = M_PI / 180.0;

using residuals::MotionResidual;
using residuals::StillResidual;

/// One still segment as the solver sees it.
struct Still {
  StillSegment segment;
  signal::SegmentStats stats;
  std::array<double, 4> q{0, 0, 0, 1};  // R_n_b, Eigen order x y z w
  bool known = false;         // attitude held constant
  bool heading_only = false;  // tilt known, heading estimated (HeadingManifold)
  bool chain_head = false;    // heading held as the gauge (TiltManifold)
  bool spinning = false;      // known nonzero rate: gyroscope residual only
  residuals::StillMeasurement acc_measurement, gyr_measurement;
};

struct Motion {
  std::size_t from = 0;  // still index
  std::size_t first = 0, last = 0;  // sample range [first, last]
};

/// A problem built from the current values, with its residual blocks (null where absent).
struct BuiltProblem {
  std::unique_ptr<ceres::Problem> problem;
  std::vector<ceres::ResidualBlockId> acc, gyr;  // per still segment
  std::vector<ceres::ResidualBlockId> motion;    // per motion interval
  std::vector<ceres::ResidualBlockId> velocity;  // per motion interval, when used
};

Quat ToQuat(const std::array<double, 4>& q) { return Quat(q[3], q[0], q[1], q[2]); }
std::array<double, 4> FromQuat(const Quat& q) { return {q.x(), q.y(), q.z(), q.w()}; }

/// Mean accelerometer (or gyroscope) output of every segment at rest (not turning at a stated
/// rate), in segment order.
std::vector<Vec3> AtRestMeans(const std::vector<Still>& still, bool gyro) {
  std::vector<Vec3> out;
  for (const auto& s : still) {
    if (!s.spinning) out.push_back(gyro ? s.stats.gyr_mean : s.stats.acc_mean);
  }
  return out;
}

void CheckEffectData(const model::Model& model, const ImuSeries& series, const geo::Site& site) {
  if (site.known && model.has_effect("earth_rate")) {
    throw Error("earth_rate is a candidate only without a site: with --lat/--lon Earth rate is "
                "already in the model (from GeographicLib); drop it from the model");
  }
  for (const auto& term : model.terms()) {
    const auto& info = term.effect->info();
    if (info.excitation.temperature && !series.has_temperature()) {
      throw InsufficientDataError(info.name + " needs the sensor temperature, but the input has "
                                  "no temperature column; record it (temp_c) or drop the effect");
    }
  }
}

/// Unit of a reported parameter: the catalogue's SI unit, or, for the base effects on
/// unscaled sensor output, that output's unit (bias) and unit per SI input (matrix).
std::string UnitOf(const model::EffectInfo& info, int i, const ImuSeries& series) {
  const std::string& si = info.parameters[static_cast<std::size_t>(i)].unit;
  const bool accel = info.sensor == model::Sensor::kAccel;
  const std::string& out = accel ? series.acc_unit : series.gyr_unit;
  const std::string in = accel ? "m/s^2" : "rad/s";
  if (out == in || info.input_side) return si;
  if (!info.linear_stage) {
    // Additive terms are in output units: "rad/s per m/s^2" becomes "counts per m/s^2".
    return info.ScalesWithOutput(i) ? out + si.substr(in.size()) : si;
  }
  const bool matrix = info.parameters[static_cast<std::size_t>(i)].name.rfind("matrix.", 0) == 0;
  return matrix ? out + " per " + in : out;
}

/// The whitened residuals and Jacobian of `probe` (built with the probe terms free) at the
/// current values: columns `free_blocks` (the fit's free unknowns, named `names`) then every
/// probe term's block.
ProbeJacobian ProbeColumns(const model::Model& model, model::ParameterBlocks& theta,
                           const BuiltProblem& probe, const std::vector<double*>& free_blocks,
                           const std::vector<std::string>& names,
                           const std::vector<bool>& is_model) {
  ProbeJacobian out;
  out.unknown_names = names;
  out.unknown_is_model = is_model;
  std::vector<double*> blocks = free_blocks;
  for (int t = 0; t < model.num_terms(); ++t) {
    const auto& term = model.terms()[static_cast<std::size_t>(t)];
    if (!term.probe) continue;
    blocks.push_back(theta[static_cast<std::size_t>(t)].data());
    for (int i = 0; i < term.effect->info().size(); ++i) {
      out.probe_names.push_back(term.effect->info().ParameterName(i));
      out.probe_term.push_back(t);
    }
  }
  ceres::Problem::EvaluateOptions eval;
  eval.parameter_blocks = blocks;
  auto add_rows = [&](ceres::ResidualBlockId id, ProbeJacobian::RowKind kind, int index) {
    if (id == nullptr) return;
    eval.residual_blocks.push_back(id);
    for (int axis = 0; axis < 3; ++axis) {
      out.row_kind.push_back(kind);
      out.row_index.push_back(index);
      out.row_axis.push_back(axis);
    }
  };
  for (std::size_t k = 0; k < probe.acc.size(); ++k) {
    add_rows(probe.acc[k], ProbeJacobian::RowKind::kStillAccel, static_cast<int>(k));
    add_rows(probe.gyr[k], ProbeJacobian::RowKind::kStillGyro, static_cast<int>(k));
  }
  for (std::size_t k = 0; k < probe.motion.size(); ++k) {
    add_rows(probe.motion[k], ProbeJacobian::RowKind::kMotion, static_cast<int>(k));
  }
  for (std::size_t k = 0; k < probe.velocity.size(); ++k) {
    add_rows(probe.velocity[k], ProbeJacobian::RowKind::kVelocity, static_cast<int>(k));
  }
  std::vector<double> r;
  ceres::CRSMatrix crs;
  probe.problem->Evaluate(eval, nullptr, &r, nullptr, &crs);
  Eigen::MatrixXd all = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int idx = crs.rows[static_cast<std::size_t>(row)];
         idx < crs.rows[static_cast<std::size_t>(row) + 1]; ++idx) {
      all(row, crs.cols[static_cast<std::size_t>(idx)]) = crs.values[static_cast<std::size_t>(idx)];
    }
  }
  const auto n_free = static_cast<Eigen::Index>(names.size());
  out.r = Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
  out.J = all.leftCols(n_free);
  out.Z = all.rightCols(all.cols() - n_free);
  return out;
}

}  // namespace

int CountDistinctOrientations(const std::vector<Vec3>& acc_means, double min_angle_deg) {
  std::vector<Vec3> reps;
  for (const auto& m : acc_means) {
    const Vec3 u = m.normalized();
    const bool seen = std::any_of(reps.begin(), reps.end(), [&](const Vec3& r) {
      return std::acos(std::clamp(r.dot(u), -1.0, 1.0)) * kRadToDeg < min_angle_deg;
    });
    if (!seen) reps.push_back(u);
  }
  return static_cast<int>(reps.size());
}

CalibrationResult Calibrate(const ImuSeries& series, const std::vector<StillSegment>& segments,
                            const model::Model& model_in, const geo::Site& site,
                            const CalibrationOptions& options) {
  CalibrationResult result;
  result.method = options.method;
  result.site = site;
  model::Model model = model_in;
  const bool gyro_data = series.has_gyro();
  if (!gyro_data && model.has_gyro()) {
    model.DropGyro();
    result.warnings.push_back("the input has no gyroscope: calibrating the accelerometer only");
  }
  CheckEffectData(model, series, site);
  result.has_gyro = model.has_gyro();
  result.acc_unit = series.acc_unit;
  result.gyr_unit = series.gyr_unit;

  // Still segments and their statistics.
  std::vector<Still> still;
  for (const auto& seg : segments) {
    if (seg.end > series.size() || seg.begin >= seg.end) {
      throw Error("still segment '" + seg.label + "' [" + std::to_string(seg.begin) + ", " +
                  std::to_string(seg.end) + ") is outside the " + std::to_string(series.size()) +
                  " samples");
    }
    if (static_cast<int>(seg.count()) < options.min_segment_samples) continue;
    Still s;
    s.segment = seg;
    s.stats = signal::ComputeSegmentStats(series, seg);
    s.known = seg.known_R_n_b.has_value();
    s.spinning = seg.spinning();
    still.push_back(std::move(s));
  }
  if (still.empty()) {
    throw InsufficientDataError(
        "no still segment of at least " + std::to_string(options.min_segment_samples) +
        " samples: record the IMU still (a minute level, or many still poses joined by turns)");
  }
  const double g = site.gravity();
  // A known tilt with a free heading: the heading is seen only through Earth rate, so it is
  // estimated when the still gyroscope residuals with a site are in the fit, else held.
  const bool earth_rate_seen = site.known && result.has_gyro && options.use_still_gyro;
  for (auto& s : still) {
    if (s.known && s.segment.heading_free && earth_rate_seen) {
      s.known = false;
      s.heading_only = true;
    }
  }
  if (std::all_of(still.begin(), still.end(), [](const Still& s) { return s.spinning; })) {
    throw InsufficientDataError("every segment turns at a stated rate: record still poses too");
  }

  // Noise from the data: pooled scatter and correlation time over the still segments (not
  // the turning ones, whose scatter is signal).
  std::vector<StillSegment> used;
  for (const auto& s : still) {
    if (!s.spinning) used.push_back(s.segment);
  }
  const auto acc_noise = signal::EstimateCorrelationTime(series, used, signal::Sensor::kAccel);
  std::array<signal::CorrelationTime, 3> gyr_noise{};
  if (result.has_gyro) {
    gyr_noise = signal::EstimateCorrelationTime(series, used, signal::Sensor::kGyro);
  }
  // Per-axis tau for whitening (at least 1); the result reports the largest.
  Vec3 tau_acc = Vec3::Ones(), tau_gyr = Vec3::Ones();
  for (int i = 0; i < 3; ++i) {
    const auto axis = static_cast<std::size_t>(i);
    result.noise_acc[i] = std::max(std::sqrt(acc_noise[axis].variance), options.min_sigma_acc);
    tau_acc[i] = std::max(1.0, acc_noise[axis].tau_int);
    if (result.has_gyro) {
      result.noise_gyr[i] = std::max(std::sqrt(gyr_noise[axis].variance), options.min_sigma_gyr);
      tau_gyr[i] = std::max(1.0, gyr_noise[axis].tau_int);
    }
  }
  result.tau_acc = tau_acc.maxCoeff();
  result.tau_gyr = tau_gyr.maxCoeff();

  // Initial accelerometer.
  model::ParameterBlocks theta = model.ZeroParameters();
  const int t_acc = model.FindTerm("accel_linear");
  const AccelGuess acc_guess = GuessAccel(AtRestMeans(still, false), g);
  {
    auto& b = theta[static_cast<std::size_t>(t_acc)];
    b[0] = b[3] = b[5] = acc_guess.scale - 1.0;
    for (int i = 0; i < 3; ++i) b[static_cast<std::size_t>(6 + i)] = acc_guess.bias[i];
  }
  auto down_of = [&](const Still& s) {
    return Vec3(-(s.stats.acc_mean - acc_guess.bias) / acc_guess.scale).normalized();
  };

  // Chains of segments joined by motion.
  const bool motion_on = options.use_motion && result.has_gyro;
  std::vector<Motion> motions;
  for (std::size_t k = 0; k + 1 < still.size(); ++k) {
    const std::size_t first = still[k].segment.end - 1;
    const std::size_t last = still[k + 1].segment.begin;
    const double gap = series.t_s[last] - series.t_s[first];
    if (!motion_on || last <= first || gap > options.max_motion_s) continue;
    Motion m;
    m.from = k;
    m.first = first;
    m.last = last;
    motions.push_back(m);
  }
  std::vector<bool> joined_to_previous(still.size(), false);
  for (const auto& m : motions) joined_to_previous[m.from + 1] = true;

  // Initial gyroscope: bias from the still means, scale by the one-dimensional search.
  const int t_gyr = model.FindTerm("gyro_linear");
  double gyro_scale = 1.0;  // rad/s per sensor unit
  Vec3 gyro_bias0 = Vec3::Zero();
  if (result.has_gyro) {
    const auto at_rest = AtRestMeans(still, true);
    for (const auto& m : at_rest) gyro_bias0 += m / static_cast<double>(at_rest.size());
    std::vector<std::pair<std::size_t, std::size_t>> intervals;
    std::vector<Vec3> before, after;
    for (const auto& m : motions) {
      intervals.emplace_back(m.first, m.last);
      before.push_back(down_of(still[m.from]));
      after.push_back(down_of(still[m.from + 1]));
    }
    gyro_scale = GuessGyroScale(series, intervals, before, after, gyro_bias0);
    auto& b = theta[static_cast<std::size_t>(t_gyr)];
    b[0] = b[4] = b[8] = 1.0 / gyro_scale - 1.0;
    for (int i = 0; i < 3; ++i) b[static_cast<std::size_t>(9 + i)] = gyro_bias0[i];
  }

  // Fixed parameters are held at their nominal values, whatever the guesses above say.
  for (int t = 0; t < model.num_terms(); ++t) {
    const auto& fixed = model.terms()[static_cast<std::size_t>(t)].fixed;
    for (std::size_t i = 0; i < fixed.size(); ++i) {
      if (fixed[i]) theta[static_cast<std::size_t>(t)][i] = 0.0;
    }
  }

  // Initial attitudes: tilt from gravity, heading carried along each chain.
  for (std::size_t k = 0; k < still.size(); ++k) {
    Still& s = still[k];
    if (s.known || s.heading_only) {
      s.q = FromQuat(*s.segment.known_R_n_b);
      continue;
    }
    if (k > 0 && joined_to_previous[k]) {
      const auto it = std::find_if(motions.begin(), motions.end(),
                                   [&](const Motion& m) { return m.from + 1 == k; });
      const Quat dR = IntegrateRaw(series, it->first, it->last, gyro_bias0, gyro_scale);
      s.q = FromQuat(CorrectTilt(ToQuat(still[k - 1].q) * dR, down_of(s)));
    } else {
      const double heading = (k == 0 && options.first_heading_deg)
                                 ? *options.first_heading_deg * kDegToRad
                                 : 0.0;
      s.q = FromQuat(AttitudeFromDown(down_of(s), heading));
    }
  }
  // Gauge: the first segment of each chain holds its heading unless a known attitude in the
  // chain already fixes it (or there is no gyroscope, where every heading is free).
  {
    std::size_t k = 0;
    while (k < still.size()) {
      std::size_t end = k + 1;
      while (end < still.size() && joined_to_previous[end]) ++end;
      bool any_known = false;
      for (std::size_t j = k; j < end; ++j) {
        any_known = any_known || still[j].known || still[j].heading_only;
      }
      if (!any_known) still[k].chain_head = true;
      k = end;
    }
    if (!result.has_gyro) {
      for (auto& s : still) s.chain_head = !s.known && !s.heading_only;
    }
  }

  // The problem, built from the current values; `held` adds parameters (term, index) held
  // at their values (the pivots of unobservable directions, see below).
  const auto acc_terms = StillResidual::TermsOf(model, model::Sensor::kAccel);
  const auto gyr_terms = StillResidual::TermsOf(model, model::Sensor::kGyro);
  const bool still_gyro = result.has_gyro && options.use_still_gyro;
  for (auto& s : still) {
    const double n = static_cast<double>(s.stats.count);
    residuals::StillMeasurement m;
    m.dt_s = s.stats.t_mid_s - model.t_ref_s;
    m.dtemp_c = std::isfinite(s.stats.temp_mean_c) ? s.stats.temp_mean_c - model.temp_ref_c : 0.0;
    m.mean = s.stats.acc_mean;
    for (int i = 0; i < 3; ++i) m.sqrt_info[i] = std::sqrt(n / tau_acc[i]) / result.noise_acc[i];
    s.acc_measurement = m;
    if (still_gyro) {
      m.mean = s.stats.gyr_mean;
      for (int i = 0; i < 3; ++i) m.sqrt_info[i] = std::sqrt(n / tau_gyr[i]) / result.noise_gyr[i];
      s.gyr_measurement = m;
    }
  }
  std::vector<residuals::MotionSamples> motion_samples;
  std::vector<std::vector<Vec3>> output_rate;  // per motion, per sample: d y_g / dt, units/s
  for (auto& mo : motions) {
    residuals::MotionSamples ms;
    std::vector<Vec3> dy;
    for (std::size_t i = mo.first; i <= mo.last; ++i) {
      ms.dt_s.push_back(series.t_s[i] - model.t_ref_s);
      ms.acc.push_back(series.acc[i].cast<double>());
      ms.gyr.push_back(series.gyr[i].cast<double>());
      ms.dtemp_c.push_back(series.has_temperature() ? series.temp_c[i] - model.temp_ref_c : 0.0);
      const std::size_t a = i > 0 ? i - 1 : i, b = std::min(i + 1, series.size() - 1);
      const double h = series.t_s[b] - series.t_s[a];
      dy.push_back(h > 0 ? Vec3((series.gyr[b] - series.gyr[a]).cast<double>() / h) : Vec3::Zero());
    }
    ms.alpha_b.resize(dy.size());
    motion_samples.push_back(std::move(ms));
    output_rate.push_back(std::move(dy));
  }
  // Whitening of the motion residuals: the white gyroscope noise (sensor units) carried through
  // E^-1 into rad/s and integrated over the interval's steps. It depends on E, so it is set
  // from the starting E and again from the solved E before the final solve (the chi^2 then does
  // not depend on the starting values). The angular acceleration input of the effects
  // (time_offset, accel_size_effect) is the derivative of the corrected rate, E^-1 d y_g / dt
  // (central differences), set at the same two points.
  bool needs_velocity = false;
  for (const auto& term : model.terms()) {
    needs_velocity = needs_velocity || term.effect->info().excitation.angular_acceleration;
  }
  const bool velocity_on = motion_on && options.accel_in_motion.value_or(needs_velocity);
  std::vector<Vec3> velocity_info(motions.size(), Vec3::Ones());
  auto set_motion_weights = [&](const Mat3& E, const Mat3& F) {
    const Mat3 E_inv = E.inverse();
    const Mat3 F_inv = F.inverse();
    const Mat3 cov_f = F_inv * result.noise_acc.cwiseAbs2().asDiagonal() * F_inv.transpose();
    for (std::size_t k = 0; k < motions.size(); ++k) {
      for (std::size_t i = 0; i < output_rate[k].size(); ++i) {
        motion_samples[k].alpha_b[i] = E_inv * output_rate[k][i];
      }
    }
    const Mat3 cov_rate = E_inv * result.noise_gyr.cwiseAbs2().asDiagonal() * E_inv.transpose();
    for (std::size_t k = 0; k < motions.size(); ++k) {
      const auto& mo = motions[k];
      const double steps = static_cast<double>(mo.last - mo.first);
      const double dt = (series.t_s[mo.last] - series.t_s[mo.first]) / std::max(1.0, steps);
      for (int i = 0; i < 3; ++i) {
        const double sigma_rate = std::sqrt(cov_rate(i, i));  // rad/s per sample
        motion_samples[k].sqrt_info[i] =
            1.0 / (sigma_rate * dt * std::sqrt(std::max(1.0, steps) * tau_gyr[i]));
      }
      // Velocity: accelerometer noise summed over the steps, and gravity tilted by the
      // attitude random walk of the gyroscope noise (mean over the axes), which moves the
      // velocity only across gravity: d, the direction of gravity in the body at the start.
      const double n = std::max(1.0, steps);
      const double var_w = cov_rate.trace() / 3.0 * tau_gyr.mean();
      const Vec3 d = down_of(still[mo.from]);
      for (int i = 0; i < 3; ++i) {
        const double across = std::max(0.0, 1.0 - d[i] * d[i]);
        const double var_v = cov_f(i, i) * tau_acc[i] * dt * dt * n +
                             across * g * g * var_w * dt * dt * dt * dt * n * n * n / 3.0;
        velocity_info[k][i] = 1.0 / std::sqrt(var_v);
      }
    }
  };
  set_motion_weights(Mat3::Identity() / gyro_scale, Mat3::Identity() * acc_guess.scale);

  std::vector<std::unique_ptr<ceres::Manifold>> manifolds;
  // `free_probes`: the probe terms' blocks are left free (for their Jacobian columns only).
  auto build = [&](const std::vector<std::pair<int, int>>& held_extra, bool free_probes = false) {
    BuiltProblem built;
    built.problem = std::make_unique<ceres::Problem>([] {
      ceres::Problem::Options o;
      o.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
      return o;
    }());
    ceres::Problem* problem = built.problem.get();
    for (int t = 0; t < model.num_terms(); ++t) {
      auto& block = theta[static_cast<std::size_t>(t)];
      const auto& fixed = model.terms()[static_cast<std::size_t>(t)].fixed;
      problem->AddParameterBlock(block.data(), static_cast<int>(block.size()));
      if (free_probes && model.terms()[static_cast<std::size_t>(t)].probe) continue;
      std::vector<int> held;
      for (std::size_t i = 0; i < fixed.size(); ++i) {
        const bool extra = std::find(held_extra.begin(), held_extra.end(),
                                     std::make_pair(t, static_cast<int>(i))) != held_extra.end();
        if (fixed[i] || extra) held.push_back(static_cast<int>(i));
      }
      if (held.size() == block.size()) {
        problem->SetParameterBlockConstant(block.data());
      } else if (!held.empty()) {
        manifolds.push_back(std::make_unique<ceres::SubsetManifold>(static_cast<int>(block.size()), held));
        problem->SetManifold(block.data(), manifolds.back().get());
      }
    }
    for (auto& s : still) {
      problem->AddParameterBlock(s.q.data(), 4);
      if (s.known) {
        problem->SetParameterBlockConstant(s.q.data());
      } else {
        manifolds.push_back(s.heading_only ? residuals::HeadingManifold()
                            : s.chain_head ? residuals::TiltManifold()
                                           : residuals::AttitudeManifold());
        problem->SetManifold(s.q.data(), manifolds.back().get());
      }
    }
    auto blocks_of = [&](const std::vector<int>& terms, double* q) {
      std::vector<double*> blocks = {q};
      for (int t : terms) blocks.push_back(theta[static_cast<std::size_t>(t)].data());
      return blocks;
    };
    for (auto& s : still) {
      built.acc.push_back(
          s.spinning ? nullptr
                     : problem->AddResidualBlock(
                           StillResidual::Create(model, model::Sensor::kAccel, s.acc_measurement,
                                                 site.g_n, site.omega_ie_n),
                           nullptr, blocks_of(acc_terms, s.q.data())));
      built.gyr.push_back(
          still_gyro ? problem->AddResidualBlock(
                           StillResidual::Create(model, model::Sensor::kGyro, s.gyr_measurement,
                                                 site.g_n, site.omega_ie_n,
                                                 s.segment.known_omega_eb_b.value_or(Vec3::Zero())),
                           nullptr, blocks_of(gyr_terms, s.q.data()))
                     : nullptr);
    }
    for (std::size_t k = 0; k < motions.size(); ++k) {
      const auto& mo = motions[k];
      std::vector<double*> blocks = {still[mo.from].q.data(), still[mo.from + 1].q.data()};
      for (auto& b : theta) blocks.push_back(b.data());
      built.motion.push_back(problem->AddResidualBlock(
          MotionResidual::Create(model, motion_samples[k], site.omega_ie_n), nullptr, blocks));
      if (velocity_on) {
        std::vector<double*> vblocks = {still[mo.from].q.data()};
        for (auto& b : theta) vblocks.push_back(b.data());
        built.velocity.push_back(problem->AddResidualBlock(
            residuals::VelocityResidual::Create(model, motion_samples[k], site.g_n,
                                                site.omega_ie_n, velocity_info[k]),
            nullptr, vblocks));
      }
    }
    return built;
  };

  // `rough`: a first solve that another will refine (looser tolerances, fewer iterations).
  auto solve = [&](ceres::Problem& problem, bool rough) {
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_QR;
    solver_options.max_num_iterations = options.max_iterations;
    solver_options.function_tolerance = rough ? 1e-6 : options.function_tolerance;
    solver_options.parameter_tolerance = rough ? 1e-8 : options.parameter_tolerance;
    solver_options.gradient_tolerance = 1e-14;
    solver_options.num_threads = 1;
    solver_options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    result.fit.solver_report = summary.BriefReport();
    result.fit.iterations += static_cast<int>(summary.iterations.size());
    result.fit.converged = summary.termination_type == ceres::CONVERGENCE;
    if (!summary.IsSolutionUsable()) throw Error("the solver failed: " + summary.BriefReport());
  };

  // Jacobian over every free unknown (model parameters, then attitudes) and its analysis.
  std::vector<std::pair<int, int>> model_index;  // per column: (term, index) or (-1, still)
  std::vector<double*> free_blocks;              // of the last analysis, in column order
  std::vector<std::string> names;
  std::vector<bool> is_model;
  auto analyse = [&](ceres::Problem& problem, double* cost, std::vector<double>* residual_values) {
    std::vector<double> values;
    free_blocks.clear();
    names.clear();
    is_model.clear();
    model_index.clear();
    for (int t = 0; t < model.num_terms(); ++t) {
      auto& block = theta[static_cast<std::size_t>(t)];
      if (problem.IsParameterBlockConstant(block.data())) continue;
      free_blocks.push_back(block.data());
      const auto& term = model.terms()[static_cast<std::size_t>(t)];
      const auto& info = term.effect->info();
      for (int i = 0; i < info.size(); ++i) {
        if (term.fixed[static_cast<std::size_t>(i)]) continue;
        names.push_back(info.ParameterName(i));
        values.push_back(info.parameters[static_cast<std::size_t>(i)].nominal + block[static_cast<std::size_t>(i)]);
        is_model.push_back(true);
        model_index.emplace_back(t, i);
      }
    }
    const char* kTangentName[3] = {"north", "east", "down"};
    for (std::size_t k = 0; k < still.size(); ++k) {
      if (still[k].known) continue;
      free_blocks.push_back(still[k].q.data());
      const int first = still[k].heading_only ? 2 : 0;
      const int dims = still[k].heading_only ? 1 : still[k].chain_head ? 2 : 3;
      for (int i = first; i < first + dims; ++i) {
        names.push_back("attitude[" + std::to_string(k) + "]." + kTangentName[i]);
        values.push_back(std::nan(""));
        is_model.push_back(false);
        model_index.emplace_back(-1, static_cast<int>(k));
      }
    }
    ceres::Problem::EvaluateOptions eval;
    eval.parameter_blocks = free_blocks;
    ceres::CRSMatrix crs;
    problem.Evaluate(eval, cost, residual_values, nullptr, &crs);
    ObservabilityInput oin;
    oin.J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r) {
      for (int idx = crs.rows[static_cast<std::size_t>(r)]; idx < crs.rows[static_cast<std::size_t>(r) + 1]; ++idx) {
        oin.J(r, crs.cols[static_cast<std::size_t>(idx)]) = crs.values[static_cast<std::size_t>(idx)];
      }
    }
    oin.names = names;
    oin.values = values;
    oin.is_model = is_model;
    oin.rank_tolerance = options.rank_tolerance;
    return AnalyseObservability(oin);
  };

  // Solve. Where the data leaves directions unobservable, the solver could wander along them
  // (or exploit ones that are observable only at the level of rounding), so the fit is redone
  // from the starting values with one parameter per null direction (its row-echelon pivot,
  // e.g. accel.matrix.zz for "9.78 accel.bias.z + 1 accel.matrix.zz") held at its start value.
  const model::ParameterBlocks theta0 = theta;
  std::vector<std::array<double, 4>> q0;
  for (const auto& s : still) q0.push_back(s.q);
  std::vector<std::pair<int, int>> held;
  {
    const BuiltProblem first_build = build({});
    solve(*first_build.problem, result.has_gyro && !motions.empty());
    double cost0 = 0;
    const ObservabilityAnalysis first = analyse(*first_build.problem, &cost0, nullptr);
    for (int c : first.pivots) {
      if (model_index[static_cast<std::size_t>(c)].first >= 0) held.push_back(model_index[static_cast<std::size_t>(c)]);
    }
  }
  if (result.has_gyro && !motions.empty()) {
    const auto linear = model.Predict(theta, model::SensorInput<double>());
    set_motion_weights(linear.E, linear.F);
  }
  if (!held.empty()) {
    theta = theta0;
    for (std::size_t k = 0; k < still.size(); ++k) still[k].q = q0[k];
  }
  // The final problem: every free unknown, for the analysis and the residuals; with pivots
  // held (if any), for the fit and its covariance.
  const BuiltProblem final_build = build({});
  BuiltProblem held_build;
  if (!held.empty()) held_build = build(held);
  ceres::Problem& held_problem = held.empty() ? *final_build.problem : *held_build.problem;
  if (!held.empty() || (result.has_gyro && !motions.empty())) solve(held_problem, false);
  ceres::Problem& problem = *final_build.problem;
  double cost = 0;
  std::vector<double> residual_values;
  const ObservabilityAnalysis analysis = analyse(problem, &cost, &residual_values);
  result.observability = analysis.summary;

  // Parameters.
  const auto all_values = model::ReportedValues(model, theta);
  const auto num_params = static_cast<Eigen::Index>(all_values.size());
  result.covariance = Eigen::MatrixXd::Zero(num_params, num_params);
  std::vector<Eigen::Index> column_of(all_values.size(), -1);
  int flat = 0;
  for (int t = 0; t < model.num_terms(); ++t) {
    const auto& term = model.terms()[static_cast<std::size_t>(t)];
    const auto& info = term.effect->info();
    for (int i = 0; i < info.size(); ++i, ++flat) {
      ParameterEstimate p;
      p.name = info.ParameterName(i);
      p.unit = UnitOf(info, i, series);
      p.value = all_values[static_cast<std::size_t>(flat)];
      p.fixed = term.fixed[static_cast<std::size_t>(i)];
      const auto col = std::find(model_index.begin(), model_index.end(), std::make_pair(t, i));
      if (col != model_index.end()) {
        const auto c = col - model_index.begin();
        column_of[static_cast<std::size_t>(flat)] = c;
        p.observable = analysis.observable[static_cast<std::size_t>(c)];
      }
      result.parameters.push_back(p);
    }
  }
  // Covariance by ceres::Covariance on the problem with the pivots held, full rank by
  // construction. For every observable parameter and every determined combination (estimable
  // functions) the variance does not depend on which member of a null direction is held, so
  // it equals the analysis's pseudo-inverse (tests/estimation checks this); held pivots get
  // zero rows and columns. Should Ceres find the held problem singular, the pseudo-inverse is
  // used and a warning says so.
  std::vector<int> offset_of_term;
  for (int t = 0, off = 0; t < model.num_terms(); ++t) {
    offset_of_term.push_back(off);
    off += model.terms()[static_cast<std::size_t>(t)].effect->info().size();
  }
  bool ceres_covariance = false;
  {
    std::vector<const double*> blocks;
    std::vector<int> block_term;
    for (int t = 0; t < model.num_terms(); ++t) {
      const double* b = theta[static_cast<std::size_t>(t)].data();
      if (held_problem.IsParameterBlockConstant(b)) continue;
      blocks.push_back(b);
      block_term.push_back(t);
    }
    std::vector<std::pair<const double*, const double*>> pairs;
    for (std::size_t i = 0; i < blocks.size(); ++i) {
      for (std::size_t j = i; j < blocks.size(); ++j) pairs.emplace_back(blocks[i], blocks[j]);
    }
    ceres::Covariance::Options cov_options;
    cov_options.algorithm_type = ceres::DENSE_SVD;
    cov_options.num_threads = 1;
    ceres::Covariance covariance(cov_options);
    if (options.use_ceres_covariance && !pairs.empty() &&
        covariance.Compute(pairs, &held_problem)) {
      ceres_covariance = true;
      for (std::size_t i = 0; i < blocks.size(); ++i) {
        for (std::size_t j = i; j < blocks.size(); ++j) {
          const int ti = block_term[i], tj = block_term[j];
          const int ni = model.terms()[static_cast<std::size_t>(ti)].effect->info().size();
          const int nj = model.terms()[static_cast<std::size_t>(tj)].effect->info().size();
          Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> C(ni, nj);
          covariance.GetCovarianceBlock(blocks[i], blocks[j], C.data());
          result.covariance.block(offset_of_term[static_cast<std::size_t>(ti)],
                                  offset_of_term[static_cast<std::size_t>(tj)], ni, nj) = C;
          result.covariance.block(offset_of_term[static_cast<std::size_t>(tj)],
                                  offset_of_term[static_cast<std::size_t>(ti)], nj, ni) = C.transpose();
        }
      }
    }
  }
  if (!ceres_covariance) {
    if (options.use_ceres_covariance && model.num_free_parameters() > 0) {
      result.warnings.push_back("ceres::Covariance found the problem singular; sigmas are from "
                                "the pseudo-inverse of the column-scaled Jacobian");
    }
    for (Eigen::Index a = 0; a < num_params; ++a) {
      for (Eigen::Index b = 0; b < num_params; ++b) {
        const auto ca = column_of[static_cast<std::size_t>(a)], cb = column_of[static_cast<std::size_t>(b)];
        if (ca >= 0 && cb >= 0) result.covariance(a, b) = analysis.covariance(ca, cb);
      }
    }
  }
  for (std::size_t i = 0; i < result.parameters.size(); ++i) {
    auto& p = result.parameters[i];
    const auto ii = static_cast<Eigen::Index>(i);
    p.sigma = (p.observable && !p.fixed) ? std::sqrt(std::max(0.0, result.covariance(ii, ii)))
                                         : std::numeric_limits<double>::quiet_NaN();
  }
  result.sigma_source = ceres_covariance ? "ceres::Covariance (DENSE_SVD)" : "pseudo-inverse";

  // Forward quantities.
  {
    const auto out = model.Predict(theta, model::SensorInput<double>());
    result.accel_matrix = out.F;
    const auto& a = theta[static_cast<std::size_t>(t_acc)];
    result.accel_bias = Vec3(a[6], a[7], a[8]);
    if (result.has_gyro) {
      result.gyro_matrix = out.E;
      const auto& b = theta[static_cast<std::size_t>(t_gyr)];
      result.gyro_bias = Vec3(b[9], b[10], b[11]);
    }
  }

  // Residuals per segment and fit summary.
  FitSummary& fit = result.fit;
  fit.chi2 = 2.0 * cost;
  fit.num_residuals = static_cast<int>(residual_values.size());
  fit.dof = fit.num_residuals - analysis.summary.rank;
  fit.still_segments = static_cast<int>(still.size());
  fit.motion_segments = static_cast<int>(motions.size());
  Vec3 ss_acc = Vec3::Zero(), ss_gyr = Vec3::Zero(), ss_mot = Vec3::Zero(), ss_vel = Vec3::Zero();
  for (std::size_t k = 0; k < still.size(); ++k) {
    const Still& s = still[k];
    StillSegmentFit f;
    f.segment = s.segment;
    f.t_mid_s = s.stats.t_mid_s;
    f.count = s.stats.count;
    f.acc_mean = s.stats.acc_mean;
    if (result.has_gyro) f.gyr_mean = s.stats.gyr_mean;
    f.R_n_b = ToQuat(s.q);
    f.attitude_known = s.known;
    // Residuals are measured minus predicted, whitened by sqrt_info: unwhiten to report them.
    double w[3];
    if (final_build.acc[k]) {
      problem.EvaluateResidualBlock(final_build.acc[k], false, nullptr, w, nullptr);
      f.acc_whitened = Vec3(w[0], w[1], w[2]);
      f.acc_residual = f.acc_whitened.cwiseQuotient(s.acc_measurement.sqrt_info);
      ss_acc += f.acc_residual.cwiseAbs2();
    }
    if (final_build.gyr[k]) {
      problem.EvaluateResidualBlock(final_build.gyr[k], false, nullptr, w, nullptr);
      f.gyr_whitened = Vec3(w[0], w[1], w[2]);
      f.gyr_residual = f.gyr_whitened.cwiseQuotient(s.gyr_measurement.sqrt_info);
      ss_gyr += f.gyr_residual.cwiseAbs2();
    }
    result.still.push_back(f);
  }
  for (std::size_t k = 0; k < motions.size(); ++k) {
    const Motion& mo = motions[k];
    MotionFit f;
    f.from = mo.from;
    f.to = mo.from + 1;
    f.duration_s = series.t_s[mo.last] - series.t_s[mo.first];
    double w[3];
    problem.EvaluateResidualBlock(final_build.motion[k], false, nullptr, w, nullptr);
    f.whitened = Vec3(w[0], w[1], w[2]);
    f.rotation_residual = f.whitened.cwiseQuotient(motion_samples[k].sqrt_info);
    ss_mot += f.rotation_residual.cwiseAbs2();
    if (k < final_build.velocity.size()) {
      problem.EvaluateResidualBlock(final_build.velocity[k], false, nullptr, w, nullptr);
      f.has_velocity = true;
      f.velocity_whitened = Vec3(w[0], w[1], w[2]);
      f.velocity_residual = f.velocity_whitened.cwiseQuotient(velocity_info[k]);
      ss_vel += f.velocity_residual.cwiseAbs2();
    }
    result.motion.push_back(f);
  }
  const double ns = static_cast<double>(still.size());
  fit.rms_acc = (ss_acc / static_cast<double>(AtRestMeans(still, false).size())).cwiseSqrt();
  if (still_gyro) fit.rms_gyr = (ss_gyr / ns).cwiseSqrt();
  if (!motions.empty()) fit.rms_motion = (ss_mot / static_cast<double>(motions.size())).cwiseSqrt();
  fit.velocity_segments = static_cast<int>(final_build.velocity.size());
  if (fit.velocity_segments > 0) {
    fit.rms_velocity = (ss_vel / static_cast<double>(fit.velocity_segments)).cwiseSqrt();
  }

  // What the data cannot determine, and what to record.
  const int orientations = CountDistinctOrientations(AtRestMeans(still, false));
  bool accel_short = false, gyro_short = false;
  std::vector<std::string> lost;
  for (const auto& p : result.parameters) {
    if (p.fixed || p.observable) continue;
    lost.push_back(p.name);
    accel_short = accel_short || p.name.rfind("accel.", 0) == 0;
    gyro_short = gyro_short || p.name.rfind("gyro.", 0) == 0;
  }
  std::vector<std::string> advice;
  if (accel_short) {
    advice.push_back("the base accelerometer model needs still poses in at least 9 distinct "
                     "orientations (fewer when attitudes are known); found " +
                     std::to_string(orientations));
  }
  if (gyro_short) {
    advice.push_back("the gyroscope matrix needs turns about three independent axes between still "
                     "poses; found " + std::to_string(motions.size()) + " motion intervals" +
                     (result.has_gyro && !site.known ? " (and no site: Earth rate unused)" : ""));
  }
  if (!lost.empty()) {
    std::string list;
    for (const auto& name : lost) list += (list.empty() ? "" : ", ") + name;
    std::string message = "the data cannot determine " + list;
    for (const auto& a : advice) message += "; " + a;
    if (options.on_insufficient == InsufficientData::kError) throw InsufficientDataError(message);
    result.warnings.push_back(message);
  }
  if (!site.known) {
    result.warnings.push_back(
        "no site given: gravity fixed at " + std::to_string(g) + " m/s^2" +
        (result.has_gyro ? " and Earth rate left out; the accelerometer scale and the gyroscope "
                           "bias depend on it"
                         : "; the accelerometer scale depends on it") +
        " (give --lat --lon --height)");
  }
  const bool any_known = std::any_of(still.begin(), still.end(), [](const Still& s) { return s.known || s.heading_only; });
  if (site.known && result.has_gyro && !any_known && !options.first_heading_deg) {
    result.warnings.push_back(
        "the heading of the first still pose is held at 0 (x north) as the gauge; with a site, "
        "Earth rate (" + std::to_string(site.omega_ie_n.head<2>().norm()) +
        " rad/s horizontal) is predicted for that heading: state it (--heading DEG or "
        "--level-north) or the gyroscope biases absorb up to that much");
  }
  if (model.has_probes()) {
    result.probes = ProbeColumns(model, theta, build({}, true), free_blocks, names, is_model);
  }
  result.model = model;
  result.theta = theta;
  return result;
}

}  // namespace plumb::estimation

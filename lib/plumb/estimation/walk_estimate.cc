#include "plumb/estimation/walk_estimate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "plumb/core/option_name.h"
#include "plumb/core/typical_mems.h"
#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/solve.h"

namespace plumb::estimation {
namespace {

/// An estimated walk this many times the typical one is the gate implausible_walk.
constexpr double kImplausibleWalk = 10.0;
/// Smallest level kept, as a fraction of the typical one.
constexpr double kFloor = 1e-3;
/// Relative change of the level below which the iteration stops (the estimate's own spread,
/// sqrt(2 / redundancy), is 20-50% for sessions of 10-50 poses), and the most fits made.
constexpr double kTolerance = 0.05;
constexpr int kMaxIterations = 8;
/// Fewest redundant wander factors for an estimate: below, its scatter is so wide that the
/// variance marginalised over it (red / (red - 2) times the estimate) would be three times the
/// estimate and more: a handful of factors say little about a level.
constexpr double kMinRedundancy = 3.0;
/// Fewest redundant factors for a step of the iteration (Helmert's ratio needs some).
constexpr double kMinIterate = 2.0;

/// One sensor's wander as this stage scales it: both processes by one factor on the
/// standard deviation, each axis between the floor and the still data's bound.
struct SensorWander {
  model::Sensor sensor;
  const char* name;
  Vec3* walk;
  Vec3* instability;
  std::array<LevelSource, 3>* walk_from;
  std::array<LevelSource, 3>* instability_from;
  bool walk_free, instability_free;  ///< not given in the options
  Vec3 walk_bound, instability_bound;
  double walk_typical, instability_typical;  ///< in the sensor's units
  Vec3 walk0 = Vec3::Zero(), instability0 = Vec3::Zero();  ///< stage 2a's levels
  bool chosen = false;  ///< estimated here
  bool pooled = false;  ///< scaled as the whole IMU's wander (its own factors absorbed)
  double scale = 1.0;   ///< on stage 2a's standard deviations, as used
  double reads = 1.0;   ///< the last Helmert ratio
  double chi2 = 0.0, redundancy = 0.0;  ///< of its group at the last fit

  /// The levels moved from stage 2a's by the estimate.
  bool Estimated() const { return scale != 1.0; }
  /// The variance marginalised over the estimate's scatter (file comment): the scale times
  /// sqrt(red / (red - 2)), an estimate below stage 2a's level never lifted above it. Where
  /// the factors are too few: a level the iteration lowered stays (the factors of so small a
  /// wander are absorbed, and every higher level the data showed too high), any other goes
  /// back to stage 2a's. Returns the factor applied.
  double Marginalise() {
    if (redundancy < kMinRedundancy && scale < 1.0 && reads < 1.0) return 1.0;
    if (redundancy < kMinRedundancy) {
      Apply(1.0);
      return 1.0;
    }
    const double marginal = std::sqrt(redundancy / (redundancy - 2.0));
    const double target = scale >= 1.0 ? scale * marginal : std::min(scale * marginal, 1.0);
    const double applied = target / scale;
    Apply(target);
    return applied;
  }

  bool Scales(WanderProcess::Kind kind) const {
    return kind == WanderProcess::Kind::kWalk ? walk_free : instability_free;
  }
  /// Sets the levels for `s` (stage 2a's times s, within floor and bound); returns the
  /// largest relative change of a level.
  double Apply(double s) {
    scale = s;
    double change = 0.0;
    auto set = [&](Vec3& level, const Vec3& start, const Vec3& bound, double typical) {
      for (int i = 0; i < 3; ++i) {
        const double next = std::clamp(start[i] * s, kFloor * typical, std::max(bound[i], kFloor * typical));
        change = std::max(change, std::abs(next / level[i] - 1.0));
        level[i] = next;
      }
    };
    if (walk_free) set(*walk, walk0, walk_bound, walk_typical);
    if (instability_free) set(*instability, instability0, instability_bound, instability_typical);
    return change;
  }
};

/// r^T r and redundancy of each chosen sensor's wander factors at the current solution.
void GroupStats(CalibrationProblem& problem, BuiltProblem& built,
                const CalibrationOptions& options, std::array<SensorWander, 2>& sensors) {
  // Rows of the wander factors: the last 3 * built.walk.size() rows (added last, in the
  // order of built.walk_process).
  const auto rows = static_cast<Eigen::Index>(built.problem->NumResiduals());
  const auto wander_rows = static_cast<Eigen::Index>(3 * built.walk.size());
  const auto& processes = problem.WanderProcesses();
  std::vector<Eigen::Index> group_rows;
  std::vector<std::size_t> owner;
  for (Eigen::Index i = rows - wander_rows; i < rows; ++i) {
    const WanderProcess& w =
        processes[built.walk_process[static_cast<std::size_t>((i - (rows - wander_rows)) / 3)]];
    for (std::size_t k = 0; k < sensors.size(); ++k) {
      if (sensors[k].chosen && sensors[k].sensor == w.sensor && sensors[k].Scales(w.kind)) {
        group_rows.push_back(i);
        owner.push_back(k);
      }
    }
  }
  for (SensorWander& s : sensors) s.chi2 = s.redundancy = 0.0;
  if (group_rows.empty()) return;
  std::vector<double> r;
  const Eigen::VectorXd h = Leverages(problem, *built.problem, options, group_rows, &r);
  for (std::size_t k = 0; k < group_rows.size(); ++k) {
    const double rk = r[static_cast<std::size_t>(group_rows[k])];
    sensors[owner[k]].chi2 += rk * rk;
    sensors[owner[k]].redundancy += 1.0 - h[static_cast<Eigen::Index>(k)];
  }
}

/// Iteration step: each chosen sensor's scale by Helmert's ratio, from its own factors where
/// they are redundant enough, else from the whole IMU's (both sensors' factors). Returns the
/// largest relative change of a level.
double Rescale(std::array<SensorWander, 2>& sensors) {
  double chi2_all = 0.0, red_all = 0.0;
  for (const SensorWander& s : sensors) {
    if (!s.chosen) continue;
    chi2_all += s.chi2;
    red_all += s.redundancy;
  }
  double change = 0.0;
  for (SensorWander& s : sensors) {
    if (!s.chosen) continue;
    s.pooled = s.redundancy <= kMinIterate;
    if (s.pooled) {
      s.chi2 = chi2_all;
      s.redundancy = red_all;
    }
    if (s.redundancy <= kMinIterate) continue;
    const double next = s.scale * std::sqrt(s.chi2 / s.redundancy);
    s.reads = next;
    change = std::max(change, s.Apply(next));
  }
  return change;
}

std::string Describe(const SensorWander& s, double marginal) {
  char text[480];
  const char* whose = s.pooled ? " (as the whole IMU's: its own factors are absorbed)" : "";
  if (!s.Estimated()) {
    std::snprintf(text, sizeof text, "%s kept (its wander factors are absorbed by the fit: %.1f "
                  "redundant, at least %.0f needed)", s.name, s.redundancy, kMinRedundancy);
  } else {
    std::snprintf(text, sizeof text, "%s x %.3g the levels above%s (%.1f redundant wander "
                  "factors; x %.3g of it for the estimate's own scatter): walk %.2g, "
                  "instability %.2g", s.name, s.scale, whose, s.redundancy, marginal,
                  s.walk->maxCoeff(), s.instability->maxCoeff());
  }
  return text;
}

}  // namespace

WalkEstimate ResolveWander(const ImuSeries& series, const model::Model& model,
                           const geo::Site& site, const StillSet& still,
                           const model::ParameterBlocks& theta, const WanderLevels& levels,
                           const StartingValues& start, const CalibrationOptions& options) {
  WalkEstimate out;
  out.noise = levels.noise;
  NoiseModel& n = out.noise;
  const double acc_scale = start.accel.scale, gyr_scale = 1.0 / start.gyro_rad_per_unit;
  std::array<SensorWander, 2> sensors{{
      {model::Sensor::kAccel, "accel", &n.walk_acc, &n.instability_acc, &n.from.walk_acc,
       &n.from.instability_acc, !options.accel_walk_density.has_value(),
       !options.accel_instability.has_value(), levels.bounds.walk_acc,
       levels.bounds.instability_acc, typical_mems::kAccelWalk * acc_scale,
       typical_mems::kAccelInstability * acc_scale},
      {model::Sensor::kGyro, "gyro", &n.walk_gyr, &n.instability_gyr, &n.from.walk_gyr,
       &n.from.instability_gyr, !options.gyro_walk_density.has_value(),
       !options.gyro_instability.has_value(), levels.bounds.walk_gyr,
       levels.bounds.instability_gyr, typical_mems::kGyroWalk * gyr_scale,
       typical_mems::kGyroInstability * gyr_scale},
  }};
  bool any = false;
  for (SensorWander& s : sensors) {
    if (s.sensor == model::Sensor::kGyro && !model.has_gyro()) continue;
    s.walk0 = *s.walk;
    s.instability0 = *s.instability;
    s.chosen = options.estimate_walk && (s.walk_free || s.instability_free);
    any = any || s.chosen;
  }
  if (!any) return out;
  if (static_cast<int>(still.poses.size()) < options.walk_min_poses) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "bias random walk not estimated (%zu still segments, at least %d are needed to "
                  "see it): the level from the still data or the typical MEMS sensor kept",
                  still.poses.size(), options.walk_min_poses);
    out.warnings.push_back(Notice{"walk_not_estimated", text, {}});
    return out;
  }
  for (int it = 0; it < kMaxIterations; ++it) {
    CalibrationProblem problem(series, model, site, still, theta, out.noise, start, options);
    FitReport scratch;
    Solution solution = SolveWithGauge(problem, options, scratch);
    GroupStats(problem, solution.all_free, options, sensors);
    ++out.iterations;
    if (Rescale(sensors) < kTolerance) break;
  }
  std::string note = "bias wander from the session (variance components over its wander "
                     "factors, " + std::to_string(out.iterations) + " fits):";
  for (SensorWander& s : sensors) {
    if (!s.chosen) continue;
    const double marginal = s.Marginalise();
    if (s.Estimated()) {
      if (s.walk_free) s.walk_from->fill(LevelSource::kEstimated);
      if (s.instability_free) s.instability_from->fill(LevelSource::kEstimated);
    }
    note += std::string(note.back() == ':' ? " " : "; ") + Describe(s, marginal);
  }
  AddNotice(out.notes, "walk_estimated", note);
  // A walk far above any MEMS sensor's is more likely a missing effect seen between the poses.
  for (const SensorWander& s : sensors) {
    if (!s.chosen || !s.Estimated() || !s.walk_free) continue;
    const double ratio = s.walk->maxCoeff() / s.walk_typical;
    if (ratio <= kImplausibleWalk) continue;
    char text[640];
    std::snprintf(text, sizeof text,
                  "%sthe estimated %s walk is %.0f times the typical MEMS walk: the differences "
                  "between poses it was read from are more likely an effect the model misses "
                  "than a walk, and a walk that large hides it from chi2; run 'plumb diagnose' "
                  "(without %s) or give the walk (%s/%s)",
                  out.implausible.empty() ? "" : "; ",
                  s.sensor == model::Sensor::kAccel ? "accelerometer" : "gyroscope", ratio,
                  OptionText(Option::kEstimateWalk).c_str(), OptionText(Option::kAccelWalk).c_str(),
                  OptionText(Option::kGyroWalk).c_str());
    out.implausible += text;
  }
  return out;
}

}  // namespace plumb::estimation

#include "plumb/estimation/walk_estimate.h"

#include <cmath>
#include <cstdio>
#include <tuple>

#include "plumb/core/typical_mems.h"
#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/solve.h"

namespace plumb::estimation {
namespace {

/// An estimated walk this many times the typical one draws a warning.
constexpr double kImplausibleWalk = 10.0;
/// Smallest density kept, as a fraction of the start.
constexpr double kFloor = 1e-3;
/// Relative change of K below which the iteration stops (the estimate's own spread,
/// sqrt(2 / redundancy), is 20-50% for sessions of 10-50 poses), and the most fits made.
constexpr double kTolerance = 0.05;
constexpr int kMaxIterations = 8;

/// r^T r and redundancy of the walk factors of each sensor at the current solution.
struct GroupStats {
  double chi2_acc = 0, red_acc = 0, chi2_gyr = 0, red_gyr = 0;
};

GroupStats WalkGroups(CalibrationProblem& problem, BuiltProblem& built,
                      const CalibrationOptions& options) {
  // Rows of the wander factors: the last 3 * built.walk.size() rows (added last, in the
  // order of built.walk_process). Only the walks' factors form the groups.
  const auto rows = static_cast<Eigen::Index>(built.problem->NumResiduals());
  const auto walk_rows = static_cast<Eigen::Index>(3 * built.walk.size());
  const auto& processes = problem.WanderProcesses();
  std::vector<Eigen::Index> group_rows;
  std::vector<bool> acc;
  for (Eigen::Index i = rows - walk_rows; i < rows; ++i) {
    const WanderProcess& w =
        processes[built.walk_process[static_cast<std::size_t>((i - (rows - walk_rows)) / 3)]];
    if (w.kind != WanderProcess::Kind::kWalk) continue;
    group_rows.push_back(i);
    acc.push_back(w.sensor == model::Sensor::kAccel);
  }
  std::vector<double> r;
  const Eigen::VectorXd h = Leverages(problem, *built.problem, options, group_rows, &r);
  GroupStats g;
  for (std::size_t k = 0; k < group_rows.size(); ++k) {
    const double r2 = r[static_cast<std::size_t>(group_rows[k])] * r[static_cast<std::size_t>(group_rows[k])];
    (acc[k] ? g.chi2_acc : g.chi2_gyr) += r2;
    (acc[k] ? g.red_acc : g.red_gyr) += 1.0 - h[static_cast<Eigen::Index>(k)];
  }
  return g;
}

}  // namespace

WalkEstimate ResolveWander(const ImuSeries& series, const model::Model& model,
                           const geo::Site& site, const StillSet& still,
                           const model::ParameterBlocks& theta, const NoiseModel& noise,
                           const StartingValues& start, const CalibrationOptions& options) {
  WalkEstimate out;
  out.noise = noise;
  const bool has_gyro = model.has_gyro();
  // The walks not given are estimated, starting from the levels of stage 2a (wander_levels.h).
  const double acc0 = typical_mems::kAccelWalk * start.accel.scale;
  const double gyr0 = typical_mems::kGyroWalk / start.gyro_rad_per_unit;
  const bool free_acc = !options.accel_walk_density.has_value();
  const bool free_gyr = has_gyro && !options.gyro_walk_density.has_value();
  if (!options.estimate_walk || (!free_acc && !free_gyr)) return out;
  if (static_cast<int>(still.poses.size()) < options.walk_min_poses) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "bias random walk not estimated (%zu still segments, at least %d are needed to "
                  "see it): the level from the still data or the typical MEMS sensor kept",
                  still.poses.size(), options.walk_min_poses);
    out.warnings.emplace_back(text);
    return out;
  }
  bool learnt_acc = false, learnt_gyr = false;
  for (int it = 0; it < kMaxIterations; ++it) {
    CalibrationProblem problem(series, model, site, still, theta, out.noise, start, options);
    FitReport scratch;
    Solution solution = SolveWithGauge(problem, options, scratch);
    const GroupStats g = WalkGroups(problem, solution.all_free, options);
    ++out.iterations;
    out.redundancy_acc = g.red_acc;
    out.redundancy_gyr = g.red_gyr;
    double change = 0;
    auto scale = [&](Vec3& K, double chi2, double red, double k0, bool& learnt) {
      if (red <= 1.0) return;  // the factors are absorbed: nothing to learn from them
      learnt = true;
      const double next = std::max(K.maxCoeff() * std::sqrt(chi2 / red), kFloor * k0);
      change = std::max(change, std::abs(next / K.maxCoeff() - 1.0));
      K.setConstant(next);
    };
    if (free_acc) scale(out.noise.walk_acc, g.chi2_acc, g.red_acc, acc0, learnt_acc);
    if (free_gyr) scale(out.noise.walk_gyr, g.chi2_gyr, g.red_gyr, gyr0, learnt_gyr);
    if (change < kTolerance) break;
  }
  // Per sensor: estimated, or (its walk factors fully absorbed by the other unknowns, e.g.
  // holds not joined by turns) the level of stage 2a kept.
  if (learnt_acc) out.noise.from.walk_acc.fill(LevelSource::kEstimated);
  if (learnt_gyr) out.noise.from.walk_gyr.fill(LevelSource::kEstimated);
  auto describe = [](const char* sensor, double K, double red, bool learnt) {
    char text[160];
    std::snprintf(text, sizeof text, learnt ? "%s %.3g (from %.1f redundant walk factors)"
                                            : "%s %.3g (kept: its walk factors are absorbed by "
                                              "the fit, %.1f redundant)",
                  sensor, K, red);
    return std::string(text);
  };
  std::string note = "bias random walk from the session (variance components, " +
                     std::to_string(out.iterations) + " fits), sensor units/s/sqrt(Hz):";
  if (free_acc) note += " " + describe("accel", out.noise.walk_acc[0], out.redundancy_acc, learnt_acc);
  if (free_gyr) {
    note += std::string(free_acc ? "," : "") + " " +
            describe("gyro", out.noise.walk_gyr[0], out.redundancy_gyr, learnt_gyr);
  }
  out.notes.push_back(note);
  // A walk far above any MEMS sensor's is more likely a missing effect seen between the poses.
  for (const auto& [name, K, K0, free] : {std::tuple{"accelerometer", out.noise.walk_acc[0], acc0, free_acc},
                                           std::tuple{"gyroscope", out.noise.walk_gyr[0], gyr0, free_gyr}}) {
    if (!free || K <= kImplausibleWalk * K0) continue;
    char text[360];
    std::snprintf(text, sizeof text,
                  "%sthe estimated %s walk is %.0f times the typical MEMS walk: the differences "
                  "between poses it was read from are more likely an effect the model misses "
                  "than a walk, and a walk that large hides it from chi2; run 'plumb diagnose' "
                  "(without --estimate-rw) or give the walk (--accel-rw/--gyro-rw)",
                  out.implausible.empty() ? "" : "; ", name, K / K0);
    out.implausible += text;
  }
  return out;
}

}  // namespace plumb::estimation

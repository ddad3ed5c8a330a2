#include "plumb/estimation/walk_estimate.h"

#include <cmath>
#include <cstdio>

#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/solve.h"

namespace plumb::estimation {
namespace {

/// Typical consumer MEMS bias walks (the simulator's TypicalMems), SI.
constexpr double kTypicalAccelWalk = 1e-4;   // m/s^3/sqrt(Hz)
constexpr double kTypicalGyroWalk = 2e-6;    // rad/s^2/sqrt(Hz)
/// Smallest density kept, as a fraction of the start.
constexpr double kFloor = 1e-3;
/// Relative change of K below which the iteration stops, and the most fits made.
constexpr double kTolerance = 0.02;
constexpr int kMaxIterations = 8;

/// r^T r and redundancy of the walk factors of each sensor at the current solution.
struct GroupStats {
  double chi2_acc = 0, red_acc = 0, chi2_gyr = 0, red_gyr = 0;
};

GroupStats WalkGroups(CalibrationProblem& problem, BuiltProblem& built,
                      const CalibrationOptions& options, std::size_t acc_factors) {
  UnknownColumns columns;
  std::vector<double> r;
  double cost = 0;
  Eigen::MatrixXd J;
  const ObservabilityAnalysis analysis =
      AnalyseAt(problem, *built.problem, options, columns, &cost, &r, &J);
  // Rows of the walk factors: the last 3 * built.walk.size() rows (added last), the
  // accelerometer's first.
  const auto rows = static_cast<Eigen::Index>(r.size());
  const auto walk_rows = static_cast<Eigen::Index>(3 * built.walk.size());
  GroupStats g;
  for (Eigen::Index i = rows - walk_rows; i < rows; ++i) {
    const double h = J.row(i).dot(analysis.covariance * J.row(i).transpose());
    const bool acc = (i - (rows - walk_rows)) < static_cast<Eigen::Index>(3 * acc_factors);
    const double r2 = r[static_cast<std::size_t>(i)] * r[static_cast<std::size_t>(i)];
    (acc ? g.chi2_acc : g.chi2_gyr) += r2;
    (acc ? g.red_acc : g.red_gyr) += 1.0 - h;
  }
  return g;
}

}  // namespace

WalkEstimate EstimateWalk(const ImuSeries& series, const model::Model& model,
                          const geo::Site& site, const StillSet& still,
                          const model::ParameterBlocks& theta, const NoiseModel& noise,
                          const StartingValues& start, const CalibrationOptions& options) {
  WalkEstimate out;
  out.noise = noise;
  const bool has_gyro = model.has_gyro();
  if (static_cast<int>(still.poses.size()) < options.walk_min_poses) {
    out.note = "bias random walk not estimated: " + std::to_string(still.poses.size()) +
               " still segments, at least " + std::to_string(options.walk_min_poses) +
               " are needed to see it (give --accel-rw/--gyro-rw)";
    return out;
  }
  // Start from the typical walk in the sensor's units.
  const double acc0 = kTypicalAccelWalk * start.accel.scale;
  const double gyr0 = kTypicalGyroWalk / start.gyro_rad_per_unit;
  if (!noise.accel_walks()) out.noise.walk_acc = Vec3::Constant(acc0);
  if (has_gyro && !noise.gyro_walks()) out.noise.walk_gyr = Vec3::Constant(gyr0);
  bool learnt_acc = false, learnt_gyr = false;
  for (int it = 0; it < kMaxIterations; ++it) {
    CalibrationProblem problem(series, model, site, still, theta, out.noise, start, options);
    FitReport scratch;
    Solution solution = SolveWithGauge(problem, options, scratch);
    const std::size_t acc_factors = 2 * still.poses.size();
    const GroupStats g = WalkGroups(problem, solution.all_free, options, acc_factors);
    ++out.iterations;
    out.redundancy_acc = g.red_acc;
    out.redundancy_gyr = g.red_gyr;
    double change = 0;
    auto scale = [&](Vec3& K, double chi2, double red, double k0, bool& learnt) {
      if (red <= 1.0) return;  // the factors are absorbed: nothing to learn from them
      learnt = true;
      const double next = std::max(K[0] * std::sqrt(chi2 / red), kFloor * k0);
      change = std::max(change, std::abs(next / K[0] - 1.0));
      K.setConstant(next);
    };
    scale(out.noise.walk_acc, g.chi2_acc, g.red_acc, acc0, learnt_acc);
    if (has_gyro) scale(out.noise.walk_gyr, g.chi2_gyr, g.red_gyr, gyr0, learnt_gyr);
    if (change < kTolerance) break;
  }
  out.estimated = true;
  // Per sensor: estimated, or (its walk factors fully absorbed by the other unknowns, e.g.
  // holds not joined by turns) the typical MEMS walk kept.
  auto describe = [](const char* sensor, double K, double red, bool learnt) {
    char text[160];
    std::snprintf(text, sizeof text, learnt ? "%s %.3g (from %.1f redundant walk factors)"
                                            : "%s %.3g (the typical MEMS walk: its walk factors "
                                              "are absorbed by the fit, %.1f redundant)",
                  sensor, K, red);
    return std::string(text);
  };
  out.note = "bias random walk from the session (variance components, " +
             std::to_string(out.iterations) + " fits), sensor units/s/sqrt(Hz): " +
             describe("accel", out.noise.walk_acc[0], out.redundancy_acc, learnt_acc);
  if (has_gyro) {
    out.note += ", " + describe("gyro", out.noise.walk_gyr[0], out.redundancy_gyr, learnt_gyr);
  }
  return out;
}

}  // namespace plumb::estimation

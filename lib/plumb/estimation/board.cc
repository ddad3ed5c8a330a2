#include "plumb/estimation/board.h"

#include <ceres/cost_function.h>
#include <ceres/problem.h>

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>
#include <string>

#include "plumb/core/units.h"
#include "plumb/estimation/covariance.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/wander_levels.h"

namespace plumb::estimation {
namespace {

/// The rotation nearest (in the Frobenius norm) `m`.
Mat3 NearestRotation(const Mat3& m) {
  const Eigen::JacobiSVD<Mat3> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

/// The rotation among the 24 that map axes onto axes (a board's IMU mounted square to it)
/// nearest `R`: the one with the largest trace of P^T R.
Mat3 NearestRightAngleRotation(const Mat3& R) {
  Mat3 best = Mat3::Identity();
  double best_trace = -4.0;
  std::array<int, 3> axis = {0, 1, 2};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      Mat3 P = Mat3::Zero();
      for (int r = 0; r < 3; ++r) P(r, axis[r]) = (signs >> r & 1) != 0 ? -1.0 : 1.0;
      const double trace = (P.transpose() * R).trace();
      if (P.determinant() > 0 && trace > best_trace) {
        best = P;
        best_trace = trace;
      }
    }
  } while (std::next_permutation(axis.begin(), axis.end()));
  return best;
}

/// Still poses whose gravity directions lie within this angle of each other are one
/// orientation for the mount's start: 5 deg is a tilt an accelerometer's bias mimics (0.5 m/s^2
/// of bias, common before calibration, is 3 deg), so such poses say nothing of the tilt.
inline constexpr double kOneOrientationRad = 5.0 * units::kRadPerDeg;

/// Whether the poses of `still` see gravity from one orientation only (kOneOrientationRad).
bool OneOrientation(const StillSet& still) {
  for (const StillPose& a : still.poses) {
    for (const StillPose& b : still.poses) {
      const Vec3 down_a = a.R_n_b().conjugate() * Vec3::UnitZ();
      const Vec3 down_b = b.R_n_b().conjugate() * Vec3::UnitZ();
      if (std::acos(std::clamp(down_a.dot(down_b), -1.0, 1.0)) > kOneOrientationRad) return false;
    }
  }
  return true;
}

/// The starting R_b_i: the rotation nearest the mean of R_n_b(k)^T R_n_i(k) over the poses.
/// From one orientation that rotation is only the turn between the two accelerometers' gravity
/// directions, biases included, and the data cannot tell a mount from a bias: start (and,
/// where it stays undetermined, hold) at the nearest square mount, as a bias starts at 0.
Quat StartingMount(const StillSet& imu0, const StillSet& imu) {
  Mat3 sum = Mat3::Zero();
  for (std::size_t k = 0; k < imu0.poses.size(); ++k) {
    sum += (imu0.poses[k].R_n_b().conjugate() * imu.poses[k].R_n_b()).toRotationMatrix();
  }
  const Mat3 mean = NearestRotation(sum);
  return Quat(OneOrientation(imu0) ? NearestRightAngleRotation(mean) : mean).normalized();
}

/// Its noise model with the wander's levels assigned from its own still data.
NoiseModel BoardImuNoise(const BoardImu& imu, const StillSet& still, bool has_gyro,
                         const StartingValues& start, const CalibrationOptions& options,
                         FitReport& fit) {
  const std::string prefix = "imu" + std::to_string(imu.instance) + ": ";
  NoiseModel noise = EstimateNoise(imu.series, still, has_gyro, options);
  if (!options.ModelsWander()) return noise;
  std::vector<Notice> notes;
  const std::optional<signal::StillNoise> own =
      MeasureStillNoise(imu.series, still, options.instability_time_s, notes, options.run_jobs);
  std::vector<const signal::StillNoise*> measured;
  if (own) measured.push_back(&*own);
  WanderLevels levels = AssignWanderLevels(noise, measured, start, has_gyro,
                                           imu.series.duration_s(), options,
                                           static_cast<int>(still.poses.size()));
  notes.insert(notes.end(), levels.notes.begin(), levels.notes.end());
  for (Notice& n : notes) {
    n.message = prefix + n.message;
    fit.notes.push_back(std::move(n));
  }
  return levels.noise;
}

}  // namespace

std::vector<BoardImuInput> PrepareBoard(const std::vector<BoardImu>& board,
                                        const std::vector<model::Model>& models,
                                        const ImuSeries& series0, const StillSet& still0,
                                        const geo::Site& site, const CalibrationOptions& options,
                                        FitReport& fit) {
  std::vector<BoardImuInput> out;
  for (std::size_t k = 0; k < board.size(); ++k) {
    const BoardImu& imu = board[k];
    BoardImuInput in;
    in.instance = imu.instance;
    in.series = &imu.series;
    in.model = models.at(k);
    const bool has_gyro = in.model.has_gyro();
    in.still = StillSetOnBoardImu(still0, series0, imu.series, "imu" + std::to_string(imu.instance));
    in.theta = in.model.ZeroParameters();
    in.start = Initialize(imu.series, in.model, site.gravity(), has_gyro,
                          options.first_heading_deg, in.still, in.theta, options.run_jobs);
    in.R_b_i = StartingMount(still0, in.still);
    in.noise = BoardImuNoise(imu, in.still, has_gyro, in.start, options, fit);
    out.push_back(std::move(in));
  }
  return out;
}

namespace {

/// The column of the problem's parameter (t, i) among `columns`, or -1 when it is held.
Eigen::Index ColumnOf(const UnknownColumns& columns, int t, int i) {
  const auto& index = columns.model_index;
  const auto at = std::find(index.begin(), index.end(), std::make_pair(t, i));
  return at == index.end() ? -1 : static_cast<Eigen::Index>(at - index.begin());
}

/// IMU `imu` of the problem as calibrated; the columns of its parameters appended to `column_of`.
BoardImuCalibration ReportBoardImu(const CalibrationProblem& problem, std::size_t imu,
                                   const UnknownColumns& columns,
                                   const ObservabilityAnalysis& analysis,
                                   std::vector<Eigen::Index>& column_of) {
  const ProblemImu& u = problem.imus()[imu];
  BoardImuCalibration out;
  out.instance = u.instance;
  out.model = u.model;
  out.has_gyro = u.has_gyro;
  out.noise = u.noise.Levels();
  out.acc_unit = u.series->acc_unit;
  out.gyr_unit = u.series->gyr_unit;
  const std::vector<const double*> blocks = problem.TermBlocks(imu);
  for (int local = 0; local < u.num_terms(); ++local) {
    const model::EffectInfo& info = u.TermInfo(local);
    const double* block = blocks[static_cast<std::size_t>(local)];
    out.theta.emplace_back(block, block + info.size());
    const bool mount = local == u.model.num_terms();
    for (int i = 0; i < info.size(); ++i) {
      const model::ParameterInfo& p = info.parameters[static_cast<std::size_t>(i)];
      ParameterEstimate e;
      e.name = u.ParameterName(local, i);
      e.place = {local, i};
      e.unit = mount ? p.unit : ParameterUnit(u.model, e.place, *u.series);
      e.value = p.nominal + block[i];
      e.fixed = u.Fixed(local, i);
      const Eigen::Index c = ColumnOf(columns, u.first_term + local, i);
      column_of.push_back(c);
      e.observable = c >= 0 && analysis.observable[static_cast<std::size_t>(c)];
      if (c >= 0 && e.observable && !e.fixed) e.sigma = std::sqrt(analysis.covariance(c, c));
      out.parameters.push_back(std::move(e));
    }
  }
  return out;
}

}  // namespace

void ReportBoard(const CalibrationProblem& problem, const BuiltProblem& built,
                 const UnknownColumns& columns, const ObservabilityAnalysis& analysis,
                 const std::vector<Eigen::Index>& column_of, Calibration& calibration) {
  if (problem.imus().size() < 2) return;
  std::vector<Eigen::Index> all = column_of;
  for (std::size_t i = 1; i < problem.imus().size(); ++i) {
    BoardImuCalibration b = ReportBoardImu(problem, i, columns, analysis, all);
    for (const ceres::ResidualBlockId id : built.board[i - 1].turns) {
      double cost = 0.0;
      built.problem->EvaluateResidualBlock(id, false, &cost, nullptr, nullptr);
      b.turn_chi2 += 2.0 * cost;
      b.turn_residuals += built.problem->GetCostFunctionForResidualBlock(id)->num_residuals();
    }
    calibration.board.push_back(std::move(b));
  }
  const auto n = static_cast<Eigen::Index>(all.size());
  Eigen::MatrixXd& cov = calibration.board_covariance;
  cov = Eigen::MatrixXd::Zero(n, n);
  const auto determined = [&](Eigen::Index c) {
    return c >= 0 && analysis.observable[static_cast<std::size_t>(c)];
  };
  for (Eigen::Index a = 0; a < n; ++a) {
    for (Eigen::Index b = 0; b < n; ++b) {
      const Eigen::Index ca = all[static_cast<std::size_t>(a)], cb = all[static_cast<std::size_t>(b)];
      if (determined(ca) && determined(cb)) cov(a, b) = analysis.covariance(ca, cb);
    }
  }
  // Zero rows for fixed and unobservable parameters: an unobservable one's pseudo-inverse
  // values mean nothing (observability.determined says what the data fix of it), and would
  // make the matrix, written and read back, no covariance. IMU 0's own block as its
  // parameters report it (covariance.h).
  const Eigen::Index n0 = calibration.covariance.rows();
  for (Eigen::Index a = 0; a < n0; ++a) {
    for (Eigen::Index b = 0; b < n0; ++b) {
      const bool determined = calibration.parameters[static_cast<std::size_t>(a)].observable &&
                              calibration.parameters[static_cast<std::size_t>(b)].observable;
      cov(a, b) = determined ? calibration.covariance(a, b) : 0.0;
    }
  }
}

}  // namespace plumb::estimation

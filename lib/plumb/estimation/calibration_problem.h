// plumb/estimation/calibration_problem.h — stage 4 of the backend: the least-squares problem.
//
// Unknowns: the model's parameter blocks (theta, one per term; fixed parameters held by a
// SubsetManifold) and one attitude R_n_b per still pose (AttitudeManifold; TiltManifold for a
// chain's heading gauge; HeadingManifold for a known tilt; constant when known). Residuals
// (lib/plumb/residuals), each whitened by its square-root information:
//   still accelerometer   y_a mean - predicted,            sqrt_info = sqrt(N / tau) / sigma_a
//   still gyroscope       y_g mean - predicted (Earth rate, stated turn rate)
//   motion                Log((R_k dR)^T R_k+1), dR the corrected rate integrated on SO(3)
//   velocity (optional)   the accelerometer integrated while the IMU turns (lever arms, time
//                         offset: effects whose excitation includes angular acceleration)
//   bias wander (optional) with a bias random walk or instability in the noise model, every
//                         pose has each wander process (noise_model.h) at its first and last
//                         sample (s_k, e_k) as unknowns, in the still residual as
//                         w (s_k + e_k) (the process's bridge mean), in the motion residual
//                         linear between e_k and s_k+1, and tied by the Markov factors
//                         t_ref -> s_0 -> e_0 -> s_1 -> ... (residuals/bias_walk_residual.h)
// The board's other IMUs (SPEC 6, "Several IMUs of one board"; problem_imu.h) share the poses'
// attitudes: each has its model's blocks and a board_mount block (its rotation R_b_i into the
// body, model/board_mount.h), its own still and motion residuals (mounted: at the attitudes
// R_k R_b_i) and its own wander states; no velocity residual yet, so their lever arms and time
// offsets are held.
// The problem owns the values (theta, the poses' attitudes) that Ceres works on, so a
// ceres::Problem can be built from them again (with other parameters held) and its residuals
// and Jacobians handed out: the observability analysis, the covariance, diagnose's probe
// columns and the per-segment residuals all read them here. The values lie in one buffer, term
// blocks IMU by IMU in term order, then the attitudes in pose order, then the wander states, so that every ordering by address
// (ceres::Covariance sorts parameter blocks by address) is the same on every run: results do
// not depend on how the heap happened to be laid out.
//
// INTERNAL to plumb::estimation (not installed): it exposes Ceres's problem; the public
// interface is calibrator.h and what it returns.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/estimation/fit_report.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/parallel_evaluation.h"
#include "plumb/estimation/problem_imu.h"
#include "plumb/estimation/still_set.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"
#include "plumb/residuals/measurements.h"

namespace plumb::estimation {

/// A (term, index) pair naming one scalar parameter: the terms are counted over every IMU of
/// the problem, IMU 0's model's first, then each other IMU's model's and its board_mount block
/// (CalibrationProblem::imus(), ProblemImu::first_term).
using ParameterIndex = std::pair<int, int>;

/// What a fit holds where it starts besides the model's fixed parameters (solve.h): one
/// parameter per null direction (its pivot), and the weakly determined combinations
/// (observability.h kWeakSpread), each as terms and the data's sigma of it.
struct Gauge {
  struct Combination {
    std::vector<std::pair<ParameterIndex, double>> terms;  ///< parameter, coefficient
    double sigma = 0.0;  ///< the data's sigma of the combination, its unit
  };
  std::vector<ParameterIndex> parameters;
  std::vector<Combination> combinations;

  bool empty() const { return parameters.empty() && combinations.empty(); }
};

/// A held combination's residual is the combination's move from its start over this share of
/// the data's sigma of it: the data cannot move it measurably (a pull of one sigma moves it
/// by 1e-6 of its sigma), and a thousand to one keeps the normal equations well within double
/// precision.
inline constexpr double kHeldCombinationWidth = 1e-3;

/// A ceres::Problem built from the current values, with its residual blocks per still pose
/// and motion interval (null where absent) and the manifolds it uses.
struct BuiltProblem {
  std::vector<std::unique_ptr<ceres::Manifold>> manifolds;  // outlives `problem` (declared first)
  /// The motion residuals evaluated before each pass, at once when options.run_jobs is given
  /// (null without motion); outlives `problem`, which points to it.
  std::unique_ptr<ParallelEvaluation> evaluation;
  std::unique_ptr<ceres::Problem> problem;
  std::vector<ceres::ResidualBlockId> acc, gyr;  ///< per still pose
  std::vector<ceres::ResidualBlockId> motion;    ///< per motion interval
  std::vector<ceres::ResidualBlockId> velocity;  ///< per motion interval, when used
  std::vector<ceres::ResidualBlockId> walk;      ///< bias-wander factors, when the bias wanders
  std::vector<std::size_t> walk_process;         ///< per wander factor: its process (Wander order)
  std::vector<ceres::ResidualBlockId> held;      ///< per held combination (Gauge)
  /// The board's other IMUs' residuals (CalibrationProblem::imus()[i + 1]).
  struct ImuBlocks {
    std::vector<ceres::ResidualBlockId> acc, gyr;  ///< per still pose
    std::vector<ceres::ResidualBlockId> motion;    ///< per motion interval
    /// Per motion interval with windows, when its turns are compared with IMU 0's (ProblemImu::
    /// turns_compared): its accelerometer against IMU 0's (residuals/board_force_residual.h).
    std::vector<ceres::ResidualBlockId> turns;
    std::vector<ceres::ResidualBlockId> walk;      ///< its bias-wander factors
  };
  std::vector<ImuBlocks> board;
};

/// The free unknowns of a built problem as Jacobian columns, in order: the board's mounts (IMU
/// by IMU), the model parameters (IMU by IMU, term by term), then attitude tangents (pose by
/// pose: north, east, down as free), then the bias-wander states (pose by pose; per process of NoiseModel::Wander, start then end).
struct UnknownColumns {
  std::vector<double*> blocks;          ///< parameter blocks in column order
  std::vector<std::string> names;       ///< per column, e.g. "accel.bias.x", "attitude[3].down"
  std::vector<double> values;           ///< per column: reported value (NaN for attitudes)
  std::vector<bool> is_model;           ///< per column: model parameter (else attitude)
  /// Per column: a model parameter's typical size (model::ParameterInfo::typical) in the
  /// column's unit (times the output's sensitivity where the output is not SI); 0 otherwise.
  std::vector<double> typical;
  std::vector<std::pair<int, int>> model_index;  ///< per column: (term, index) or (-1, pose)
  /// Columns [first_wander, size) are the bias-wander states (none: first_wander == size).
  std::size_t first_wander = 0;
};

class CalibrationProblem {
 public:
  /// `theta` and the poses' attitudes hold the starting values (Initialize); `start` gives
  /// the starting linear parts for the first motion weights. `board`: the board's other IMUs
  /// fitted with it (SPEC 6; problem_imu.h), each with its model's blocks and a board_mount
  /// block as its terms after IMU 0's (ParameterIndex counts the terms of every IMU, IMU 0's
  /// first); none: IMU 0 alone.
  CalibrationProblem(const ImuSeries& series, model::Model model, const geo::Site& site,
                     StillSet still, model::ParameterBlocks theta, const NoiseModel& noise,
                     const StartingValues& start, const CalibrationOptions& options,
                     std::vector<BoardImuInput> board = {});
  CalibrationProblem(const CalibrationProblem&) = delete;  // Ceres points into the values
  CalibrationProblem& operator=(const CalibrationProblem&) = delete;

  /// Whitening of IMU 0's motion residuals (the white gyroscope noise carried through E^-1 and
  /// integrated over the interval's steps) and of its velocity residuals, and the angular
  /// acceleration input E^-1 d y_g / dt, from the linear parts E and F.
  void SetMotionWeights(const Mat3& E, const Mat3& F);
  /// Sets every IMU's motion weights from the current values of its linear parts (before the
  /// final solve, so that chi^2 does not depend on the starting values).
  void SetMotionWeightsFromSolution();

  /// A problem on the current values. `gauge`: parameters held at their values besides the
  /// model's fixed ones, and combinations held where they are (residuals::HeldCombination,
  /// after every other residual); `free_probes`: the probe terms' blocks are left free (for
  /// their Jacobian columns only).
  BuiltProblem Build(const Gauge& gauge, bool free_probes = false);

  /// The free unknowns of `problem` (built by Build with `held` held) as columns.
  UnknownColumns Columns(const ceres::Problem& problem,
                         const std::vector<ParameterIndex>& held = {});
  /// Whitened residuals (optional) and Jacobian over `columns`, with the cost 0.5 r^T r.
  Eigen::MatrixXd Jacobian(ceres::Problem& problem, const UnknownColumns& columns,
                           double* cost, std::vector<double>* residuals) const;
  /// The same Jacobian, sparse (column-major), for problems with many unknowns.
  Eigen::SparseMatrix<double> SparseJacobian(ceres::Problem& problem,
                                             const UnknownColumns& columns, double* cost,
                                             std::vector<double>* residuals) const;
  /// The whitened residuals and Jacobian of `probe` (Build(..., true)) at the current values:
  /// columns `columns` then every probe term's block.
  ProbeJacobian ProbeColumns(const BuiltProblem& probe, const UnknownColumns& columns);
  /// Per-segment and per-interval residuals of `built` at the current values, and their RMS,
  /// into `fit` (IMU 0's).
  void ReportResiduals(const BuiltProblem& built, FitReport& fit) const;

  /// IMU 0's model, poses and intervals.
  const model::Model& model() const { return imus_[0].model; }
  const StillSet& still() const { return imus_[0].still; }
  /// The IMUs of the fit: IMU 0, then the board's others in the order given.
  const std::vector<ProblemImu>& imus() const { return imus_; }
  /// IMU 0's current model parameter blocks (a copy), one per term.
  model::ParameterBlocks theta() const;
  /// Where Ceres keeps each of IMU 0's term blocks, in term order (for model::Model::Predict
  /// and ceres::Covariance on a built problem).
  std::vector<const double*> ModelBlocks() const;
  /// The same for IMU `imu`'s terms (its model's, then its board_mount block).
  std::vector<const double*> TermBlocks(std::size_t imu) const;
  /// The current attitude R_n_b of pose k.
  Quat R_n_b(std::size_t k) const;
  /// Saves the current values (theta and the attitudes), and puts them back (the solve's
  /// restart from the starting values, solve.h).
  void SaveValues();
  void RestoreValues();
  /// Takes every unknown's value from `from` (a problem of the same model, segments and
  /// wander), but for the attitudes this problem's poses know (held): what the same solution
  /// looks like under this problem's assumptions (sensitivity.h). Throws plumb::Error when the
  /// layouts differ.
  void TakeValues(const CalibrationProblem& from);
  /// The processes IMU 0's biases wander by (NoiseModel::Wander): BuiltProblem::walk_process
  /// indexes them.
  const std::vector<WanderProcess>& WanderProcesses() const { return imus_[0].wander; }
  /// The gyroscope is integrated between poses (there are motion intervals).
  bool has_motion() const { return imus_[0].has_gyro && !still().motions.empty(); }

 private:
  ProblemImu MakeImu(const ImuSeries& series, model::Model model, StillSet still,
                     const NoiseModel& noise, const StartingValues& start, bool mounted) const;
  void AddParameterBlocks(BuiltProblem& built, const std::vector<ParameterIndex>& held,
                          bool free_probes);
  /// Adds IMU `imu`'s still, motion and velocity residuals (IMU 0's into built.acc, .gyr,
  /// .motion, .velocity; the others' into built.board[imu - 1]).
  void AddResiduals(BuiltProblem& built, std::size_t imu);
  /// Adds the comparison of IMU `imu`'s turns with IMU 0's (ProblemImu::turns_compared).
  void AddTurnComparison(BuiltProblem& built, std::size_t imu, BuiltProblem::ImuBlocks& own);
  /// Weighs IMU `imu`'s turn windows (board_turns.h) at the current values of both IMUs'
  /// linear stages and its rotation.
  void SetTurnWeights(std::size_t imu);
  void AddHeldCombinations(BuiltProblem& built, const std::vector<Gauge::Combination>& held);
  /// The IMU and its own term of the problem's term t (ParameterIndex::first).
  std::pair<std::size_t, int> TermOf(int t) const;
  int num_terms() const { return imus_.back().first_term + imus_.back().num_terms(); }
  double* block(int t) {
    const auto [imu, local] = TermOf(t);
    return values_.data() + imus_[imu].block_offset[static_cast<std::size_t>(local)];
  }
  const double* block(int t) const { return const_cast<CalibrationProblem*>(this)->block(t); }
  int block_size(int t) const {
    const auto [imu, local] = TermOf(t);
    return imus_[imu].TermInfo(local).size();
  }
  /// IMU `imu`'s board_mount block (mounted IMUs only).
  double* mount(std::size_t imu) {
    return values_.data() + imus_[imu].block_offset[static_cast<std::size_t>(imus_[imu].model.num_terms())];
  }
  /// The state of IMU `imu`'s wander process p in pose k, at the segment's first (`end`
  /// false) or last sample (3 values, sensor units).
  double* wander(std::size_t imu, std::size_t k, std::size_t p, bool end) {
    const ProblemImu& u = imus_[imu];
    return values_.data() + u.walk_offset + 6 * (u.wander.size() * k + p) + (end ? 3 : 0);
  }
  const double* wander(std::size_t imu, std::size_t k, std::size_t p, bool end) const {
    return const_cast<CalibrationProblem*>(this)->wander(imu, k, p, end);
  }
  /// Adds the Markov factors of IMU `imu`'s wander process p to `built` (IMU 0's into
  /// built.walk).
  void AddWanderFactors(BuiltProblem& built, std::size_t imu, std::size_t p);
  double* q(std::size_t k) { return values_.data() + q_offset_ + 4 * k; }
  const double* q(std::size_t k) const { return values_.data() + q_offset_ + 4 * k; }
  /// IMU-local terms [first, end): its model's are [0, model.num_terms()), its mount the one
  /// after them.
  struct TermRange {
    int first = 0;
    int end = 0;
  };
  /// Adds the columns of IMU `imu`'s free blocks among its terms `locals` to `out`.
  void AddTermColumns(const ceres::Problem& problem, const std::vector<ParameterIndex>& held,
                      std::size_t imu, TermRange locals, UnknownColumns& out);
  /// Adds the columns of IMU `imu`'s wander states to `out`.
  void AddWanderColumns(std::size_t imu, UnknownColumns& out);

  geo::Site site_;
  CalibrationOptions options_;
  std::vector<ProblemImu> imus_;           // IMU 0, then the board's others
  std::vector<double> values_;             // term blocks (IMU by IMU), q_k per pose, wander
  std::size_t q_offset_ = 0;               // offset of the first attitude in values_
  std::vector<double> saved_values_;
};

}  // namespace plumb::estimation

// plumb/estimation/solve.h — stage 5 of the backend: the solve, with a gauge for what the
// data cannot determine.
//
// Levenberg-Marquardt (Ceres, dense QR). Where the data leaves directions unobservable the
// solver could wander along them (or exploit ones that are observable only at the level of
// rounding), so the fit is redone from the starting values with one parameter per null
// direction (its row-echelon pivot, e.g. accel.matrix.zz for "9.78 accel.bias.z + 1
// accel.matrix.zz") held at its start value, and every weakly determined combination
// (observability.h kWeakSpread) held where it starts (residuals::HeldCombination). The weak
// combinations depend on where the analysis linearises, so the held fit is analysed again and
// redone while its gauge changes shape (at most kGaugeRounds fits). The free fit can wander far
// along what the data do not determine (one turn sampled at 3 Hz took a gyroscope scale to 1e7),
// and a gauge read there need not hold at the start: when the held fits do not converge, the
// gauge is read again at the starting values, on the noise model's sigmas, and the held fits are
// made again from it. With motion intervals, the motion residuals' whitening is set again from
// the first solution's E and F before the final solve, so chi^2 does not depend on the starting
// values.
//
// INTERNAL to plumb::estimation (not installed): it exposes Ceres's problem.
#pragma once

#include <ceres/ceres.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/elimination.h"
#include "plumb/estimation/fit_report.h"
#include "plumb/estimation/observability.h"
#include "plumb/estimation/options.h"

namespace plumb::estimation {

/// The held fits SolveWithGauge makes at most: the first from the free fit's analysis, then
/// again while the analysis at the held fit's solution finds a gauge of another shape (more or
/// fewer null directions or weak combinations). Two settle every session we have.
inline constexpr int kGaugeRounds = 3;

/// Above this many parameters (ambient, all blocks) the solve uses a sparse Cholesky
/// factorisation instead of dense QR.
inline constexpr int kDenseUnknowns = 400;

/// Tolerances of a first, rough solve that another solve refines (options.function_tolerance
/// and parameter_tolerance apply to the final one).
inline constexpr double kRoughFunctionTolerance = 1e-6;
inline constexpr double kRoughParameterTolerance = 1e-8;
/// Initial trust-region radius of a solve from the starting values (initialization.h: closed
/// forms and a scale search, within a few percent): Ceres's default of 1e4 took two to three
/// more iterations on sessions of many poses, growing threefold per step.
inline constexpr double kStartTrustRegion = 1e6;
/// Initial trust-region radius of a solve that refines another's solution (Ceres's default is
/// 1e4): nearly Gauss-Newton, as a solve from next to the optimum can be; a step that fails
/// shrinks it.
inline constexpr double kRefineTrustRegion = 1e12;
/// Gradient tolerance of every solve: small enough that the function and parameter
/// tolerances decide convergence.
inline constexpr double kGradientTolerance = 1e-14;

/// Which solve of a fit: its tolerances and its first trust region.
enum class SolveStage {
  kFromStart,  ///< from the starting values to the final tolerances (options' function and
               ///< parameter tolerances; kStartTrustRegion)
  kRough,      ///< from the starting values to the rough tolerances; another solve refines it
  kRefine,     ///< from another solve's solution to the final tolerances (kRefineTrustRegion)
};

/// What one solve did.
struct SolveOutcome {
  int steps = 0;           ///< steps taken (successful and not; Ceres's iteration 0 is the start)
  bool converged = false;  ///< Ceres's termination is CONVERGENCE
  std::string report;      ///< ceres::Solver::Summary::BriefReport()
};

/// One solve of `problem` at `stage`, limited to options.max_iterations; throws plumb::Error
/// when the solution is not usable.
SolveOutcome Solve(ceres::Problem& problem, SolveStage stage, const CalibrationOptions& options);

/// Adds a solve to the fit's account: its steps to the iterations, one solve, its convergence
/// and Ceres's brief report (the last solve's).
void Record(const SolveOutcome& solve, FitReport& fit);

/// The analysis (observability.h) of a problem at the current values, with what the calibration
/// reads of it besides: the unknowns' columns, the cost, the whitened residuals and Jacobian.
struct AnalysedSolution {
  ObservabilityAnalysis analysis;
  UnknownColumns columns;
  double cost = 0;
  std::vector<double> residuals;  ///< whitened
  /// Over `columns`, for the linearity check (AnalysisOptions::keep_jacobian).
  Eigen::SparseMatrix<double> jacobian;
  /// The analysis's elimination when it took every column after the model's (attitudes and
  /// wander together; else null), for the linearity check (AnalysisOptions::keep_jacobian).
  std::shared_ptr<const EliminatedJacobian> eliminated;
  /// Every column's whitened Jacobian, as analysed (AnalysisOptions::dense).
  Eigen::MatrixXd dense_jacobian;
};

/// How AnalyseAt analyses and what it keeps.
struct AnalysisOptions {
  /// Analyse every column densely (O(unknowns^3)) and keep the Jacobian analysed
  /// (dense_jacobian). Otherwise the bias-wander states are eliminated first (a sparse QR): the
  /// analysis and its covariance are then over the columns before columns.first_wander, the
  /// wander marginalised.
  bool dense = false;
  /// Without `dense`: keep the whitened sparse Jacobian and, when the analysis made one, the
  /// elimination of every column after the model's, for other checks at the same point.
  bool keep_jacobian = false;
  /// Judge the weak combinations on the sigmas the noise model gives, not scaled by the misfit
  /// (observability.h kWeakSpread): at the starting values the misfit says only that no fit
  /// has been made yet.
  bool formal_sigmas = false;
};

/// The observability analysis of `problem` at the current values (see AnalysisOptions).
AnalysedSolution AnalyseAt(CalibrationProblem& calibration, ceres::Problem& problem,
                           const CalibrationOptions& options, const AnalysisOptions& how = {});

/// The leverages h_ii = J_i (J^T J)^+ J_i^T of the whitened residual rows `rows` of `problem`
/// (every free unknown, the wander states eliminated by a sparse QR first), and its whitened
/// residuals (optional): the part of each residual the fit absorbs, for variance components.
Eigen::VectorXd Leverages(CalibrationProblem& calibration, ceres::Problem& problem,
                          const CalibrationOptions& options, const std::vector<Eigen::Index>& rows,
                          std::vector<double>* residuals);

/// AnalyseAt at a solution, keeping the Jacobian for the linearity check.
AnalysedSolution AnalyseSolution(CalibrationProblem& calibration, ceres::Problem& problem,
                                 const CalibrationOptions& options);

/// The solved problem.
struct Solution {
  BuiltProblem all_free;  ///< every free unknown: for the analysis and the residuals
  BuiltProblem held;      ///< with the gauge held (empty when there is none)
  Gauge gauge;            ///< the null directions' pivots and the weak combinations held
  /// all_free analysed at the solution, when the fit's last analysis was made there (nothing
  /// held, or a gauge analysed again at its solution); empty otherwise.
  std::optional<AnalysedSolution> analysed;
  /// The problem the fit and its covariance were made on.
  ceres::Problem& fitted() { return gauge.empty() ? *all_free.problem : *held.problem; }
};

/// Stage 5 (file comment): solves `calibration` in place.
Solution SolveWithGauge(CalibrationProblem& calibration, const CalibrationOptions& options,
                        FitReport& fit);

}  // namespace plumb::estimation

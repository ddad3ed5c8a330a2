#include "plumb/estimation/solve.h"

#include "plumb/core/error.h"
#include "plumb/estimation/elimination.h"

#include <memory>
#include <string>

namespace plumb::estimation {

SolveOutcome Solve(ceres::Problem& problem, SolveStage stage, const CalibrationOptions& options) {
  const bool rough = stage == SolveStage::kRough;
  ceres::Solver::Options solver_options;
  // Problems with bias-wander states have several unknowns per pose, most of them in a
  // banded chain: a sparse factorisation keeps their cost linear in the poses.
  solver_options.linear_solver_type =
      problem.NumParameters() > kDenseUnknowns ? ceres::SPARSE_NORMAL_CHOLESKY : ceres::DENSE_QR;
  // Eigen's sparse Cholesky rather than SuiteSparse's: SuiteSparse's supernodal kernels go
  // through the system BLAS, whose code paths depend on where the heap put the arrays, and a
  // fit must give the same bits whatever the heap and the thread (plumb sweep's shards).
  solver_options.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = rough ? kRoughFunctionTolerance : options.function_tolerance;
  solver_options.parameter_tolerance = rough ? kRoughParameterTolerance : options.parameter_tolerance;
  solver_options.gradient_tolerance = kGradientTolerance;
  // A solve that refines another starts next to the optimum: Gauss-Newton's full step is
  // right there, and a trust region grown from Ceres's default (1e4, three times per step)
  // would damp the weakly determined directions for several iterations.
  solver_options.initial_trust_region_radius =
      stage == SolveStage::kRefine ? kRefineTrustRegion : kStartTrustRegion;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable()) throw Error("the solver failed: " + summary.BriefReport());
  // Counted as the report counts them (the steps taken; Ceres's iteration 0 is the start).
  return {summary.num_successful_steps + summary.num_unsuccessful_steps,
          summary.termination_type == ceres::CONVERGENCE, summary.BriefReport()};
}

void Record(const SolveOutcome& solve, FitReport& fit) {
  fit.solver_report = solve.report;
  fit.iterations += solve.steps;
  fit.last_solve_iterations = solve.steps;
  ++fit.solves;
  fit.converged = solve.converged;
}

AnalysedSolution AnalyseAt(CalibrationProblem& calibration, ceres::Problem& problem,
                           const CalibrationOptions& options, const AnalysisOptions& how) {
  AnalysedSolution out;
  UnknownColumns& columns = out.columns;
  columns = calibration.Columns(problem);
  ObservabilityInput in;
  in.names = columns.names;
  in.values = columns.values;
  in.is_model = columns.is_model;
  in.typical = columns.typical;
  in.rank_tolerance = options.rank_tolerance;
  const auto n = static_cast<Eigen::Index>(columns.names.size());
  const auto first_wander = static_cast<Eigen::Index>(columns.first_wander);
  const Eigen::Index n_m = LeadingModelColumns(columns.is_model);
  if (how.dense || (n_m == n && !how.keep_jacobian)) {
    in.J = calibration.Jacobian(problem, columns, &out.cost, &out.residuals);
    in.chi2 = how.formal_sigmas ? 0.0 : 2.0 * out.cost;
    in.observations = static_cast<int>(out.residuals.size());
    out.analysis = AnalyseObservability(in);
    if (how.dense) out.dense_jacobian = std::move(in.J);
    return out;
  }
  Eigen::SparseMatrix<double> J_local;
  Eigen::SparseMatrix<double>& J = how.keep_jacobian ? out.jacobian : J_local;
  J = calibration.SparseJacobian(problem, columns, &out.cost, &out.residuals);
  in.chi2 = how.formal_sigmas ? 0.0 : 2.0 * out.cost;
  in.observations = static_cast<int>(out.residuals.size());
  // The attitudes and wander states eliminated together when the data determine the attitudes
  // clearly (the cost is then linear in the poses), else the wander states alone; kept for
  // the caller (`eliminated`) in the first case.
  auto kept_elimination = std::make_shared<EliminatedJacobian>();
  if (how.keep_jacobian) kept_elimination->J = J;
  const Eigen::SparseMatrix<double>& J_e = how.keep_jacobian ? kept_elimination->J : J;
  kept_elimination->elimination = EliminatePoses(J_e, n_m, first_wander);
  const Elimination* elimination = kept_elimination->elimination.get();
  if (elimination == nullptr) {
    in.J = Eigen::MatrixXd(J);
    out.analysis = AnalyseObservability(in);
    return out;
  }
  const Eigen::Index kept = elimination->first();
  in.J = elimination->Reduced(options.run_jobs);
  if (how.keep_jacobian && kept == n_m) {
    kept_elimination->M = in.J;
    out.eliminated = kept_elimination;
  }
  in.names.resize(static_cast<std::size_t>(kept));
  in.values.resize(static_cast<std::size_t>(kept));
  in.is_model.resize(static_cast<std::size_t>(kept));
  in.typical.resize(static_cast<std::size_t>(kept));
  in.wander_outside = static_cast<int>(n - first_wander);
  const Eigen::Index n_attitudes = first_wander - kept;
  if (n_attitudes > 0) {
    in.eliminated_names.assign(columns.names.begin() + kept, columns.names.begin() + first_wander);
    in.eliminated_response = [elimination, n_attitudes,
                              J_k = Eigen::SparseMatrix<double>(J.leftCols(kept))](
                                 const Eigen::MatrixXd& directions) -> Eigen::MatrixXd {
      // J_k x_k + J_e x_e = 0: x_e = -argmin |J_k x_k + J_e x_e|, its attitudes' rows.
      return -elimination->Solve(J_k * directions).topRows(n_attitudes);
    };
  }
  out.analysis = AnalyseObservability(in);
  // The wander states are always determined (their factors tie them down): counted apart.
  out.analysis.summary.wander_states = static_cast<int>(n - first_wander);
  return out;
}

Eigen::VectorXd Leverages(CalibrationProblem& calibration, ceres::Problem& problem,
                          const CalibrationOptions& options, const std::vector<Eigen::Index>& rows,
                          std::vector<double>* residuals) {
  const UnknownColumns columns = calibration.Columns(problem);
  double cost = 0;
  // The projector onto range(J) is P_e (the per-pose columns' range) plus the projector onto
  // the range of the reduced Jacobian M = (I - P_e) J_k, M's rank as the analysis decides it
  // on unit-norm columns (JacobianRange).
  const JacobianRange range(calibration.SparseJacobian(problem, columns, &cost, residuals),
                            LeadingModelColumns(columns.is_model),
                            static_cast<Eigen::Index>(columns.first_wander),
                            options.rank_tolerance);
  return range.Leverage(rows);
}

AnalysedSolution AnalyseSolution(CalibrationProblem& calibration, ceres::Problem& problem,
                                 const CalibrationOptions& options) {
  AnalysisOptions how;
  how.keep_jacobian = true;
  return AnalyseAt(calibration, problem, options, how);
}

namespace {

/// What to hold, from an analysis: the null directions' pivots that are model parameters, and
/// the weak combinations with the data's sigma of each.
Gauge GaugeOf(const AnalysedSolution& at) {
  Gauge gauge;
  const std::vector<ParameterIndex>& index = at.columns.model_index;
  for (int c : at.analysis.pivots) {
    if (index[static_cast<std::size_t>(c)].first >= 0) gauge.parameters.push_back(index[static_cast<std::size_t>(c)]);
  }
  for (const Eigen::VectorXd& c : at.analysis.weak) {
    Gauge::Combination held;
    for (Eigen::Index j = 0; j < c.size(); ++j) {
      if (c[j] != 0.0) held.terms.emplace_back(index[static_cast<std::size_t>(j)], c[j]);
    }
    held.sigma = std::sqrt(c.dot(at.analysis.covariance * c));
    gauge.combinations.push_back(std::move(held));
  }
  return gauge;
}

bool SameShape(const Gauge& a, const Gauge& b) {
  return a.parameters.size() == b.parameters.size() &&
         a.combinations.size() == b.combinations.size();
}

/// The gauge read at the starting values (the values saved before the free fit), on the noise
/// model's sigmas; the calibration's values are left at the start.
Gauge GaugeAtStart(CalibrationProblem& calibration, const CalibrationOptions& options) {
  calibration.RestoreValues();
  const BuiltProblem start = calibration.Build({});
  AnalysisOptions how;
  how.formal_sigmas = true;
  return GaugeOf(AnalyseAt(calibration, *start.problem, options, how));
}

/// The held fits from `gauge`, each from the starting values: again while the analysis at the
/// solution finds a gauge of another shape (at most kGaugeRounds). Leaves `out` as the last.
void HeldFits(CalibrationProblem& calibration, const CalibrationOptions& options, Gauge gauge,
              Solution& out, FitReport& fit) {
  for (int round = 0; round < kGaugeRounds; ++round) {
    out.analysed.reset();
    calibration.RestoreValues();
    out.gauge = std::move(gauge);
    out.all_free = calibration.Build({});
    out.held = calibration.Build(out.gauge);
    Record(Solve(*out.held.problem, SolveStage::kFromStart, options), fit);
    // Without weak combinations the null directions are the free fit's: nothing to redo.
    if (out.gauge.combinations.empty()) break;
    out.analysed = AnalyseSolution(calibration, *out.all_free.problem, options);
    gauge = GaugeOf(*out.analysed);
    if (SameShape(gauge, out.gauge)) break;
  }
}

}  // namespace

// Solves with every unknown free (with motion: roughly, then again with the motion weights
// of that solution) and analyses the solution. Where the analysis finds null directions or
// weak combinations, they are held and the fit is made again from the starting values, and
// analysed again while the gauge changes shape (the fit's account then has every solve). Held
// fits that do not converge are made again from the gauge at the starting values.
Solution SolveWithGauge(CalibrationProblem& calibration, const CalibrationOptions& options,
                        FitReport& fit) {
  Solution out;
  calibration.SaveValues();
  out.all_free = calibration.Build({});
  Record(Solve(*out.all_free.problem,
               calibration.has_motion() ? SolveStage::kRough : SolveStage::kFromStart, options),
         fit);
  FitReport refined = fit;  // the fit's account, kept only when nothing is held
  if (calibration.has_motion()) {
    calibration.SetMotionWeightsFromSolution();
    out.all_free = calibration.Build({});
    Record(Solve(*out.all_free.problem, SolveStage::kRefine, options), refined);
  }
  out.analysed = AnalyseSolution(calibration, *out.all_free.problem, options);
  Gauge gauge = GaugeOf(*out.analysed);
  if (gauge.empty()) {
    fit = std::move(refined);
    return out;
  }
  HeldFits(calibration, options, std::move(gauge), out, fit);
  if (!fit.converged) HeldFits(calibration, options, GaugeAtStart(calibration, options), out, fit);
  return out;
}

}  // namespace plumb::estimation

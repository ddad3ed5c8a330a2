#include "plumb/estimation/solve.h"

#include "plumb/core/error.h"

#include <Eigen/SparseQR>
#include <Eigen/OrderingMethods>
#include <string>

namespace plumb::estimation {

void Solve(ceres::Problem& problem, bool rough, const CalibrationOptions& options,
           FitReport& fit) {
  ceres::Solver::Options solver_options;
  // Problems with bias-wander states have several unknowns per pose, most of them in a
  // banded chain: a sparse factorisation keeps their cost linear in the poses.
  solver_options.linear_solver_type =
      problem.NumParameters() > kDenseUnknowns ? ceres::SPARSE_NORMAL_CHOLESKY : ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = rough ? kRoughFunctionTolerance : options.function_tolerance;
  solver_options.parameter_tolerance = rough ? kRoughParameterTolerance : options.parameter_tolerance;
  solver_options.gradient_tolerance = kGradientTolerance;
  solver_options.num_threads = 1;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  fit.solver_report = summary.BriefReport();
  fit.iterations += static_cast<int>(summary.iterations.size());
  fit.converged = summary.termination_type == ceres::CONVERGENCE;
  if (!summary.IsSolutionUsable()) throw Error("the solver failed: " + summary.BriefReport());
}

namespace {

/// The whitened Jacobian of the columns before `columns.first_wander` with the wander states
/// eliminated: J = [J_a J_w], J_w = Q [R; 0] (sparse QR; J_w has full column rank, every
/// state being tied to zero at t_ref by its Markov factors), and the rows of Q^T J_a below
/// R are the part of J_a the wander states cannot absorb. Its SVD gives the rank, null space
/// and covariance of the other unknowns with the wander marginalised, as the full dense
/// analysis would, at the cost of a sparse QR instead of an SVD over every state.
Eigen::MatrixXd WanderEliminated(const Eigen::SparseMatrix<double>& J, Eigen::Index first_wander) {
  const Eigen::Index n_w = J.cols() - first_wander;
  const Eigen::SparseMatrix<double> J_w = J.rightCols(n_w);
  Eigen::SparseQR<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> qr(J_w);
  if (qr.info() != Eigen::Success || qr.rank() != n_w) {
    throw Error("the bias-wander states are not determined by their factors (rank " +
                std::to_string(qr.rank()) + " of " + std::to_string(n_w) + ")");
  }
  const Eigen::MatrixXd J_a = Eigen::MatrixXd(J.leftCols(first_wander));
  const Eigen::MatrixXd QtJ_a = qr.matrixQ().transpose() * J_a;
  return QtJ_a.bottomRows(J.rows() - n_w);
}

}  // namespace

ObservabilityAnalysis AnalyseAt(CalibrationProblem& calibration, ceres::Problem& problem,
                                const CalibrationOptions& options, UnknownColumns& columns,
                                double* cost, std::vector<double>* residuals,
                                Eigen::MatrixXd* jacobian) {
  columns = calibration.Columns(problem);
  ObservabilityInput in;
  in.names = columns.names;
  in.values = columns.values;
  in.is_model = columns.is_model;
  in.rank_tolerance = options.rank_tolerance;
  const auto n_w = static_cast<int>(columns.names.size() - columns.first_wander);
  if (jacobian != nullptr || n_w == 0) {
    in.J = calibration.Jacobian(problem, columns, cost, residuals);
    ObservabilityAnalysis out = AnalyseObservability(in);
    if (jacobian != nullptr) *jacobian = std::move(in.J);
    return out;
  }
  const auto first = static_cast<Eigen::Index>(columns.first_wander);
  in.J = WanderEliminated(calibration.SparseJacobian(problem, columns, cost, residuals), first);
  in.names.resize(columns.first_wander);
  in.values.resize(columns.first_wander);
  in.is_model.resize(columns.first_wander);
  ObservabilityAnalysis out = AnalyseObservability(in);
  // The wander states are always determined (their factors tie them down): they add to the
  // rank and the unknowns alike.
  out.summary.rank += n_w;
  out.summary.num_unknowns += n_w;
  return out;
}

Solution SolveWithGauge(CalibrationProblem& calibration, const CalibrationOptions& options,
                        FitReport& fit) {
  Solution out;
  calibration.SaveValues();
  {
    BuiltProblem first = calibration.Build({});
    Solve(*first.problem, calibration.has_motion(), options, fit);
    UnknownColumns columns;
    double cost = 0;
    const ObservabilityAnalysis analysis =
        AnalyseAt(calibration, *first.problem, options, columns, &cost, nullptr);
    for (int c : analysis.pivots) {
      const ParameterIndex& index = columns.model_index[static_cast<std::size_t>(c)];
      if (index.first >= 0) out.held_parameters.push_back(index);
    }
  }
  if (calibration.has_motion()) calibration.SetMotionWeightsFromSolution();
  if (!out.held_parameters.empty()) calibration.RestoreValues();
  out.all_free = calibration.Build({});
  if (!out.held_parameters.empty()) out.held = calibration.Build(out.held_parameters);
  if (!out.held_parameters.empty() || calibration.has_motion()) {
    Solve(out.fitted(), false, options, fit);
  }
  return out;
}

}  // namespace plumb::estimation

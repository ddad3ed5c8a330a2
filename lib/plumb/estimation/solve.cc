#include "plumb/estimation/solve.h"

#include "plumb/core/error.h"

#include <Eigen/SVD>
#include <Eigen/SparseCholesky>
#include <string>

namespace plumb::estimation {

void Solve(ceres::Problem& problem, bool rough, const CalibrationOptions& options,
           FitReport& fit) {
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

/// The whitened Jacobian J = [J_a J_w] split at `first_wander`, and the projection P_w onto
/// the range of the wander states' columns J_w, through the sparse Cholesky factor of
/// J_w^T J_w (J_w has full column rank and a banded normal matrix: every state is tied to
/// zero at t_ref by its Markov factors). (I - P_w) J_a is the part of J_a the wander states
/// cannot absorb: its SVD gives the rank, null space and covariance of the other unknowns
/// with the wander marginalised, as the full dense analysis would, at the cost of a banded
/// factorisation instead of an SVD over every state. One step of iterative refinement (the
/// corrected semi-normal equations) keeps it as accurate as a QR of J_w.
class WanderElimination {
 public:
  WanderElimination(const Eigen::SparseMatrix<double>& J, Eigen::Index first_wander)
      : J_(J), first_(first_wander), J_w_(J.rightCols(J.cols() - first_wander)) {
    chol_.compute(Eigen::SparseMatrix<double>(J_w_.transpose() * J_w_));
    if (chol_.info() != Eigen::Success) {
      throw Error("the bias-wander states are not determined by their factors (their normal "
                  "matrix is not positive definite)");
    }
  }
  /// (I - P_w) A for a dense A with J's rows.
  Eigen::MatrixXd Project(const Eigen::MatrixXd& A) const {
    Eigen::MatrixXd X = chol_.solve(J_w_.transpose() * A);
    Eigen::MatrixXd R = A - J_w_ * X;
    X = chol_.solve(J_w_.transpose() * R);  // refinement
    return R - J_w_ * X;
  }
  /// (I - P_w) J_a: rows x first_wander.
  Eigen::MatrixXd Reduced() const { return Project(Eigen::MatrixXd(J_.leftCols(first_))); }
  /// The diagonal of P_w at `rows`.
  Eigen::VectorXd WanderLeverage(const std::vector<Eigen::Index>& rows) const {
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(J_.rows(), static_cast<Eigen::Index>(rows.size()));
    for (std::size_t i = 0; i < rows.size(); ++i) E(rows[i], static_cast<Eigen::Index>(i)) = 1.0;
    const Eigen::MatrixXd P = E - Project(E);  // P_w E
    Eigen::VectorXd out(static_cast<Eigen::Index>(rows.size()));
    for (std::size_t i = 0; i < rows.size(); ++i) {
      out[static_cast<Eigen::Index>(i)] = P(rows[i], static_cast<Eigen::Index>(i));
    }
    return out;
  }

 private:
  const Eigen::SparseMatrix<double>& J_;
  Eigen::Index first_;
  Eigen::SparseMatrix<double> J_w_;
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> chol_;
};

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
  const Eigen::SparseMatrix<double> J = calibration.SparseJacobian(problem, columns, cost, residuals);
  in.J = WanderElimination(J, static_cast<Eigen::Index>(columns.first_wander)).Reduced();
  in.names.resize(columns.first_wander);
  in.values.resize(columns.first_wander);
  in.is_model.resize(columns.first_wander);
  ObservabilityAnalysis out = AnalyseObservability(in);
  // The wander states are always determined (their factors tie them down): counted apart.
  out.summary.wander_states = n_w;
  return out;
}

Eigen::VectorXd Leverages(CalibrationProblem& calibration, ceres::Problem& problem,
                          const CalibrationOptions& options, const std::vector<Eigen::Index>& rows,
                          std::vector<double>* residuals) {
  const UnknownColumns columns = calibration.Columns(problem);
  double cost = 0;
  const Eigen::SparseMatrix<double> J = calibration.SparseJacobian(problem, columns, &cost, residuals);
  // The projector onto range(J) is P_w (the wander columns' range) plus the projector U_r U_r^T
  // onto the range of the reduced Jacobian M = (I - P_w) J_a, M's rank as the analysis
  // decides it on unit-norm columns: h_ii = (P_w)_ii + |U_r^T e_i|^2.
  const auto first = static_cast<Eigen::Index>(columns.first_wander);
  Eigen::MatrixXd M;
  Eigen::VectorXd h = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rows.size()));
  if (first < J.cols()) {
    const WanderElimination elimination(J, first);
    M = elimination.Reduced();
    h = elimination.WanderLeverage(rows);
  } else {
    M = Eigen::MatrixXd(J);
  }
  for (Eigen::Index c = 0; c < M.cols(); ++c) {
    const double norm = M.col(c).norm();
    if (norm > 0) M.col(c) /= norm;
  }
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU);
  const Eigen::VectorXd& sv = svd.singularValues();
  Eigen::Index r = 0;
  while (r < sv.size() && sv[r] > options.rank_tolerance * sv[0]) ++r;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    h[static_cast<Eigen::Index>(i)] += svd.matrixU().row(rows[i]).head(r).squaredNorm();
  }
  return h;
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

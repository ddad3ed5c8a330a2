#include "plumb/estimation/linearity.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>

#include "plumb/estimation/observability.h"

namespace plumb::estimation {
namespace {

/// chi^2 of `problem` at the solution moved by `delta` (one entry per column of `columns`,
/// through each block's manifold); the values are put back.
double Chi2At(ceres::Problem& problem, const UnknownColumns& columns, const Eigen::VectorXd& delta) {
  std::vector<std::vector<double>> saved;
  Eigen::Index col = 0;
  for (double* block : columns.blocks) {
    const int size = problem.ParameterBlockSize(block);
    const int tangent = problem.ParameterBlockTangentSize(block);
    saved.emplace_back(block, block + size);
    std::vector<double> moved(static_cast<std::size_t>(size));
    const ceres::Manifold* manifold = problem.GetManifold(block);
    if (manifold != nullptr) {
      manifold->Plus(block, delta.data() + col, moved.data());
    } else {
      for (int i = 0; i < size; ++i) moved[static_cast<std::size_t>(i)] = block[i] + delta[col + i];
    }
    std::copy(moved.begin(), moved.end(), block);
    col += tangent;
  }
  double cost = 0;
  problem.Evaluate(ceres::Problem::EvaluateOptions{}, &cost, nullptr, nullptr, nullptr);
  for (std::size_t b = 0; b < columns.blocks.size(); ++b) {
    std::copy(saved[b].begin(), saved[b].end(), columns.blocks[b]);
  }
  return 2.0 * cost;
}

/// The largest `keep` terms of the unit direction `v` over `names`, "+ ..." when there are more.
std::string LargestTerms(const Eigen::VectorXd& v, const std::vector<std::string>& names,
                         std::size_t keep) {
  std::vector<Eigen::Index> order(static_cast<std::size_t>(v.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i) order[static_cast<std::size_t>(i)] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](Eigen::Index a, Eigen::Index b) { return std::abs(v[a]) > std::abs(v[b]); });
  Eigen::VectorXd largest = Eigen::VectorXd::Zero(v.size());
  for (std::size_t i = 0; i < std::min(keep, order.size()); ++i) largest[order[i]] = v[order[i]];
  std::string text = FormatCombination(largest, names, false);
  if (order.size() > keep && std::abs(v[order[keep]]) > 1e-9 * std::abs(v[order[0]])) {
    text += " + ...";
  }
  return text;
}

}  // namespace

LinearityReport CheckLinearity(CalibrationProblem& calibration, ceres::Problem& problem,
                               const std::vector<ParameterIndex>& held, double step_sigmas,
                               const Eigen::SparseMatrix<double>* jacobian, double cost) {
  LinearityReport out;
  out.step_sigmas = step_sigmas;
  const UnknownColumns columns = calibration.Columns(problem, held);
  const auto n = static_cast<Eigen::Index>(columns.names.size());
  const auto n_m = static_cast<Eigen::Index>(
      std::count(columns.is_model.begin(), columns.is_model.end(), true));
  if (n_m == 0) return out;
  double cost0 = cost;
  Eigen::SparseMatrix<double> J_local;
  if (jacobian == nullptr) J_local = calibration.SparseJacobian(problem, columns, &cost0, nullptr);
  const Eigen::SparseMatrix<double>& J = jacobian != nullptr ? *jacobian : J_local;
  const double chi2_0 = 2.0 * cost0;
  const Eigen::SparseMatrix<double> N = Eigen::SparseMatrix<double>(J.transpose()) * J;
  const Eigen::Index n_r = n - n_m;
  // Model columns come first (calibration_problem.h): N = [N_mm N_mr; N_rm N_rr].
  Eigen::MatrixXd S = Eigen::MatrixXd(N.topLeftCorner(n_m, n_m));
  Eigen::MatrixXd X(n_r, n_m);  // N_rr^-1 N_rm: the other unknowns' conditional response
  if (n_r > 0) {
    const Eigen::SparseMatrix<double> N_rr = N.bottomRightCorner(n_r, n_r);
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(N_rr);
    if (ldlt.info() != Eigen::Success) return out;
    const Eigen::MatrixXd N_rm = Eigen::MatrixXd(N.bottomLeftCorner(n_r, n_m));
    X = ldlt.solve(N_rm);
    S -= N_rm.transpose() * X;
  }
  const Eigen::LDLT<Eigen::MatrixXd> s_ldlt(S);
  if (s_ldlt.info() != Eigen::Success || !s_ldlt.isPositive()) return out;
  const Eigen::MatrixXd C = s_ldlt.solve(Eigen::MatrixXd::Identity(n_m, n_m));
  const Eigen::VectorXd d = C.diagonal().cwiseSqrt();
  if (!d.allFinite() || d.minCoeff() <= 0) return out;
  const Eigen::MatrixXd R = d.cwiseInverse().asDiagonal() * C * d.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(R);
  if (eig.info() != Eigen::Success) return out;
  out.checked = true;
  const double c2 = step_sigmas * step_sigmas;
  // The loosest directions (largest mu, last in Eigen's increasing order) span the valley of
  // near-equal fits, where its curvature shows; the tight ones are checked only on small fits.
  const Eigen::Index first = std::max<Eigen::Index>(0, n_m - kLinearityDirections);
  for (Eigen::Index k = first; k < n_m; ++k) {
    const double mu = std::max(eig.eigenvalues()[k], 0.0);
    const Eigen::VectorXd d_m = d.asDiagonal() * eig.eigenvectors().col(k) * std::sqrt(mu);
    Eigen::VectorXd delta(n);
    delta.head(n_m) = step_sigmas * d_m;
    if (n_r > 0) delta.tail(n_r) = -step_sigmas * (X * d_m);
    const double plus = Chi2At(problem, columns, delta) - chi2_0;
    const double minus = Chi2At(problem, columns, -delta) - chi2_0;
    const double ratio = std::max(plus, minus) / c2;
    out.ratio.push_back(ratio);
    if (ratio > out.worst_ratio) {
      out.worst_ratio = ratio;
      const std::vector<std::string> names(columns.names.begin(), columns.names.begin() + n_m);
      out.worst_direction = LargestTerms(eig.eigenvectors().col(k), names, 4);
    }
  }
  return out;
}

}  // namespace plumb::estimation

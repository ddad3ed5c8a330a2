#include "plumb/estimation/linearity.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <vector>

#include "plumb/estimation/elimination.h"
#include "plumb/estimation/observability.h"

namespace plumb::estimation {
namespace {

/// chi^2 of `problem` at its values moved by each of `deltas` (one entry per column of
/// `columns`, through each block's manifold). Each point is one job (through `run_jobs`): it
/// evaluates every residual block, in the problem's order, at its own copies of the moved
/// blocks, so the problem's values are never touched and the points can be evaluated at once.
std::vector<double> Chi2At(const ceres::Problem& problem, const UnknownColumns& columns,
                           const std::vector<Eigen::VectorXd>& deltas, const JobRunner& run_jobs) {
  std::unordered_map<const double*, std::size_t> moved_index;
  for (std::size_t b = 0; b < columns.blocks.size(); ++b) moved_index[columns.blocks[b]] = b;
  std::vector<ceres::ResidualBlockId> ids;
  problem.GetResidualBlocks(&ids);
  struct Block {
    const ceres::CostFunction* cost;
    const ceres::LossFunction* loss;
    std::vector<double*> values;
    std::vector<std::ptrdiff_t> moved;  ///< per parameter block: its index among the moved, or -1
  };
  std::vector<Block> blocks;
  for (ceres::ResidualBlockId id : ids) {
    Block block{problem.GetCostFunctionForResidualBlock(id),
                problem.GetLossFunctionForResidualBlock(id), {}, {}};
    problem.GetParameterBlocksForResidualBlock(id, &block.values);
    for (double* values : block.values) {
      const auto at = moved_index.find(values);
      block.moved.push_back(at == moved_index.end() ? -1 : static_cast<std::ptrdiff_t>(at->second));
    }
    blocks.push_back(std::move(block));
  }
  // The moved blocks' sizes and manifolds, read here: the jobs only read what is prepared.
  std::vector<int> sizes, tangents;
  std::vector<const ceres::Manifold*> manifolds;
  for (double* values : columns.blocks) {
    sizes.push_back(problem.ParameterBlockSize(values));
    tangents.push_back(problem.ParameterBlockTangentSize(values));
    manifolds.push_back(problem.GetManifold(values));
  }
  std::vector<double> chi2(deltas.size(), 0.0);
  RunJobs(run_jobs, static_cast<int>(deltas.size()), [&](int job) {
    const Eigen::VectorXd& delta = deltas[static_cast<std::size_t>(job)];
    std::vector<std::vector<double>> moved;
    Eigen::Index col = 0;
    for (std::size_t b = 0; b < columns.blocks.size(); ++b) {
      const double* values = columns.blocks[b];
      moved.emplace_back(values, values + sizes[b]);
      if (manifolds[b] != nullptr) {
        manifolds[b]->Plus(values, delta.data() + col, moved.back().data());
      } else {
        for (int i = 0; i < sizes[b]; ++i) moved.back()[static_cast<std::size_t>(i)] += delta[col + i];
      }
      col += tangents[b];
    }
    double cost = 0.0;
    std::vector<const double*> at;
    std::vector<double> r;
    for (const Block& block : blocks) {
      at.clear();
      for (std::size_t j = 0; j < block.values.size(); ++j) {
        at.push_back(block.moved[j] < 0 ? block.values[j]
                                        : moved[static_cast<std::size_t>(block.moved[j])].data());
      }
      r.assign(static_cast<std::size_t>(block.cost->num_residuals()), 0.0);
      if (!block.cost->Evaluate(at.data(), r.data(), nullptr)) {
        cost = std::numeric_limits<double>::infinity();
        break;
      }
      const double sq = Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size())).squaredNorm();
      double rho[3] = {sq, 1.0, 0.0};
      if (block.loss != nullptr) block.loss->Evaluate(sq, rho);
      cost += 0.5 * rho[0];
    }
    chi2[static_cast<std::size_t>(job)] = 2.0 * cost;
  });
  return chi2;
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
                               const Eigen::SparseMatrix<double>* jacobian, double cost,
                               const EliminatedJacobian* eliminated, const JobRunner& run_jobs) {
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
  const Eigen::Index n_r = n - n_m;
  // Model columns come first (calibration_problem.h): N = J^T J = [N_mm N_mr; N_rm N_rr], and
  // S = N_mm - N_rm^T N_rr^-1 N_rm is the Schur complement on the model's parameters. With
  // the analysis's elimination of every other column, S = M^T M and the other unknowns'
  // response to d_m is its least-squares solution of J_r x = J_m d_m; else from N.
  const bool reuse = eliminated != nullptr && eliminated->elimination != nullptr &&
                     eliminated->elimination->first() == n_m && eliminated->J.cols() == n;
  Eigen::MatrixXd S, X;  // X = N_rr^-1 N_rm: the other unknowns' conditional response
  if (reuse) {
    S = eliminated->M.transpose() * eliminated->M;
  } else {
    const Eigen::SparseMatrix<double> N = Eigen::SparseMatrix<double>(J.transpose()) * J;
    S = Eigen::MatrixXd(N.topLeftCorner(n_m, n_m));
    if (n_r > 0) {
      const Eigen::SparseMatrix<double> N_rr = N.bottomRightCorner(n_r, n_r);
      const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(N_rr);
      if (ldlt.info() != Eigen::Success) return out;
      const Eigen::MatrixXd N_rm = Eigen::MatrixXd(N.bottomLeftCorner(n_r, n_m));
      X = ldlt.solve(N_rm);
      S -= N_rm.transpose() * X;
    }
  }
  auto response = [&](const Eigen::VectorXd& d_m) -> Eigen::VectorXd {
    if (!reuse) return X * d_m;
    return eliminated->elimination->Solve(Eigen::MatrixXd(J.leftCols(n_m) * d_m));
  };
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
  std::vector<Eigen::VectorXd> deltas;  // per direction: + then -
  for (Eigen::Index k = first; k < n_m; ++k) {
    const double mu = std::max(eig.eigenvalues()[k], 0.0);
    const Eigen::VectorXd d_m = d.asDiagonal() * eig.eigenvectors().col(k) * std::sqrt(mu);
    Eigen::VectorXd delta(n);
    delta.head(n_m) = step_sigmas * d_m;
    if (n_r > 0) delta.tail(n_r) = -step_sigmas * response(d_m);
    deltas.push_back(delta);
    deltas.push_back(-delta);
  }
  const std::vector<double> chi2 = Chi2At(problem, columns, deltas, run_jobs);
  for (Eigen::Index k = first; k < n_m; ++k) {
    const auto at = static_cast<std::size_t>(2 * (k - first));
    const double plus = chi2[at] - chi2_0;
    const double minus = chi2[at + 1] - chi2_0;
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

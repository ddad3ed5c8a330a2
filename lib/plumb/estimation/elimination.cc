#include "plumb/estimation/elimination.h"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <utility>

#include "plumb/core/error.h"

namespace plumb::estimation {

Elimination::Elimination(const Eigen::SparseMatrix<double>& J, Eigen::Index first)
    : J_(J), first_(first), J_e_(J.rightCols(J.cols() - first)), scale_(J_e_.cols()) {
  for (Eigen::Index c = 0; c < J_e_.cols(); ++c) {
    const double norm = J_e_.col(c).norm();
    scale_[c] = norm > 0 ? 1.0 / norm : 1.0;
  }
  J_e_ = J_e_ * scale_.asDiagonal();
  ldlt_.compute(Eigen::SparseMatrix<double>(J_e_.transpose() * J_e_));
}

std::unique_ptr<Elimination> Elimination::Make(const Eigen::SparseMatrix<double>& J,
                                               Eigen::Index first, double min_pivot) {
  std::unique_ptr<Elimination> out(new Elimination(J, first));
  const auto& ldlt = out->ldlt_;
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > min_pivot)) return nullptr;
  return out;
}

Eigen::MatrixXd Elimination::ScaledSolve(const RowMajorMatrix& A) const {
  Eigen::MatrixXd X = ldlt_.solve(Eigen::MatrixXd(RowMajorMatrix(J_e_.transpose() * A)));
  RowMajorMatrix residual = A;
  residual.noalias() -= J_e_ * RowMajorMatrix(X);
  X += ldlt_.solve(Eigen::MatrixXd(RowMajorMatrix(J_e_.transpose() * residual)));  // refinement
  return X;
}

Eigen::MatrixXd Elimination::Solve(const Eigen::MatrixXd& A) const {
  return scale_.asDiagonal() * ScaledSolve(A);
}

Eigen::MatrixXd Elimination::Project(const Eigen::MatrixXd& A) const {
  RowMajorMatrix projected = A;
  projected.noalias() -= J_e_ * RowMajorMatrix(ScaledSolve(projected));
  return projected;
}

Eigen::MatrixXd Elimination::Reduced(const JobRunner& run_jobs) const {
  const Eigen::MatrixXd J_k = Eigen::MatrixXd(J_.leftCols(first_));
  if (!run_jobs || first_ < 2 * kReducedColumnsPerJob) return Project(J_k);
  // Column blocks at once: each column's products and solves are the same arithmetic
  // whatever the block it is in, so the result is the same bits.
  Eigen::MatrixXd M(J_k.rows(), J_k.cols());
  const Eigen::Index jobs = (first_ + kReducedColumnsPerJob - 1) / kReducedColumnsPerJob;
  RunJobs(run_jobs, static_cast<int>(jobs), [&](int job) {
    const Eigen::Index begin = job * kReducedColumnsPerJob;
    const Eigen::Index count = std::min(kReducedColumnsPerJob, first_ - begin);
    M.middleCols(begin, count) = Project(J_k.middleCols(begin, count));
  });
  return M;
}

Eigen::VectorXd Elimination::Leverage(const std::vector<Eigen::Index>& rows) const {
  // P_e e_i a panel of unit vectors at a time (memory: rows x panel).
  constexpr std::size_t kPanel = 256;
  Eigen::VectorXd out(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t at = 0; at < rows.size(); at += kPanel) {
    const std::size_t m = std::min(kPanel, rows.size() - at);
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(J_.rows(), static_cast<Eigen::Index>(m));
    for (std::size_t i = 0; i < m; ++i) E(rows[at + i], static_cast<Eigen::Index>(i)) = 1.0;
    const Eigen::MatrixXd P = E - Project(E);
    for (std::size_t i = 0; i < m; ++i) {
      out[static_cast<Eigen::Index>(at + i)] = P(rows[at + i], static_cast<Eigen::Index>(i));
    }
  }
  return out;
}

std::unique_ptr<Elimination> EliminatePoses(const Eigen::SparseMatrix<double>& J,
                                            Eigen::Index model_columns, Eigen::Index first_wander) {
  std::unique_ptr<Elimination> out;
  if (model_columns < J.cols()) out = Elimination::Make(J, model_columns, kEliminationPivot);
  if (out == nullptr && first_wander < J.cols()) {
    out = Elimination::Make(J, first_wander, 0.0);
    if (out == nullptr) {
      throw Error("the bias-wander states are not determined by their factors (their normal "
                  "matrix is not positive definite)");
    }
  }
  return out;
}

Eigen::Index LeadingModelColumns(const std::vector<bool>& is_model) {
  return static_cast<Eigen::Index>(std::find(is_model.begin(), is_model.end(), false) -
                                   is_model.begin());
}

Eigen::MatrixXd RangeBasis(const Eigen::MatrixXd& A, double tolerance) {
  if (A.cols() == 0 || A.rows() == 0) return Eigen::MatrixXd(A.rows(), 0);
  Eigen::MatrixXd scaled = A;
  for (Eigen::Index c = 0; c < A.cols(); ++c) {
    const double n = A.col(c).norm();
    if (n > 0.0) scaled.col(c) /= n;
  }
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinU);
  const Eigen::VectorXd& s = svd.singularValues();
  Eigen::Index rank = 0;
  while (rank < s.size() && s(rank) > tolerance * s(0) && s(rank) > 0.0) ++rank;
  return svd.matrixU().leftCols(rank);
}

JacobianRange::JacobianRange(Eigen::SparseMatrix<double> J, Eigen::Index model_columns,
                             Eigen::Index first_wander, double rank_tolerance)
    : J_(std::move(J)) {
  elimination_ = EliminatePoses(J_, model_columns, first_wander);
  M_ = elimination_ != nullptr ? elimination_->Reduced() : Eigen::MatrixXd(J_);
  Q_ = RangeBasis(M_, rank_tolerance);
}

JacobianRange::JacobianRange(const Eigen::MatrixXd& J, double rank_tolerance)
    : J_(J.sparseView(0.0, 0.0)), M_(J), Q_(RangeBasis(J, rank_tolerance)) {}

Eigen::MatrixXd JacobianRange::Residual(const Eigen::MatrixXd& Z) const {
  Eigen::MatrixXd R = elimination_ != nullptr ? elimination_->Project(Z) : Z;
  R -= Q_ * (Q_.transpose() * R);
  return R;
}

Eigen::VectorXd JacobianRange::Leverage(const std::vector<Eigen::Index>& rows) const {
  Eigen::VectorXd h = elimination_ != nullptr
                          ? elimination_->Leverage(rows)
                          : Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    h[static_cast<Eigen::Index>(i)] += Q_.row(rows[i]).squaredNorm();
  }
  return h;
}

Eigen::VectorXd JacobianRange::Coefficients(const Eigen::VectorXd& z) const {
  if (elimination_ == nullptr) return M_.completeOrthogonalDecomposition().solve(z);
  const Eigen::Index k = elimination_->first();
  // The kept unknowns from what the eliminated ones cannot absorb, then the eliminated ones
  // from what is left: the least-squares solution of J c ~ z, split by the Schur complement.
  const Eigen::VectorXd c_k = M_.completeOrthogonalDecomposition().solve(elimination_->Project(z));
  Eigen::VectorXd c(J_.cols());
  c.head(k) = c_k;
  c.tail(J_.cols() - k) = elimination_->Solve(z - J_.leftCols(k) * c_k);
  return c;
}

std::unique_ptr<JacobianRange> ProbeRange(const ProbeJacobian& probes, double rank_tolerance) {
  return std::make_unique<JacobianRange>(probes.J, LeadingModelColumns(probes.unknown_is_model),
                                         static_cast<Eigen::Index>(probes.first_wander),
                                         rank_tolerance);
}

}  // namespace plumb::estimation

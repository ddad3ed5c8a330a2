// plumb/estimation/elimination.h — the structure of a calibration's whitened Jacobian, used so
// that the analysis costs grow linearly in the poses.
//
// The unknowns are the model's parameters (a few dozen, in every residual), then per pose an
// attitude (3) and the bias-wander states (up to 24), each tied only to its neighbours by the
// motion residuals and the Markov factors. Split J = [J_k J_e] with J_e those per-pose
// columns: the projection onto their range, P_e = J_e (J_e^T J_e)^-1 J_e^T, needs only a
// sparse (banded, after ordering) LDL^T factorisation of J_e^T J_e, and
//
//   M = (I - P_e) J_k          (rows x kept columns, dense but narrow)
//
// carries everything the kept unknowns can still be told by: its SVD gives their rank, null
// space and marginal covariance (M^T M is the Schur complement of J^T J on them), and
// range(J) = range(J_e) + range(M), orthogonal. So the observability analysis (solve.h) and
// the score tests of diagnose (diagnostics/score_test.h) need a factorisation linear in the
// poses and an SVD of M, never an SVD over every unknown.
//
// INTERNAL to plumb::estimation (not installed; diagnostics and study include it in their
// sources): it holds Eigen's sparse Cholesky factor. score_test.h declares JacobianRange only.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "plumb/core/jobs.h"
#include "plumb/estimation/fit_report.h"

namespace plumb::estimation {

/// Smallest pivot of the column-scaled normal matrix of the per-pose columns (unit diagonal)
/// for them to be eliminated: their singular values are then above about 1e-5 of a unit
/// column, well inside what the corrected semi-normal equations resolve. Below it (e.g. an
/// attitude the data barely determine) the analysis keeps those columns and decides their
/// rank itself.
inline constexpr double kEliminationPivot = 1e-10;

/// Columns of M per job in Elimination::Reduced.
inline constexpr Eigen::Index kReducedColumnsPerJob = 6;

/// Columns [first, n) of a whitened Jacobian J = [J_k J_e], eliminated: the projection P_e onto
/// range(J_e) through the sparse LDL^T factor of D J_e^T J_e D (D scales J_e's columns to unit
/// norm), with one step of iterative refinement (the corrected semi-normal equations), which
/// keeps it as accurate as a QR of J_e.
class Elimination {
 public:
  /// Null when J_e's columns are not clearly independent (a pivot at or below `min_pivot`).
  /// `J` must outlive the result.
  static std::unique_ptr<Elimination> Make(const Eigen::SparseMatrix<double>& J,
                                           Eigen::Index first, double min_pivot);
  /// X minimising |A - J_e X| (the eliminated unknowns in J's units), for a dense A with J's rows.
  Eigen::MatrixXd Solve(const Eigen::MatrixXd& A) const;
  /// (I - P_e) A for a dense A with J's rows.
  Eigen::MatrixXd Project(const Eigen::MatrixXd& A) const;
  /// M = (I - P_e) J_k: rows x first; blocks of columns at once through `run_jobs` when given
  /// (core/jobs.h; the same bits either way).
  Eigen::MatrixXd Reduced(const JobRunner& run_jobs = {}) const;
  /// The diagonal of P_e at `rows`.
  Eigen::VectorXd Leverage(const std::vector<Eigen::Index>& rows) const;
  Eigen::Index first() const { return first_; }

 private:
  Elimination(const Eigen::SparseMatrix<double>& J, Eigen::Index first);
  /// Rows of a dense operand stored together: the sparse products with J_e then add whole
  /// rows at a time (one contiguous, vectorised update per nonzero of J_e) rather than one
  /// column after another; every entry sums the same terms in the same order either way.
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  /// X minimising |A - J_e X| in J_e's scaled units (one refinement step).
  Eigen::MatrixXd ScaledSolve(const RowMajorMatrix& A) const;

  const Eigen::SparseMatrix<double>& J_;
  Eigen::Index first_;
  Eigen::SparseMatrix<double> J_e_;  ///< J's eliminated columns, scaled to unit norm
  Eigen::VectorXd scale_;            ///< D
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_;
};

/// A sparse Jacobian with its per-pose columns eliminated, kept together (the elimination
/// refers to J; held by a pointer so that it stays where it is): the analysis's, reused by
/// the linearity check (linearity.h) for the Schur complement on the model's parameters and
/// the other unknowns' response.
struct EliminatedJacobian {
  Eigen::SparseMatrix<double> J;
  std::unique_ptr<Elimination> elimination;  ///< from column elimination->first()
  Eigen::MatrixXd M;                         ///< elimination->Reduced()
};

/// The per-pose columns of `J` eliminated: attitudes and wander together (from column
/// `model_columns`) when the data determine the attitudes clearly, else the wander alone (from
/// `first_wander`; throws plumb::Error when even they are not determined), else none (null).
std::unique_ptr<Elimination> EliminatePoses(const Eigen::SparseMatrix<double>& J,
                                            Eigen::Index model_columns, Eigen::Index first_wander);

/// The number of leading model-parameter columns of a calibration's Jacobian (its columns are
/// the model's parameters, then the attitudes, then the wander states: UnknownColumns).
Eigen::Index LeadingModelColumns(const std::vector<bool>& is_model);

/// Orthonormal basis of the range of A, its columns scaled to unit norm first, from the thin
/// SVD; singular values at or below `tolerance` times the largest (or zero) are dropped.
Eigen::MatrixXd RangeBasis(const Eigen::MatrixXd& A, double tolerance);

/// The range of a whitened Jacobian J, for projecting other columns off it and for
/// least-squares coefficients on it, factorised once (diagnose scores every candidate against
/// the same fit). Sparse J: the per-pose columns are eliminated (EliminatePoses); dense J:
/// the SVD of all of it.
class JacobianRange {
 public:
  /// `rank_tolerance`: relative singular value of the column-scaled M below which a direction
  /// is not in the range (the fit's rank tolerance), in (0, 1).
  JacobianRange(Eigen::SparseMatrix<double> J, Eigen::Index model_columns,
                Eigen::Index first_wander, double rank_tolerance);
  JacobianRange(const Eigen::MatrixXd& J, double rank_tolerance);
  JacobianRange(const JacobianRange&) = delete;  // the elimination refers to J_
  JacobianRange& operator=(const JacobianRange&) = delete;

  Eigen::Index rows() const { return J_.rows(); }
  Eigen::Index cols() const { return J_.cols(); }
  /// (I - P_J) Z: what of Z's columns the fit cannot absorb.
  Eigen::MatrixXd Residual(const Eigen::MatrixXd& Z) const;
  /// The least-squares coefficients c of J c ~ z, one per column of J.
  Eigen::VectorXd Coefficients(const Eigen::VectorXd& z) const;
  /// The leverages h_ii = J_i (J^T J)^+ J_i^T of the rows `rows`: the diagonal of the
  /// projector onto range(J), (P_e)_ii + |Q^T e_i|^2.
  Eigen::VectorXd Leverage(const std::vector<Eigen::Index>& rows) const;
  /// |J_k|, the norm of column k.
  double ColumnNorm(Eigen::Index k) const { return J_.col(k).norm(); }

 private:
  Eigen::SparseMatrix<double> J_;
  std::unique_ptr<Elimination> elimination_;  ///< null: M = J
  Eigen::MatrixXd M_;                         ///< (I - P_e) J_k
  Eigen::MatrixXd Q_;                         ///< orthonormal basis of range(M)
};

/// The range of a probe fit's Jacobian over its free unknowns (diagnose's score tests, the
/// studies' missing-effect sensitivities).
std::unique_ptr<JacobianRange> ProbeRange(const ProbeJacobian& probes, double rank_tolerance);

}  // namespace plumb::estimation

// plumb/estimation/observability.h — rank, covariance and unobservable directions of a
// whitened least-squares problem at its optimum (SPEC section 3).
//
// Given the whitened Jacobian J (m x n) with respect to the free tangent-space unknowns, the
// columns are scaled to unit norm (J D), a thin SVD J D = U S V^T is taken, and directions with
// s_i < rank_tolerance * s_max are the null space. Covariance is the pseudo-inverse restricted
// to the observed subspace, C = D V_r S_r^-2 V_r^T D, which for a full-rank problem equals
// (J^T J)^-1 (tests/estimation check this against ceres::Covariance). Column scaling makes the
// rank decision independent of units (raw counts next to radians); ceres::Covariance's
// DENSE_SVD truncation would act on the unscaled Jacobian, so the rank-deficient case is
// handled here.
//
// A column is unobservable when the null space has a component along it; null directions are
// reported in reduced row-echelon form over named unknowns ("9.78 accel.bias.z + 1
// accel.matrix.zz"), and within each group of model parameters joined by null directions the
// combinations orthogonal to them (the ones the data determines) are reported with value and
// sigma.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "plumb/estimation/calibration.h"

namespace plumb::estimation {

struct ObservabilityInput {
  Eigen::MatrixXd J;                 ///< whitened Jacobian, m x n
  std::vector<std::string> names;    ///< n names of the unknowns
  std::vector<double> values;        ///< n reported values (NaN for attitude increments)
  std::vector<bool> is_model;        ///< n flags: model parameter (true) or attitude (false)
  double rank_tolerance = 1e-9;      ///< relative singular-value threshold, (0, 1)
  /// Unknowns eliminated before the analysis (a Schur complement: J is then the part of the
  /// other columns their columns cannot absorb, solve.cc), which the data determines: each
  /// counts in the rank and the unknowns, and the null directions show their components.
  std::vector<std::string> eliminated_names;
  /// Their components in null directions: from directions over J's n columns (n x k, original
  /// units) to the eliminated unknowns' (eliminated_names.size() x k). Required when there
  /// are eliminated names.
  std::function<Eigen::MatrixXd(const Eigen::MatrixXd&)> eliminated_response;
};

struct ObservabilityAnalysis {
  Observability summary;
  Eigen::MatrixXd covariance;        ///< n x n (J's columns), pseudo-inverse on the observed subspace
  std::vector<bool> observable;      ///< n flags (J's columns), then true per eliminated unknown
  /// One column per null direction: the row-echelon pivot (model parameters first, then J's
  /// other columns, then the eliminated ones), a set of unknowns whose values, once held, make
  /// the rest observable.
  std::vector<int> pivots;
};

ObservabilityAnalysis AnalyseObservability(const ObservabilityInput& input);

/// Formats sum_i c_i name_i with 4 significant digits, dropping |c_i| < 1e-9 max|c|.
/// `show_unit_coefficients` prints "1 name" rather than "name".
std::string FormatCombination(const Eigen::VectorXd& c, const std::vector<std::string>& names,
                              bool show_unit_coefficients);

}  // namespace plumb::estimation

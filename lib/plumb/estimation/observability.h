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
// sigma. Combinations the data determine no better than their typical spread among MEMS IMUs
// (kWeakSpread) are found on the subspace the null directions leave invariant and reported
// apart as weakly determined; the fit holds them (solve.h).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "plumb/estimation/calibration.h"

namespace plumb::estimation {

/// A combination of model parameters is weakly determined when the data's sigma of it (scaled
/// by sqrt(chi^2/dof) where that is above its band, as the report scales every sigma) exceeds
/// this many times its typical size among MEMS IMUs (sqrt(sum c_i^2 typical_i^2),
/// model::ParameterInfo::typical): about a datasheet's limit (its worst case is a few typical
/// sizes), so the data then cannot place the combination within what the datasheet already
/// says, and a fit left free along it wanders (the AR.Drone bag's four holds in two orientations put accel.bias.x at
/// 4 m/s^2; six faces with free attitudes lie in a curved valley along them, NEES 1e5). A
/// combination known to two typical sizes is still a finding (real logs' time offsets of
/// 9 +- 2 ms against a typical 1 ms). Such combinations are held where the fit
/// starts (residuals/held_combination.h), reported apart, and a parameter whose own sigma
/// exceeds this many typical sizes is not reported as determined.
inline constexpr double kWeakSpread = 3.0;

struct ObservabilityInput {
  Eigen::MatrixXd J;                 ///< whitened Jacobian, m x n
  std::vector<std::string> names;    ///< n names of the unknowns
  std::vector<double> values;        ///< n reported values (NaN for attitude increments)
  std::vector<bool> is_model;        ///< n flags: model parameter (true) or attitude (false)
  double rank_tolerance = 1e-9;      ///< relative singular-value threshold, (0, 1)
  /// n typical sizes (model::ParameterInfo::typical, in the column's unit; ignored for the
  /// columns that are not model parameters), for the weak combinations; empty: none sought.
  std::vector<double> typical;
  /// For the weak combinations' sigma scale: the fit's chi^2 and residual count (0: no
  /// scaling), and its bias-wander states that are not among J's columns (they take degrees
  /// of freedom too).
  double chi2 = 0.0;
  int observations = 0;
  int wander_outside = 0;
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
  /// The weakly determined combinations (kWeakSpread), as coefficients over J's columns (zero
  /// off the model's), in summary.weakly_determined's order: to hold where they start.
  std::vector<Eigen::VectorXd> weak;
};

ObservabilityAnalysis AnalyseObservability(const ObservabilityInput& input);

/// Formats sum_i c_i name_i with 4 significant digits, dropping |c_i| < 1e-9 max|c|.
/// `show_unit_coefficients` prints "1 name" rather than "name".
std::string FormatCombination(const Eigen::VectorXd& c, const std::vector<std::string>& names,
                              bool show_unit_coefficients);

}  // namespace plumb::estimation

// plumb/diagnostics/score_test.h — the score (Lagrange multiplier) test of SPEC section 5: how
// much would chi^2 fall if an effect were added, computed at the current optimum without a
// refit.
//
// With r the whitened residuals at the optimum, J their Jacobian over the fit's free unknowns
// and Z over the candidate's parameters at zero (all whitened):
//
//   P  = I - J (J^T J)^+ J^T            (projection away from what the fit can already absorb)
//   LM = r^T P Z (Z^T P Z)^+ Z^T P r     (the predicted fall of chi^2 if the effect is added)
//
// Under "not missing", LM is chi^2 with q degrees of freedom, q the rank of P Z. P is formed from
// the column-scaled J's singular vectors whose singular values exceed `rank_tolerance` times the
// largest (the fit's unobservable directions are not counted twice).
//
// Identifiability: column j of Z (parameter typical size s_j) is identifiable when
//   - the data excites it: |Z_j| s_j >= excitation_floor;
//   - the fit cannot absorb it: |P Z_j| >= identifiable_ratio |Z_j|; otherwise it is
//     confounded with the fit's unknowns whose columns make up most of Z_j in the
//     least-squares fit Z_j ~ J c (named with their share of |J c|);
//   - the data determines it better than its typical size: 1 / |P Z_j| (the sigma the
//     parameter alone would get) is below s_j / detectable_ratio; otherwise a typical-size effect
//     would hide in the noise and "not significant" would not mean "absent".
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace plumb::estimation {
/// The fit's Jacobian factorised once (estimation/elimination.h, internal to the library: it
/// holds Eigen's sparse Cholesky factor, which this header does not bring along).
class JacobianRange;
}  // namespace plumb::estimation

namespace plumb::diagnostics {

struct ScoreTestOptions {
  /// Relative singular-value threshold of the column-scaled J below which a direction is not
  /// in its range (the fit's rank tolerance), in (0, 1).
  double rank_tolerance = 1e-9;
  /// A candidate column is identifiable when |P Z_j| / |Z_j| is at least this, in (0, 1).
  double identifiable_ratio = 1e-3;
  /// A column is "not excited" when |Z_j| (whitened: residual sigmas per unit parameter) times
  /// the parameter's typical size is below this, >= 0: an effect of typical size would move
  /// the residuals by less than this many sigma in all (e.g. a lever arm seen only through
  /// Earth rate on still data).
  double excitation_floor = 1e-3;
  /// A column is too weakly determined when |P Z_j| s_j is below this, >= 0: the data would
  /// give the parameter a sigma above s_j / detectable_ratio.
  double detectable_ratio = 1.0;
  /// How many of the fit's unknowns to name as confounders per column, >= 1.
  int max_confounders = 3;
};

/// One column of Z that the data cannot separate from the fit.
struct Confounding {
  std::string parameter;                  ///< the candidate's parameter, e.g. "time_offset.dt"
  bool excited = true;                    ///< false: the data does not move the prediction
  double ratio = 0.0;                     ///< |P Z_j| / |Z_j|, in [0, 1]
  /// The sigma the data would give the parameter, 1 / |P Z_j|, its unit; infinite when 0.
  double sigma = 0.0;
  double typical = 0.0;                   ///< the parameter's typical size, its unit
  /// The unit of sigma and typical (the catalogue's, e.g. "rad/s"); empty where the fit's
  /// data are in sensor units and the catalogue's unit does not apply.
  std::string unit;
  /// Excited and not confounded, but determined only to more than its typical size.
  bool too_weak = false;
  std::vector<std::string> confounders;   ///< the fit's unknowns that absorb it, most first
  std::vector<double> shares;             ///< their shares of |J c|, in (0, 1]
};

struct ScoreTestResult {
  double lm = 0.0;        ///< predicted fall of chi^2, >= 0
  int dof = 0;            ///< q: rank of P Z (identifiable directions)
  int num_parameters = 0; ///< columns of Z
  bool identifiable = true;  ///< every column identifiable
  std::vector<Confounding> not_identifiable;  ///< the columns that are not
  /// Orthonormal basis of the range of P Z (its identifiable columns): the directions of
  /// residual space that only this candidate explains (rows x dof).
  Eigen::MatrixXd basis;
};

/// The score test for one candidate against the fit's Jacobian `J`, factorised once for all
/// candidates of the same fit (estimation/elimination.h: the per-pose unknowns eliminated; P
/// is formed from it with the rank tolerance it was built with). `z_names` name Z's columns;
/// `z_typical` their typical sizes (same order, > 0); `j_names` name J's columns. Throws
/// plumb::Error on size mismatches.
ScoreTestResult ScoreTest(const Eigen::VectorXd& r, const estimation::JacobianRange& J,
                          const Eigen::MatrixXd& Z, const std::vector<std::string>& j_names,
                          const std::vector<std::string>& z_names,
                          const std::vector<double>& z_typical,
                          const ScoreTestOptions& options = {});
/// The same with a dense J, factorised here with options.rank_tolerance.
ScoreTestResult ScoreTest(const Eigen::VectorXd& r, const Eigen::MatrixXd& J,
                          const Eigen::MatrixXd& Z, const std::vector<std::string>& j_names,
                          const std::vector<std::string>& z_names,
                          const std::vector<double>& z_typical,
                          const ScoreTestOptions& options = {});

}  // namespace plumb::diagnostics

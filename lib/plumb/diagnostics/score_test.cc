// plumb/diagnostics/score_test.cc — see score_test.h.
#include "plumb/diagnostics/score_test.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "plumb/core/error.h"
#include "plumb/estimation/elimination.h"

namespace plumb::diagnostics {
ScoreTestResult ScoreTest(const Eigen::VectorXd& r, const Eigen::MatrixXd& J,
                          const Eigen::MatrixXd& Z, const std::vector<std::string>& j_names,
                          const std::vector<std::string>& z_names,
                          const std::vector<double>& z_typical, const ScoreTestOptions& options) {
  if (J.rows() != r.size()) throw Error("ScoreTest: r, J and Z must have the same number of rows");
  const estimation::JacobianRange range(J, options.rank_tolerance);
  return ScoreTest(r, range, Z, j_names, z_names, z_typical, options);
}

ScoreTestResult ScoreTest(const Eigen::VectorXd& r, const estimation::JacobianRange& J,
                          const Eigen::MatrixXd& Z, const std::vector<std::string>& j_names,
                          const std::vector<std::string>& z_names,
                          const std::vector<double>& z_typical, const ScoreTestOptions& options) {
  if (J.rows() != r.size() || Z.rows() != r.size()) {
    throw Error("ScoreTest: r, J and Z must have the same number of rows");
  }
  if (static_cast<Eigen::Index>(j_names.size()) != J.cols() ||
      static_cast<Eigen::Index>(z_names.size()) != Z.cols() || z_typical.size() != z_names.size()) {
    throw Error("ScoreTest: one name (and typical size) per column of J and Z");
  }
  ScoreTestResult out;
  out.num_parameters = static_cast<int>(Z.cols());
  const Eigen::MatrixXd PZ = J.Residual(Z);

  // Identifiability, column by column.
  std::vector<Eigen::Index> usable;
  for (Eigen::Index j = 0; j < Z.cols(); ++j) {
    const double z = Z.col(j).norm();
    const double pz = PZ.col(j).norm();
    const double typical = z_typical[static_cast<std::size_t>(j)];
    const bool excited = z * typical > options.excitation_floor;
    const double ratio = z > 0.0 ? pz / z : 0.0;
    const bool separate = ratio >= options.identifiable_ratio;
    const bool strong = pz * typical >= options.detectable_ratio;
    if (excited && separate && strong) {
      usable.push_back(j);
      continue;
    }
    Confounding c;
    c.parameter = z_names[static_cast<std::size_t>(j)];
    c.excited = excited;
    c.ratio = ratio;
    c.sigma = pz > 0.0 ? 1.0 / pz : std::numeric_limits<double>::infinity();
    c.typical = typical;
    c.too_weak = excited && separate && !strong;
    if (excited && !separate && J.cols() > 0) {
      // Z_j ~ J coef: which unknowns make up the part of Z_j that the fit absorbs.
      const Eigen::VectorXd coef = J.Coefficients(Z.col(j));
      std::vector<double> part(static_cast<std::size_t>(J.cols()));
      for (Eigen::Index k = 0; k < J.cols(); ++k) {
        part[static_cast<std::size_t>(k)] = std::abs(coef(k)) * J.ColumnNorm(k);
      }
      const double total = std::accumulate(part.begin(), part.end(), 0.0);
      std::vector<std::size_t> order(part.size());
      std::iota(order.begin(), order.end(), 0);
      std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return part[a] > part[b]; });
      for (std::size_t k = 0; k < order.size() && static_cast<int>(k) < options.max_confounders; ++k) {
        if (total <= 0.0 || part[order[k]] < 0.05 * total) break;
        c.confounders.push_back(j_names[order[k]]);
        c.shares.push_back(part[order[k]] / total);
      }
    }
    out.not_identifiable.push_back(c);
  }
  out.identifiable = out.not_identifiable.empty();

  // LM on the identifiable columns: the squared norm of r projected onto the range of P Z.
  if (!usable.empty()) {
    Eigen::MatrixXd PZu(PZ.rows(), static_cast<Eigen::Index>(usable.size()));
    for (std::size_t k = 0; k < usable.size(); ++k) PZu.col(static_cast<Eigen::Index>(k)) = PZ.col(usable[k]);
    const Eigen::MatrixXd B = estimation::RangeBasis(PZu, options.identifiable_ratio);
    out.dof = static_cast<int>(B.cols());
    out.lm = (B.transpose() * r).squaredNorm();
    out.basis = B;
  }
  return out;
}

}  // namespace plumb::diagnostics

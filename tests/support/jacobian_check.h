// tests/support/jacobian_check.h — one call that checks a cost function's Jacobians, in the
// tangent spaces of its manifolds, against central differences taken through the manifolds'
// Plus.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace plumb::testing {

/// Largest ||J_analytic - J_numeric||_F / max(1e-12, ||J_numeric||_F) over the blocks, the
/// numeric Jacobian by central differences with step `step` * max(1, |x_j|) per tangent
/// coordinate. Norm-relative, so entries that are zero in exact arithmetic do not dominate.
/// `manifolds[b]` may be null (Euclidean block).
inline double JacobianError(const ceres::CostFunction& cost,
                            const std::vector<const double*>& parameters,
                            const std::vector<const ceres::Manifold*>& manifolds,
                            double step = 1e-6) {
  const int m = cost.num_residuals();
  const auto& sizes = cost.parameter_block_sizes();
  const std::size_t nb = sizes.size();
  std::vector<Eigen::MatrixXd> ambient(nb);
  std::vector<double*> jac(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    ambient[b] = Eigen::MatrixXd::Zero(m, sizes[b]);
    jac[b] = ambient[b].data();
  }
  // Row-major Jacobians, as Ceres writes them: evaluate into transposed storage.
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> rm(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    rm[b].resize(m, sizes[b]);
    jac[b] = rm[b].data();
  }
  Eigen::VectorXd r0(m);
  cost.Evaluate(parameters.data(), r0.data(), jac.data());

  double worst = 0.0;
  std::vector<std::vector<double>> copies(nb);
  for (std::size_t b = 0; b < nb; ++b) copies[b].assign(parameters[b], parameters[b] + sizes[b]);
  for (std::size_t b = 0; b < nb; ++b) {
    const ceres::Manifold* mf = manifolds[b];
    const int tangent = mf ? mf->TangentSize() : sizes[b];
    Eigen::MatrixXd plus_jacobian = Eigen::MatrixXd::Identity(sizes[b], tangent);
    if (mf) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> P(sizes[b], tangent);
      mf->PlusJacobian(parameters[b], P.data());
      plus_jacobian = P;
    }
    const Eigen::MatrixXd analytic = Eigen::MatrixXd(rm[b]) * plus_jacobian;
    Eigen::MatrixXd numeric(m, tangent);
    for (int j = 0; j < tangent; ++j) {
      const double h = step * (mf ? 1.0 : std::max(1.0, std::abs(parameters[b][j])));
      Eigen::VectorXd rp(m), rn(m);
      for (int sign : {+1, -1}) {
        Eigen::VectorXd delta = Eigen::VectorXd::Zero(tangent);
        delta[j] = sign * h;
        std::vector<double> moved(static_cast<std::size_t>(sizes[b]));
        if (mf) {
          mf->Plus(parameters[b], delta.data(), moved.data());
        } else {
          for (int i = 0; i < sizes[b]; ++i) moved[static_cast<std::size_t>(i)] = parameters[b][i] + delta[i];
        }
        std::vector<const double*> p = parameters;
        p[b] = moved.data();
        cost.Evaluate(p.data(), sign > 0 ? rp.data() : rn.data(), nullptr);
      }
      numeric.col(j) = (rp - rn) / (2 * h);
    }
    worst = std::max(worst, (analytic - numeric).norm() / std::max(1e-12, numeric.norm()));
  }
  return worst;
}

}  // namespace plumb::testing

// tests/support/jacobian_check.h — one call that checks a cost function's Jacobians (in the
// tangent spaces of its manifolds) against central numeric differences.
#pragma once

#include <ceres/gradient_checker.h>

#include <algorithm>
#include <vector>

namespace plumb::testing {

/// Largest ||J_analytic - J_numeric||_F / max(1e-12, ||J_numeric||_F) over the blocks.
/// Norm-relative, so entries that are zero in exact arithmetic (numeric noise 1e-14) do not
/// dominate, as they do in GradientChecker's per-entry relative error.
inline double JacobianError(const ceres::CostFunction& cost,
                            const std::vector<const double*>& parameters,
                            const std::vector<const ceres::Manifold*>& manifolds) {
  ceres::NumericDiffOptions numeric;
  numeric.relative_step_size = 1e-6;  // GradientChecker uses central differences
  ceres::GradientChecker checker(&cost, &manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(parameters.data(), 1.0, &results);
  double worst = 0.0;
  for (std::size_t b = 0; b < results.local_jacobians.size(); ++b) {
    const auto& a = results.local_jacobians[b];
    const auto& n = results.local_numeric_jacobians[b];
    worst = std::max(worst, (a - n).norm() / std::max(1e-12, n.norm()));
  }
  return worst;
}

}  // namespace plumb::testing

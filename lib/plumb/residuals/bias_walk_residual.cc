#include "plumb/residuals/bias_walk_residual.h"

#include <ceres/autodiff_cost_function.h>

namespace plumb::residuals {

ceres::CostFunction* BiasWalkResidual::Create(const Vec3& inv_sigma, double phi) {
  return new ceres::AutoDiffCostFunction<BiasWalkResidual, 3, 3, 3>(
      new BiasWalkResidual(inv_sigma, phi));
}

ceres::CostFunction* BiasWalkResidual::CreateAnchor(const Vec3& inv_sigma) {
  return new ceres::AutoDiffCostFunction<BiasWalkResidual, 3, 3>(new BiasWalkResidual(inv_sigma));
}

}  // namespace plumb::residuals

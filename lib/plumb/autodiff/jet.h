// plumb/autodiff/jet.h — the one Jet type of plumb's automatic differentiation.
//
// Every dynamic autodiff cost function in plumb (plumb/residuals) and every effect's term on
// Jets (differentiable_effect.h) use Jet: value plus kJetStride derivatives, Ceres's forward
// mode (ceres/jet.h). DynamicAutoDiffCostFunction<Functor, kJetStride> evaluates a residual's
// parameters kJetStride at a time.
#pragma once

#include <ceres/jet.h>

namespace plumb::autodiff {

/// Derivatives carried by one Jet pass.
inline constexpr int kJetStride = 8;
using Jet = ceres::Jet<double, kJetStride>;

}  // namespace plumb::autodiff

// plumb/residuals/held_combination.h — a linear combination of parameters held at its start.
//
// Where the data determine a combination of model parameters c^T theta no better than a MEMS
// IMU's typical spread of it (estimation/observability.h, "weakly determined"), the fit holds
// it where it started (the nominal values) instead of letting the solver wander along it:
//
//   r = (sum_k c_k (theta_k - theta0_k)) / width                     (1 value, dimensionless)
//
// theta_k a value of one of the parameter blocks, c_k its coefficient (the combination's,
// in the parameters' own units), theta0_k its start value, and `width` far below the data's
// own sigma of the combination, so that r holds it where a parameter held constant would be
// held: the data cannot move it measurably, and the other parameters' covariance is the one
// conditional on it. Unlike holding one parameter of the combination, this leaves every
// combination uncorrelated with it where the data put it.
//
// Parameter blocks: those that hold a term of the combination, in the order given; the
// Jacobian is constant (c_k / width at each term's place).
#pragma once

#include <ceres/cost_function.h>

#include <vector>

namespace plumb::residuals {

/// One term of a held combination: value `index` of parameter block `block` (an index into
/// the blocks given to HeldCombination), its coefficient and its start value.
struct HeldTerm {
  int block = 0;
  int index = 0;
  double coefficient = 0.0;
  double start = 0.0;
};

class HeldCombination final : public ceres::CostFunction {
 public:
  /// `block_sizes`: the sizes of the blocks the terms index; `width` > 0, in the
  /// combination's units.
  HeldCombination(std::vector<int> block_sizes, std::vector<HeldTerm> terms, double width);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::vector<HeldTerm> terms_;
  double inv_width_ = 1.0;
};

}  // namespace plumb::residuals

#include "plumb/residuals/held_combination.h"

#include <algorithm>
#include <utility>

namespace plumb::residuals {

HeldCombination::HeldCombination(std::vector<int> block_sizes, std::vector<HeldTerm> terms,
                                 double width)
    : terms_(std::move(terms)), inv_width_(1.0 / width) {
  set_num_residuals(1);
  *mutable_parameter_block_sizes() = std::move(block_sizes);
}

bool HeldCombination::Evaluate(double const* const* parameters, double* residuals,
                               double** jacobians) const {
  double r = 0.0;
  for (const HeldTerm& t : terms_) r += t.coefficient * (parameters[t.block][t.index] - t.start);
  residuals[0] = r * inv_width_;
  if (jacobians == nullptr) return true;
  const std::vector<int>& sizes = parameter_block_sizes();
  for (std::size_t b = 0; b < sizes.size(); ++b) {
    if (jacobians[b] != nullptr) std::fill(jacobians[b], jacobians[b] + sizes[b], 0.0);
  }
  for (const HeldTerm& t : terms_) {
    if (jacobians[t.block] != nullptr) jacobians[t.block][t.index] += t.coefficient * inv_width_;
  }
  return true;
}

}  // namespace plumb::residuals

#include "plumb/estimation/parallel_evaluation.h"

#include <algorithm>

namespace plumb::estimation {

void ParallelEvaluation::Add(const residuals::CachedCostFunction* cost,
                             std::vector<double*> blocks, double work) {
  Item item{cost, std::move(blocks), work};
  const auto at = std::upper_bound(items_.begin(), items_.end(), item,
                                   [](const Item& a, const Item& b) { return a.work > b.work; });
  items_.insert(at, std::move(item));
}

void ParallelEvaluation::PrepareForEvaluation(bool evaluate_jacobians,
                                              bool new_evaluation_point) {
  // The values have not moved since the last call (Ceres says so): nothing to do unless
  // Jacobians are asked for now and were not then.
  if (prepared_ && !new_evaluation_point && (prepared_jacobians_ || !evaluate_jacobians)) return;
  prepared_ = true;
  prepared_jacobians_ = evaluate_jacobians;
  // Ceres asks for the Jacobians of the blocks that are not constant (a kept evaluation
  // with other Jacobians than asked is not used: CachedCostFunction::Evaluate).
  std::vector<std::vector<bool>> wanted(items_.size());
  for (std::size_t i = 0; i < items_.size(); ++i) {
    if (!evaluate_jacobians || problem_ == nullptr) continue;
    for (double* block : items_[i].blocks) {
      wanted[i].push_back(!problem_->IsParameterBlockConstant(block));
    }
  }
  // Only the blocks whose kept evaluation is not this one (Ceres also calls this before it
  // evaluates single blocks, at the values of the last pass).
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < items_.size(); ++i) {
    if (items_[i].cost->NeedsPrecompute(items_[i].blocks.data(), wanted[i])) todo.push_back(i);
  }
  if (todo.empty()) return;
  RunJobs(run_jobs_, static_cast<int>(todo.size()), [&](int job) {
    const std::size_t k = todo[static_cast<std::size_t>(job)];
    items_[k].cost->Precompute(items_[k].blocks.data(), wanted[k]);
  });
}

}  // namespace plumb::estimation

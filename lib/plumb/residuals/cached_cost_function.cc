#include "plumb/residuals/cached_cost_function.h"

#include <algorithm>
#include <cstring>

namespace plumb::residuals {

namespace {

/// `wanted` as one flag per block (missing flags false).
std::vector<bool> Wanted(const std::vector<bool>& wanted, std::size_t blocks) {
  std::vector<bool> want(blocks, false);
  for (std::size_t j = 0; j < std::min(blocks, wanted.size()); ++j) want[j] = wanted[j];
  return want;
}

}  // namespace

bool CachedCostFunction::KeptAt(double const* const* parameters) const {
  if (!kept_.valid) return false;
  const std::vector<int>& sizes = parameter_block_sizes();
  std::size_t at = 0;
  for (std::size_t j = 0; j < sizes.size(); ++j) {
    const auto bytes = static_cast<std::size_t>(sizes[j]) * sizeof(double);
    if (std::memcmp(kept_.values.data() + at, parameters[j], bytes) != 0) return false;
    at += static_cast<std::size_t>(sizes[j]);
  }
  return true;
}

bool CachedCostFunction::NeedsPrecompute(double const* const* parameters,
                                         const std::vector<bool>& wanted) const {
  if (!kept_.valid) return true;
  for (std::size_t j = 0; j < kept_.wanted.size(); ++j) {
    if (kept_.wanted[j] != (j < wanted.size() && wanted[j])) return true;
  }
  return !KeptAt(parameters);
}

void CachedCostFunction::Precompute(double const* const* parameters,
                                    const std::vector<bool>& wanted) const {
  if (!NeedsPrecompute(parameters, wanted)) return;
  const std::vector<int>& sizes = parameter_block_sizes();
  const std::size_t n = sizes.size();
  const std::vector<bool> want = Wanted(wanted, n);
  kept_.valid = false;
  kept_.values.clear();
  for (std::size_t j = 0; j < n; ++j) {
    kept_.values.insert(kept_.values.end(), parameters[j], parameters[j] + sizes[j]);
  }
  const auto m = static_cast<std::size_t>(num_residuals());
  kept_.residuals.assign(m, 0.0);
  std::size_t jacobian_values = 0;
  for (std::size_t j = 0; j < n; ++j) {
    if (want[j]) jacobian_values += m * static_cast<std::size_t>(sizes[j]);
  }
  kept_.jacobians.assign(jacobian_values, 0.0);
  std::vector<double*> blocks(n, nullptr);
  bool any = false;
  for (std::size_t j = 0, at = 0; j < n; ++j) {
    if (!want[j]) continue;
    blocks[j] = kept_.jacobians.data() + at;
    at += m * static_cast<std::size_t>(sizes[j]);
    any = true;
  }
  kept_.wanted = want;
  try {
    kept_.ok = EvaluateUncached(parameters, kept_.residuals.data(), any ? blocks.data() : nullptr);
    kept_.valid = true;
  } catch (...) {
    // Not kept: Ceres's own call evaluates again, on its thread, and the error surfaces there.
  }
}

bool CachedCostFunction::Matches(double const* const* parameters, double** jacobians) const {
  if (!kept_.valid) return false;
  for (std::size_t j = 0; j < kept_.wanted.size(); ++j) {
    const bool asked = jacobians != nullptr && jacobians[j] != nullptr;
    if (asked != kept_.wanted[j]) return false;
  }
  return KeptAt(parameters);
}

bool CachedCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  if (!Matches(parameters, jacobians)) {
    misses_.fetch_add(1, std::memory_order_relaxed);
    return EvaluateUncached(parameters, residuals, jacobians);
  }
  hits_.fetch_add(1, std::memory_order_relaxed);
  if (!kept_.ok) return false;
  std::copy(kept_.residuals.begin(), kept_.residuals.end(), residuals);
  const std::vector<int>& sizes = parameter_block_sizes();
  const auto m = static_cast<std::size_t>(num_residuals());
  std::size_t at = 0;
  for (std::size_t j = 0; j < sizes.size(); ++j) {
    if (!kept_.wanted[j]) continue;
    const std::size_t count = m * static_cast<std::size_t>(sizes[j]);
    std::copy_n(kept_.jacobians.data() + at, count, jacobians[j]);
    at += count;
  }
  return true;
}

}  // namespace plumb::residuals

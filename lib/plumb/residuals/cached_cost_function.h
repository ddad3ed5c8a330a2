// plumb/residuals/cached_cost_function.h — a cost function whose evaluation can be made ahead
// of Ceres's call, on another thread, and handed out when Ceres asks for the same thing.
//
// Ceres evaluates the residual blocks of a problem one after another (plumb sets no Ceres
// threads: Ceres's threads sum the cost in an order that varies from run to run). The costly
// blocks (the motion residuals, one pass over an interval's samples each) derive from this
// class; estimation::ParallelEvaluation, a ceres::EvaluationCallback, calls Precompute on all
// of them at once before each of Ceres's evaluation passes, and Evaluate then copies what
// was kept. A kept evaluation is used only when it was made at bit-identical parameter
// values with the same Jacobian blocks asked for, so the result is the same bits as the
// direct evaluation; anything else is evaluated directly.
#pragma once

#include <ceres/cost_function.h>

#include <atomic>
#include <vector>

namespace plumb::residuals {

class CachedCostFunction : public ceres::CostFunction {
 public:
  /// Evaluates at `parameters`, with the Jacobian of block j when wanted[j] (`wanted` empty:
  /// none), and keeps the result for Evaluate. Nothing is done when the kept evaluation is
  /// already that one. Distinct objects may precompute at once; one object must not be
  /// precomputed while Ceres evaluates it. Throws nothing (an evaluation that throws is not
  /// kept).
  void Precompute(double const* const* parameters, const std::vector<bool>& wanted) const;
  /// Whether Precompute would evaluate (what is kept is not that evaluation).
  bool NeedsPrecompute(double const* const* parameters, const std::vector<bool>& wanted) const;

  /// The kept evaluation when it matches (see above), else EvaluateUncached. Leaves what is
  /// kept as it is (only the counters below move).
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const final;

  /// Kept evaluations handed out, and evaluations made directly (for tests and benchmarks).
  long hits() const { return hits_.load(std::memory_order_relaxed); }
  long misses() const { return misses_.load(std::memory_order_relaxed); }

 protected:
  /// The cost function's own evaluation (ceres::CostFunction::Evaluate's contract).
  virtual bool EvaluateUncached(double const* const* parameters, double* residuals,
                                double** jacobians) const = 0;

 private:
  /// The kept evaluation was made at exactly these values.
  bool KeptAt(double const* const* parameters) const;
  /// ... and with exactly the Jacobian blocks `jacobians` asks for.
  bool Matches(double const* const* parameters, double** jacobians) const;

  struct Kept {
    bool valid = false;
    bool ok = false;                  ///< what EvaluateUncached returned
    std::vector<double> values;       ///< the parameter blocks, one after another
    std::vector<bool> wanted;         ///< per block: its Jacobian was evaluated
    std::vector<double> residuals;
    std::vector<double> jacobians;    ///< the wanted blocks' Jacobians, row-major, in order
  };
  mutable Kept kept_;
  mutable std::atomic<long> hits_{0}, misses_{0};
};

}  // namespace plumb::residuals

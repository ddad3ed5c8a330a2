// plumb/estimation/parallel_evaluation.h — the costly residual blocks of a problem (its
// motion residuals) evaluated at once, through CalibrationOptions::run_jobs, before each of
// Ceres's evaluation passes (a ceres::EvaluationCallback). Ceres then evaluates the blocks
// one after another as always and takes each motion residual's value and Jacobians from what
// was precomputed (residuals/cached_cost_function.h): the fit is the same bit for bit with
// and without threads.
//
// INTERNAL to plumb::estimation (not installed): a piece of calibration_problem.h.
#pragma once

#include <ceres/evaluation_callback.h>
#include <ceres/problem.h>

#include <vector>

#include "plumb/core/jobs.h"
#include "plumb/residuals/cached_cost_function.h"

namespace plumb::estimation {

class ParallelEvaluation final : public ceres::EvaluationCallback {
 public:
  explicit ParallelEvaluation(JobRunner run_jobs) : run_jobs_(std::move(run_jobs)) {}

  /// The problem whose blocks are added (which of their Jacobians Ceres asks for follows
  /// from which parameter blocks are constant in it).
  void SetProblem(const ceres::Problem* problem) { problem_ = problem; }
  /// A residual block of the problem, with its parameter blocks in its order, and the work
  /// of evaluating it (e.g. its samples): the largest are started first, so that the threads
  /// finish together.
  void Add(const residuals::CachedCostFunction* cost, std::vector<double*> blocks,
           double work);

  /// Precomputes every added block at the problem's current values (Ceres has written them
  /// to the parameter blocks before it calls this), with the Jacobians Ceres will ask for.
  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;

 private:
  struct Item {
    const residuals::CachedCostFunction* cost;
    std::vector<double*> blocks;
    double work;
  };
  JobRunner run_jobs_;
  const ceres::Problem* problem_ = nullptr;
  std::vector<Item> items_;  ///< largest work first
  bool prepared_ = false;            ///< PrepareForEvaluation has run
  bool prepared_jacobians_ = false;  ///< its last run asked for Jacobians
};

}  // namespace plumb::estimation

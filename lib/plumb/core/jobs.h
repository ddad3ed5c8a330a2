// plumb/core/jobs.h — the hook through which a front end lets the library run independent
// jobs at once. The library starts no thread itself: where a hook is empty, the jobs run one
// after another, and the results are the same bit for bit either way (each job writes only
// its own result).
#pragma once

#include <functional>

namespace plumb {

/// Runs job(0), ..., job(count - 1), in any order and on any threads, and returns when all
/// are done. The jobs throw nothing.
using JobRunner = std::function<void(int count, const std::function<void(int)>& job)>;

/// Runs the jobs through `run_jobs`, or one after another when it is empty.
inline void RunJobs(const JobRunner& run_jobs, int count, const std::function<void(int)>& job) {
  if (run_jobs) {
    run_jobs(count, job);
    return;
  }
  for (int i = 0; i < count; ++i) job(i);
}

}  // namespace plumb

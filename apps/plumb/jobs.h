// apps/plumb/jobs.h — independent jobs run at once on OpenMP threads, for the library's
// run_jobs hooks (diagnostics::DiagnoseOptions::run_jobs). The library starts no thread.
#pragma once

#include <functional>

namespace plumb::cli {

/// Runs job(0), ..., job(count - 1) on at most `jobs` threads (0: every core), each job on
/// one thread, taken in order as threads come free. The jobs must not throw.
using JobRunner = std::function<void(int count, const std::function<void(int)>& job)>;
JobRunner ParallelJobs(int jobs);

}  // namespace plumb::cli

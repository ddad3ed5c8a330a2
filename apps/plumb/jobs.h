// apps/plumb/jobs.h — independent jobs run at once on OpenMP threads, for the library's
// run_jobs hooks (core/jobs.h: estimation::CalibrationOptions::run_jobs,
// diagnostics::DiagnoseOptions::run_jobs). The library starts no thread.
#pragma once

#include "plumb/core/jobs.h"

namespace plumb::cli {

/// Runs job(0), ..., job(count - 1) on at most `jobs` threads (0: every core), each job on
/// one thread, taken in order as threads come free; empty (one job after another, and the
/// library's choices for one thread: e.g. a .bin read in one part) when that is one thread.
/// The jobs must not throw. Inside another runner's job (diagnose's refits, each fitting with
/// its own runner) the jobs run on the job's thread: OpenMP keeps nested regions to one thread.
///
/// The first runner with more than one thread starts OpenMP's threads and binds each to its
/// own CPU of those the process may use, the calling thread to the one it is on (jobs.cc says
/// why), unless OMP_PROC_BIND, OMP_PLACES or GOMP_CPU_AFFINITY is set: OpenMP then places
/// them as those say.
JobRunner ParallelJobs(int jobs);

/// The CPUs this process may use (counted once, before any thread is bound to one): what
/// `--jobs 0` means.
int Cores();

}  // namespace plumb::cli

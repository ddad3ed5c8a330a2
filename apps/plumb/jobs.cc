#include "jobs.h"

#include <omp.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <vector>

namespace plumb::cli {
namespace {

/// True when the user steers where OpenMP's threads run (OMP_PROC_BIND, OMP_PLACES or
/// GOMP_CPU_AFFINITY in the environment): libgomp then places them, and PlaceThreads does not.
bool PlacementGivenByUser() {
  for (const char* name : {"OMP_PROC_BIND", "OMP_PLACES", "GOMP_CPU_AFFINITY"}) {
    if (std::getenv(name) != nullptr) return true;
  }
  return false;
}

/// The CPUs this process may run on, the calling thread's own first (so that it stays there).
std::vector<int> AllowedCpus() {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return {};
  std::vector<int> cpus;
  const int current = sched_getcpu();
  if (current >= 0 && CPU_ISSET(current, &allowed)) cpus.push_back(current);
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed) && cpu != current) cpus.push_back(cpu);
  }
  return cpus;
}

/// Starts `threads` OpenMP threads once per process and binds thread i of its teams to its own
/// CPU (as many as there are), as OMP_PROC_BIND=true would (libgomp reads that only from the
/// environment, before main).
///
/// Why: Linux starts a new thread on its creator's CPU, and libgomp's master waits for the
/// threads of its first team by spinning on that CPU, so the new thread runs only once the
/// scheduler's tick moves one of them; a thread woken later can again be queued behind a
/// spinning one. On a 2-core machine the first parallel region of `plumb calibrate` waited
/// milliseconds for its threads (docs/performance.md, "Threads (`--jobs`) and start-up").
/// Bound threads never share a CPU, so a region starts in microseconds. The start itself asks
/// for one thread more than it binds: when that is more than the CPUs (as with every core),
/// libgomp waits for them by sleeping, not spinning, so the new threads run at once; the extra
/// thread leaves at the next, smaller team.
///
/// Results do not depend on it: each job writes only its own result (core/jobs.h).
void PlaceThreads(int threads) {
  if (PlacementGivenByUser()) return;
  const std::vector<int> cpus = AllowedCpus();
  const int n = std::min(threads, static_cast<int>(cpus.size()));
  if (n < 2) return;
#pragma omp parallel num_threads(n + 1)
  {
    const int thread = omp_get_thread_num();
    if (thread < n) {
      cpu_set_t own;
      CPU_ZERO(&own);
      CPU_SET(cpus[static_cast<std::size_t>(thread)], &own);
      pthread_setaffinity_np(pthread_self(), sizeof own, &own);  // on failure: left unbound
    }
  }
}

}  // namespace

int Cores() {
  // Counted once, before PlaceThreads binds the calling thread to one CPU: omp_get_num_procs
  // counts the CPUs the calling thread may run on.
  static const int cores = omp_get_num_procs();
  return cores;
}

JobRunner ParallelJobs(int jobs) {
  const int cores = Cores();
  if ((jobs > 0 ? jobs : cores) < 2) return {};  // one thread: one job after another
  return [jobs, cores](int count, const std::function<void(int)>& job) {
    const int threads = std::max(1, std::min(count, jobs > 0 ? jobs : cores));
    if (threads > 1 && omp_get_level() == 0) {
      static std::once_flag placed;
      std::call_once(placed, PlaceThreads, jobs > 0 ? jobs : cores);
    }
#pragma omp parallel for schedule(dynamic) num_threads(threads)
    for (int k = 0; k < count; ++k) job(k);
  };
}

}  // namespace plumb::cli

#include "jobs.h"

#include <omp.h>

#include <algorithm>

namespace plumb::cli {

JobRunner ParallelJobs(int jobs) {
  return [jobs](int count, const std::function<void(int)>& job) {
    const int threads = std::max(1, std::min(count, jobs > 0 ? jobs : omp_get_num_procs()));
#pragma omp parallel for schedule(dynamic) num_threads(threads)
    for (int k = 0; k < count; ++k) job(k);
  };
}

}  // namespace plumb::cli

// tests/support/split_read_testing.h — what the tests of the readers' read in parts
// (SplitReadOptions, plumb/io/common/split_read.h) share: jobs run in order, counting a
// reader's joins, and options that split an input of any size.
#pragma once

#include <cstddef>
#include <functional>

#include "plumb/core/jobs.h"
#include "plumb/io/common/split_read.h"

namespace plumb::testing {

/// Jobs one after another, in order (the serial RunJobs, through a runner).
inline void InOrder(int count, const std::function<void(int)>& job) {
  for (int k = 0; k < count; ++k) job(k);
}

/// InOrder, counting in `calls` the calls that run `jobs` jobs at once: a reader's joins,
/// when they are the only calls of that many jobs in a read (four column copies of a decoded
/// series, AppendSamples; eight message vectors of a tlog).
inline JobRunner CountingCalls(int jobs, std::size_t* calls) {
  return [jobs, calls](int count, const std::function<void(int)>& job) {
    if (count == jobs) ++*calls;
    InOrder(count, job);
  };
}

/// `parts` parts (two by default) for an input of any size, through `run_jobs`: the first read
/// alone for `lead` bytes, the second's start looked for at `at` of the rest, the later parts'
/// at its multiples.
inline io::SplitReadOptions TwoParts(std::size_t lead, double at, const JobRunner& run_jobs,
                                     int parts = 2) {
  io::SplitReadOptions options;
  options.run_jobs = run_jobs;
  options.split_bytes = 0;
  options.parts = parts;
  options.lead_bytes = lead;
  options.second_part_at = at;
  return options;
}

}  // namespace plumb::testing

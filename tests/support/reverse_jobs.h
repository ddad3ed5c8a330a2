// tests/support/reverse_jobs.h — JobRunners (core/jobs.h) for tests and benchmarks, which may
// start threads (the library starts none): one that runs the jobs in another order than the
// serial one, and at once, for tests that a result does not depend on how its independent jobs
// are run; one that runs them on two threads as they come free, as `plumb`'s runner does.
#pragma once

#include <atomic>
#include <functional>
#include <thread>

namespace plumb::testing {

/// Runs the jobs last to first, half of them on a second thread.
inline void ReverseOnTwoThreads(int count, const std::function<void(int)>& job) {
  std::thread other([&] {
    for (int k = count - 1; k >= 0; k -= 2) job(k);
  });
  for (int k = count - 2; k >= 0; k -= 2) job(k);
  other.join();
}

/// Runs the jobs on two threads at once, this one and one started for the call, each taking
/// the next job as it comes free (as `plumb`'s runner, apps/plumb/jobs.cc). Started per call,
/// the thread costs a few microseconds and leaves none waiting between calls.
inline void OnTwoThreads(int count, const std::function<void(int)>& job) {
  std::atomic<int> next{0};
  const auto work = [&] {
    for (int k = next++; k < count; k = next++) job(k);
  };
  std::thread other(work);
  work();
  other.join();
}

}  // namespace plumb::testing

// tests/support/reverse_jobs.h — a JobRunner (core/jobs.h) that runs the jobs in another order
// than the serial one, and at once, for tests that a result does not depend on how its
// independent jobs are run.
#pragma once

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

}  // namespace plumb::testing

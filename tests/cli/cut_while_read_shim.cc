// tests/cli/cut_while_read_shim.cc — preloaded into plumb (LD_PRELOAD) by
// Safety.ALogCutWhileItIsReadIsAnErrorNotASignal: cuts the file PLUMB_TEST_CUT_FILE to
// PLUMB_TEST_CUT_BYTES bytes right after plumb's PLUMB_TEST_CUT_AT-th madvise (1 when not
// given) of the kind PLUMB_TEST_CUT_ON names ("populate": the DataFlash and ULog readers have
// read a span of the mapped log in, the second one for the span after the first;
// "sequential": the tlog reader has mapped it whole), the moment a log rotation can strike.
// The parser then touches mapped pages past the new end, as it would after a real rotation:
// without plumb's guard, SIGBUS (exit 135); with it, an error naming the file.
#include <dlfcn.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstring>

#ifndef MADV_POPULATE_READ
#define MADV_POPULATE_READ 22
#endif

extern "C" int madvise(void* addr, size_t length, int advice) {
  using Real = int (*)(void*, size_t, int);
  static const Real real = reinterpret_cast<Real>(dlsym(RTLD_NEXT, "madvise"));
  const int out = real(addr, length, advice);
  static std::atomic<int> calls{0};
  const char* on = std::getenv("PLUMB_TEST_CUT_ON");
  const char* file = std::getenv("PLUMB_TEST_CUT_FILE");
  const char* bytes = std::getenv("PLUMB_TEST_CUT_BYTES");
  if (on == nullptr || file == nullptr || bytes == nullptr) return out;
  const int wanted = std::strcmp(on, "populate") == 0 ? MADV_POPULATE_READ : MADV_SEQUENTIAL;
  const char* at = std::getenv("PLUMB_TEST_CUT_AT");
  if (advice == wanted && ++calls == (at != nullptr ? std::atoi(at) : 1)) {
    (void)::truncate(file, static_cast<off_t>(std::atoll(bytes)));
  }
  return out;
}

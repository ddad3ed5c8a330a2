// plumb/io/common/mapping_guard.cc — see mapping_guard.h.
#include "plumb/io/common/mapping_guard.h"

#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <mutex>

namespace plumb::io::detail {
namespace {

/// One registered mapping. The handler reads it with lock-free atomics only (all it may use
/// in a signal handler); registering and releasing take kRegistryMutex.
struct GuardedRange {
  std::atomic<std::uintptr_t> begin{0};
  std::atomic<std::uintptr_t> end{0};  ///< 0: the slot is free
  std::atomic<bool> cut{false};
};

GuardedRange g_ranges[MappingGuard::kMaxGuards];
std::mutex g_registry_mutex;
struct sigaction g_previous {};          ///< the SIGBUS action before plumb's
std::atomic<std::uintptr_t> g_page{0};   ///< the page size, read before the handler runs

/// Calls the SIGBUS action that was installed before plumb's, or, when that was the default,
/// restores it so that the fault, met again as the instruction is retried, ends the process
/// as it would have without plumb (a SIGBUS sent by kill is raised again).
void PassOn(int signal, siginfo_t* info, void* context) {
  if ((g_previous.sa_flags & SA_SIGINFO) != 0 && g_previous.sa_sigaction != nullptr) {
    g_previous.sa_sigaction(signal, info, context);
    return;
  }
  if (g_previous.sa_handler != SIG_DFL && g_previous.sa_handler != SIG_IGN) {
    g_previous.sa_handler(signal);
    return;
  }
  struct sigaction fallback {};
  fallback.sa_handler = SIG_DFL;
  ::sigemptyset(&fallback.sa_mask);
  ::sigaction(signal, &fallback, nullptr);
  if (info->si_code <= 0) ::raise(signal);  // sent, not a fault: nothing retries it
}

void OnBusError(int signal, siginfo_t* info, void* context) {
  const auto at = reinterpret_cast<std::uintptr_t>(info->si_addr);
  const std::uintptr_t page = g_page.load(std::memory_order_relaxed);
  for (GuardedRange& range : g_ranges) {
    if (at < range.begin.load(std::memory_order_acquire) ||
        at >= range.end.load(std::memory_order_acquire)) {
      continue;
    }
    void* zeros = ::mmap(reinterpret_cast<void*>(at / page * page), page, PROT_READ,
                         MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1, 0);
    if (zeros == MAP_FAILED) break;
    range.cut.store(true, std::memory_order_release);
    return;  // the read is retried and finds zeros
  }
  PassOn(signal, info, context);
}

void InstallHandler() {
  g_page.store(static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE)), std::memory_order_relaxed);
  struct sigaction action {};
  action.sa_sigaction = OnBusError;
  action.sa_flags = SA_SIGINFO | SA_ONSTACK;
  ::sigemptyset(&action.sa_mask);
  ::sigaction(SIGBUS, &action, &g_previous);
}

}  // namespace

MappingGuard::MappingGuard(const void* begin, std::size_t bytes) {
  if (begin == nullptr || bytes == 0) return;
  static std::once_flag installed;
  std::call_once(installed, InstallHandler);
  const std::lock_guard<std::mutex> lock(g_registry_mutex);
  for (int i = 0; i < kMaxGuards; ++i) {
    GuardedRange& range = g_ranges[i];
    if (range.end.load(std::memory_order_relaxed) != 0) continue;
    const auto at = reinterpret_cast<std::uintptr_t>(begin);
    range.cut.store(false, std::memory_order_relaxed);
    range.begin.store(at, std::memory_order_relaxed);
    range.end.store(at + bytes, std::memory_order_release);
    slot_ = i;
    return;
  }
}

MappingGuard::~MappingGuard() {
  if (slot_ < 0) return;
  const std::lock_guard<std::mutex> lock(g_registry_mutex);
  g_ranges[slot_].end.store(0, std::memory_order_release);
  g_ranges[slot_].begin.store(0, std::memory_order_release);
}

bool MappingGuard::cut() const {
  return slot_ >= 0 && g_ranges[slot_].cut.load(std::memory_order_acquire);
}

InputError CutShortError(const std::string& path, std::size_t size_when_opened) {
  return InputError(path, "",
                    "the file was cut short or replaced while plumb read it (it had " +
                        std::to_string(size_when_opened) +
                        " bytes when opened; a log being rotated or still written?): read a "
                        "copy taken when it no longer changes");
}

}  // namespace plumb::io::detail

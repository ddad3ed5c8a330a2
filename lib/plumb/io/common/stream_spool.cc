// plumb/io/common/stream_spool.cc — see stream_spool.h.
#include "plumb/io/common/stream_spool.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>

#include "plumb/core/error.h"
#include "plumb/core/number_text.h"

namespace plumb::io {
namespace {

/// Bytes read from a stream per read(2): what a pipe holds (64 KiB) many times over.
constexpr std::size_t kSpoolChunk = std::size_t{1} << 20;

/// An in-memory copy of a stream: its descriptor and size.
struct Copy {
  int fd = -1;
  std::uint64_t bytes = 0;
};

std::mutex g_copies_mutex;

/// The copies held, by the path the user named.
std::map<std::string, Copy>& Copies() {
  static std::map<std::string, Copy> copies;
  return copies;
}

/// Closes a descriptor unless released.
struct FdOwner {
  int fd;
  ~FdOwner() {
    if (fd >= 0) ::close(fd);
  }
  int Release() {
    const int out = fd;
    fd = -1;
    return out;
  }
};

std::string Megabytes(std::uint64_t bytes) {
  return std::to_string(bytes) + " bytes (" +
         SignificantText(static_cast<double>(bytes) / 1e6, 3) + " MB)";
}

/// Writes `n` bytes to `fd` whole; false with errno on a failure.
bool WriteAll(int fd, const char* data, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, data, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    data += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

/// Reads the stream `path` whole into a new memory file, at most `max_bytes`.
Copy SpoolOne(const std::string& path, std::uint64_t max_bytes) {
  FdOwner in{::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY)};
  if (in.fd < 0) {
    throw InputError(path, "", std::string("cannot open for reading: ") + std::strerror(errno));
  }
  FdOwner copy{::memfd_create("plumb-input", MFD_CLOEXEC)};
  if (copy.fd < 0) {
    throw InputError(path, "", std::string("cannot keep the stream in memory to read it: ") +
                                   std::strerror(errno));
  }
  std::vector<char> chunk(kSpoolChunk);
  std::uint64_t total = 0;
  while (true) {
    const ssize_t r = ::read(in.fd, chunk.data(), chunk.size());
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      throw InputError(path, "byte " + std::to_string(total),
                       std::string("read failed: ") + std::strerror(errno));
    }
    if (r == 0) break;
    if (total + static_cast<std::uint64_t>(r) > max_bytes) {
      throw InputError(path, "byte " + std::to_string(max_bytes),
                       "the stream goes on past " + Megabytes(max_bytes) +
                           ", the memory allowed for reading inputs, before its end: save it to "
                           "a file and read that, or allow more memory");
    }
    if (!WriteAll(copy.fd, chunk.data(), static_cast<std::size_t>(r))) {
      throw InputError(path, "byte " + std::to_string(total),
                       std::string("cannot keep the stream in memory to read it: ") +
                           std::strerror(errno));
    }
    total += static_cast<std::uint64_t>(r);
  }
  return Copy{copy.Release(), total};
}

}  // namespace

std::optional<std::uint64_t> AvailableMemory() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  std::uint64_t value = 0;
  while (in >> key >> value) {
    std::getline(in, unit);
    if (key == "MemAvailable:") return value * 1024;  // the file says kB (KiB)
  }
  return std::nullopt;
}

std::uint64_t StreamBound(std::uint64_t max_bytes) {
  if (max_bytes > 0) return max_bytes;
  return AvailableMemory().value_or(std::uint64_t{1} << 30);
}

bool IsStream(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

std::string OpenPath(const std::string& path) {
  const std::lock_guard<std::mutex> lock(g_copies_mutex);
  const auto it = Copies().find(path);
  if (it == Copies().end()) return path;
  return "/proc/self/fd/" + std::to_string(it->second.fd);
}

std::uint64_t SpooledBytes(const std::string& path) {
  const std::lock_guard<std::mutex> lock(g_copies_mutex);
  const auto it = Copies().find(path);
  return it == Copies().end() ? 0 : it->second.bytes;
}

StreamSpool::StreamSpool(const std::vector<std::string>& paths, std::uint64_t max_bytes) {
  try {
    for (const std::string& path : paths) {
      {
        const std::lock_guard<std::mutex> lock(g_copies_mutex);
        if (Copies().count(path) != 0) continue;  // held by another spool: read once
      }
      if (!IsStream(path)) continue;
      std::uint64_t used = 0;
      for (const std::string& held : held_) used += SpooledBytes(held);
      const Copy copy = SpoolOne(path, max_bytes - std::min(max_bytes, used));
      const std::lock_guard<std::mutex> lock(g_copies_mutex);
      Copies().emplace(path, copy);
      held_.push_back(path);
    }
  } catch (...) {
    ReleaseAll();  // the copies made so far
    throw;
  }
}

StreamSpool::~StreamSpool() { ReleaseAll(); }

void StreamSpool::ReleaseAll() {
  const std::lock_guard<std::mutex> lock(g_copies_mutex);
  for (const std::string& path : held_) {
    const auto it = Copies().find(path);
    if (it == Copies().end()) continue;
    ::close(it->second.fd);
    Copies().erase(it);
  }
  held_.clear();
}

}  // namespace plumb::io

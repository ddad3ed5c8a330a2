// plumb/io/common/stream_spool.h — inputs that can be read only once, read whole first.
//
// Standard input, a pipe, a FIFO, process substitution (`<(cat LOG.bin)`, /dev/fd/N) or a
// character device give their bytes once. plumb's readers look at a file more than once: the
// format is sniffed from its first bytes, a log is mapped and read in parts, a table's header
// is read before its rows. A StreamSpool reads each such input whole into an anonymous file
// in memory (memfd_create), within a bound on its size, and while it lives every reader opens
// that copy instead (OpenPath), a regular file: no byte is lost to sniffing, and an endless
// stream (`yes | plumb ...`, /dev/zero) stops at the bound with an error instead of filling
// memory. Messages keep the name the user gave.
//
//   const StreamSpool spool({"/dev/stdin"}, max_bytes);
//   const FlightLog log = FlightLog::Open("/dev/stdin");  // reads the copy
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace plumb::io {

/// The path a reader opens for the input the user named `path`: "/proc/self/fd/N", the
/// in-memory copy, while a StreamSpool holds one for `path`; else `path` itself.
std::string OpenPath(const std::string& path);

/// The bytes of the in-memory copy of `path` a StreamSpool holds (0: none; `path` is read
/// where it is). Memory a reader's estimate adds to its own.
std::uint64_t SpooledBytes(const std::string& path);

/// Whether `path` names an input that gives its bytes once: it exists and is not a regular
/// file or a folder (a pipe, a FIFO, a character device, a socket), after following links.
bool IsStream(const std::string& path);

/// MemAvailable from /proc/meminfo, bytes; nullopt where the system does not say.
std::optional<std::uint64_t> AvailableMemory();

/// The bound on a stream read whole into memory: `max_bytes` when given (> 0), else the
/// memory available (AvailableMemory; 1 GiB where the system does not say).
std::uint64_t StreamBound(std::uint64_t max_bytes);

/// Reads every stream among `paths` (IsStream, and not held by another StreamSpool already)
/// whole into memory, and holds the copies until it is destroyed. Not copyable.
class StreamSpool {
 public:
  /// `max_bytes`: the most bytes of all the streams together (the memory the caller allows
  /// for reading inputs). Throws plumb::InputError(path, "byte N", ...) when a stream goes on past
  /// it (an endless stream stops there), or when it cannot be read; the copies already made
  /// are released.
  StreamSpool(const std::vector<std::string>& paths, std::uint64_t max_bytes);
  ~StreamSpool();
  StreamSpool(const StreamSpool&) = delete;
  StreamSpool& operator=(const StreamSpool&) = delete;

 private:
  void ReleaseAll();               ///< closes and forgets the copies this spool made
  std::vector<std::string> held_;  ///< the paths whose copies this spool made
};

}  // namespace plumb::io

// plumb/io/common/mapping_guard.h — a mapped file that may be cut short while it is read.
//
// Touching a page of a mapped file past the file's current end raises SIGBUS: a log rotated
// or truncated while plumb reads it, or replaced in place. Unhandled, that ends the process
// (exit 135) with nothing said. A MappingGuard registers a mapping's address range; plumb's
// SIGBUS handler (installed once, by the first guard) maps a page of zeros over the page
// touched inside a registered range, so that the read goes on, and marks the guard cut. The
// reader then asks cut() and throws a clear error (CutShortError) instead of keeping what it
// parsed from the zeros. A SIGBUS anywhere else goes to the handler installed before plumb's
// (Python's faulthandler, a sanitizer), or ends the process as it would have.
//
//   const MappingGuard guard(base, size);
//   ... parse [base, base + size) ...
//   if (guard.cut()) throw CutShortError(path, size);
#pragma once

#include <cstddef>
#include <string>

#include "plumb/core/error.h"

namespace plumb::io::detail {

/// Registers the mapped bytes [begin, begin + bytes) with plumb's SIGBUS handler while it
/// lives. At most kMaxGuards mappings are guarded at once; a mapping beyond them is not (a
/// SIGBUS in it then ends the process, as without the guard). Not copyable.
class MappingGuard {
 public:
  MappingGuard(const void* begin, std::size_t bytes);
  ~MappingGuard();
  MappingGuard(const MappingGuard&) = delete;
  MappingGuard& operator=(const MappingGuard&) = delete;

  /// Whether a page of the mapping was found past the file's end (and now reads as zeros):
  /// the file was cut short after it was mapped.
  bool cut() const;

  /// Mappings guarded at once, at most (a log read in two parts maps it once; a few logs
  /// read at once by threads each map theirs).
  static constexpr int kMaxGuards = 64;

 private:
  int slot_ = -1;  ///< its place among the registered ranges; -1: not guarded
};

/// The error for a file cut short (or replaced) while plumb read it: names the file and its
/// size when it was opened, and what to do.
InputError CutShortError(const std::string& path, std::size_t size_when_opened);

}  // namespace plumb::io::detail

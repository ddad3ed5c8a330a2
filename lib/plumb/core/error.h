// plumb/core/error.h — the one exception type of the library.
//
// The library never prints and never calls exit(); it throws plumb::Error with a message that
// names the file, the place (line or byte offset) and what was expected (SPEC section 8).
// Only the command-line `main` catches it.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace plumb {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// Error about an input file. `where` is e.g. "line 12" or "byte 4096"; may be empty.
class InputError : public Error {
 public:
  InputError(const std::string& file, const std::string& where, const std::string& what)
      : Error(file + (where.empty() ? "" : ":" + where) + ": " + what),
        file_(file), where_(where) {}
  const std::string& file() const { return file_; }
  const std::string& where() const { return where_; }

 private:
  std::string file_;
  std::string where_;
};

/// Error raised when the data cannot support the requested model; the message says what is
/// missing and what to record.
class InsufficientDataError : public Error {
 public:
  explicit InsufficientDataError(const std::string& what) : Error(what) {}
};

}  // namespace plumb

// Helpers for the io tests: a private temporary folder and checks on plumb::InputError.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "plumb/core/error.h"

namespace plumb::io::testing {

/// A fresh folder under the system temporary folder, removed with its content at the end.
class TempDir {
 public:
  TempDir() {
    std::string templ = (std::filesystem::temp_directory_path() / "plumb_io_test.XXXXXX").string();
    path_ = ::mkdtemp(templ.data());
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string File(const std::string& name) const { return (path_ / name).string(); }
  /// Writes `content` to `name` in the folder and returns its path.
  std::string Write(const std::string& name, const std::string& content) const {
    std::ofstream(File(name), std::ios::binary) << content;
    return File(name);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Runs `read` and checks that it throws plumb::InputError for `file` at `where` with a message
/// containing every one of `parts`.
template <typename Read>
void ExpectInputError(Read read, const std::string& file, const std::string& where,
                      std::initializer_list<std::string> parts) {
  try {
    read();
    ADD_FAILURE() << "expected plumb::InputError for " << file;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.where(), where) << e.what();
    for (const std::string& part : parts) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "message: " << e.what() << "\nmissing: " << part;
    }
  }
}

}  // namespace plumb::io::testing

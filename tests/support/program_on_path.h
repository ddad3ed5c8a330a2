// tests/support/program_on_path.h — whether a program the tests need (gnuplot, chromium) is
// on the PATH, so that a test that needs it skips with the reason when it is not.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

namespace plumb::testing {

/// True when an executable called `program` is in a folder of the PATH.
inline bool ProgramOnPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (!dir.empty() && ::access((std::filesystem::path(dir) / program).c_str(), X_OK) == 0) {
      return true;
    }
  }
  return false;
}

}  // namespace plumb::testing

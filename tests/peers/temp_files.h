// A fresh folder under the system temporary folder for files a test writes, removed at the end.
#pragma once

#include "support/temp_dir.h"

#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace plumb::peers::testing {

using TempFolder = ::plumb::testing::TempDir;

/// The message of the plumb::Error that `f` throws, or "" when it throws none.
template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace plumb::peers::testing

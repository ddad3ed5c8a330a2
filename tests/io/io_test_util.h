// Helpers for the io tests: a private temporary folder and checks on plumb::InputError.
#pragma once

#include "support/temp_dir.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "plumb/core/error.h"

namespace plumb::io::testing {

using ::plumb::testing::TempDir;

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

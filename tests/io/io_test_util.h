// Helpers for the io tests: a private temporary folder and checks on plumb::InputError.
#pragma once

#include "support/temp_dir.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

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

/// Skips the test, with the reason, when the shared-data file `path` is absent.
#define PLUMB_SKIP_IF_ABSENT(path) \
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << (path)

/// ../shared/data/<folder>/<name>.
inline std::string SharedLogPath(const std::string& folder, const std::string& name) {
  return std::string(PLUMB_SHARED_DATA_DIR) + "/" + folder + "/" + name;
}

/// The golden JSON tests/data/<folder>/<name>.golden.json (see the README there for how each
/// was decoded independently).
inline nlohmann::json ReadGoldenJson(const std::string& folder, const std::string& name) {
  const std::string path =
      std::string(PLUMB_SOURCE_DIR) + "/tests/data/" + folder + "/" + name + ".golden.json";
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return nlohmann::json::parse(in);
}

/// Every byte of the file at `path` (empty when it cannot be read).
inline std::vector<std::uint8_t> ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in),
                                   std::istreambuf_iterator<char>());
}

}  // namespace plumb::io::testing

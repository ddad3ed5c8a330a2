// Runs the plumb command as a child process (fork/exec, no shell) and captures its exit code,
// standard output and standard error, in the spirit of GeographicLib's command-line tests.
#pragma once

#include <nlohmann/json.hpp>

#include "support/temp_dir.h"

#include <fcntl.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace plumb::cli::testing {

struct ToolRun {
  int exit_code = -1;  ///< the process's exit status; -1 if it did not exit normally
  std::string out;     ///< standard output
  std::string err;     ///< standard error
};

inline std::string ReadAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

using ::plumb::testing::TempDir;

/// Runs `tool args...`; stdout and stderr go to files in `dir`, read back after the exit.
inline ToolRun Run(const std::string& tool, const std::vector<std::string>& args,
                   const TempDir& dir) {
  const std::string out_path = dir.File(".stdout"), err_path = dir.File(".stderr");
  std::vector<std::string> argv_text = {tool};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  ToolRun run;
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    ::execv(tool.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  if (pid > 0 && ::waitpid(pid, &status, 0) == pid && WIFEXITED(status)) {
    run.exit_code = WEXITSTATUS(status);
  }
  run.out = ReadAll(out_path);
  run.err = ReadAll(err_path);
  return run;
}

/// Runs the plumb command built with this tree (PLUMB_TOOL) in `dir`.
inline ToolRun Plumb(const std::vector<std::string>& args, const TempDir& dir) {
  return Run(PLUMB_TOOL, args, dir);
}

inline bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The line of `text` that starts with `prefix` ("" when none).
inline std::string LineStarting(const std::string& text, const std::string& prefix) {
  std::stringstream ss(text);
  for (std::string line; std::getline(ss, line);) {
    if (line.rfind(prefix, 0) == 0) return line;
  }
  return "";
}

/// Parses a JSON file; throws (failing the test) on invalid JSON, e.g. a bare NaN.
inline nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

/// A CSV with a header (plumb's native CSV): column name -> values.
inline std::map<std::string, std::vector<double>> ReadCsv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string field;
    for (std::size_t c = 0; std::getline(row, field, ','); ++c) columns[names[c]].push_back(std::stod(field));
  }
  return columns;
}

}  // namespace plumb::cli::testing

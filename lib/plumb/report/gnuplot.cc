#include "plumb/report/gnuplot.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <thread>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/io/common/atomic_file.h"

extern char** environ;

namespace plumb::report {
namespace {

/// How many lines of gnuplot's messages a failure quotes.
constexpr int kQuotedLogLines = 4;

std::string Join(const std::string& folder, const std::string& name) {
  return (std::filesystem::path(folder) / name).string();
}

/// The first `lines` lines of the file at `path` (empty when it cannot be read).
std::string FirstLines(const std::string& path, int lines) {
  std::ifstream in(path);
  std::string line, out;
  for (int i = 0; i < lines && std::getline(in, line); ++i) {
    out += (out.empty() ? "" : " | ") + line;
  }
  return out;
}

/// Starts `program script` in `folder` with stdin /dev/null and stdout, stderr to `log_path`
/// (absolute), waits for it up to `limit_s` (then kills it: `stopped`); returns the spawn
/// error (0 when started) and the exit status.
int Spawn(const std::string& folder, const std::string& program, const std::string& script,
          const std::string& log_path, double limit_s, int& exit_code, bool& stopped) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addchdir_np(&actions, folder.c_str());
  std::string program_arg = program, script_arg = script;
  char* argv[] = {program_arg.data(), script_arg.data(), nullptr};
  pid_t pid = -1;
  const int error = posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  exit_code = -1;
  if (error != 0) return error;
  int status = 0;
  stopped = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  for (;;) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) return 0;
    if (std::chrono::steady_clock::now() >= deadline) {
      kill(pid, SIGKILL);
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      stopped = true;
      return 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (WIFEXITED(status)) exit_code = WEXITSTATUS(status);
  return 0;
}

}  // namespace

std::string SvgTerminal(int width_px, int height_px) {
  return "set terminal svg size " + std::to_string(width_px) + "," + std::to_string(height_px) +
         " noenhanced font 'sans,10' background rgb 'white'\n";
}

std::string GnuplotQuote(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'') out += '\'';
    out += c;
  }
  return out + "'";
}

GnuplotOutcome RunGnuplot(const std::string& folder, const GnuplotJob& job,
                          const std::string& program, double limit_s) {
  for (const auto& file : job.data) io::WriteFileAtomic(Join(folder, file.name), file.content);
  io::WriteFileAtomic(Join(folder, job.script_name), job.script);
  const std::string log_path = std::filesystem::absolute(Join(folder, job.log_name)).string();
  GnuplotOutcome outcome;
  bool stopped = false;
  const int error =
      Spawn(folder, program, job.script_name, log_path, limit_s, outcome.exit_code, stopped);
  if (error == ENOENT) {
    outcome.message = "'" + program + "' was not found on the PATH: install gnuplot (Debian: "
                      "apt-get install gnuplot-nox) and run 'gnuplot " + job.script_name +
                      "' in " + folder + " to draw the figures";
    return outcome;
  }
  if (error != 0) {
    outcome.message = "could not start '" + program + "': " + std::strerror(error);
    return outcome;
  }
  outcome.ran = outcome.exit_code == 0;
  std::vector<std::string> missing;
  for (const auto& name : job.outputs) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(Join(folder, name), ec);
    if (!ec && size > 0) {
      outcome.written.push_back(name);
    } else {
      missing.push_back(name);
    }
  }
  if (stopped) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", limit_s);
    outcome.message = "'" + program + " " + job.script_name + "' did not finish within " +
                      limit + " s and was stopped: no figures (is it waiting for input, or a "
                      "window?)";
  } else if (!outcome.ran) {
    outcome.message = "'" + program + " " + job.script_name + "' failed (" +
                      (outcome.exit_code < 0 ? std::string("killed")
                                             : "exit " + std::to_string(outcome.exit_code)) +
                      ")";
    const std::string said = FirstLines(log_path, kQuotedLogLines);
    if (!said.empty()) outcome.message += ": " + said;
    outcome.message += "; see " + Join(folder, job.log_name);
  } else if (!missing.empty()) {
    std::string list;
    for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
    outcome.message = "gnuplot did not write " + list + "; see " + Join(folder, job.log_name);
  }
  return outcome;
}

}  // namespace plumb::report

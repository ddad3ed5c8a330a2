// Progress on stderr: drawn in place while a command longer than a second runs with stderr on
// a terminal (a pseudo-terminal here), never written when stderr is a file or a pipe.
#include <gtest/gtest.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using testing::Contains;
using testing::Plumb;
using testing::TempDir;
using testing::ToolRun;

/// Runs plumb with stdout and stderr on a pseudo-terminal; what the terminal received.
std::string RunOnTerminal(const std::vector<std::string>& args, int& exit_code) {
  std::vector<std::string> argv_text = {PLUMB_TOOL};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  int master = -1;
  const pid_t pid = ::forkpty(&master, nullptr, nullptr, nullptr);
  if (pid == 0) {
    ::execv(PLUMB_TOOL, argv.data());
    ::_exit(127);
  }
  std::string out;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(master, buffer, sizeof buffer);
    if (n <= 0) break;  // EIO once the child has closed the terminal
    out.append(buffer, static_cast<std::size_t>(n));
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  ::close(master);
  return out;
}

TEST(Progress, DrawnOnATerminalAndNeverIntoAFile) {
  TempDir dir;
  const std::string csv = dir.File("s.csv");
  // 150 poses at 400 Hz: each of diagnose's probe fits takes more than the second progress
  // waits before it draws (about 2 s each on a 2 GHz core).
  ASSERT_EQ(Plumb({"simulate", "--out", csv, "--poses", "150", "--rate", "400", "--seed", "4"}, dir)
                .exit_code, 0);
  int code = -1;
  const std::string terminal = RunOnTerminal({"diagnose", csv, "--confirm", "0"}, code);
  EXPECT_EQ(code, 0) << terminal;
  EXPECT_TRUE(Contains(terminal, "\r\033[Kplumb diagnose: probe fit")) << terminal;
  EXPECT_TRUE(Contains(terminal, " s\r\033[K")) << "the line is erased before the next text";
  EXPECT_TRUE(Contains(terminal, "plumb diagnose: ")) << terminal;

  const ToolRun file = Plumb({"diagnose", csv, "--confirm", "0"}, dir);
  EXPECT_EQ(file.exit_code, 0) << file.err;
  EXPECT_FALSE(Contains(file.err, "\033[K")) << file.err;
  EXPECT_FALSE(Contains(file.err, "probe fit")) << file.err;
  EXPECT_FALSE(Contains(file.out, "\033[K"));
}

}  // namespace
}  // namespace plumb::cli

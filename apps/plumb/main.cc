// plumb — IMU accelerometer and gyroscope calibration with honest uncertainty.
//
// The only place that catches exceptions: usage mistakes exit 2 (CLI11's parse errors and
// UsageError), every other error prints `plumb: error: <message>` on stderr and exits 1; a
// message that names no input file gets the INPUT files in front (WithInputsNamed).
#include <glog/logging.h>
#include <malloc.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <iostream>
#include <new>
#include <memory>
#include <utility>
#include <vector>

#include "commands.h"
#include "file_roles.h"
#include "option_flags.h"
#include "progress.h"
#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "validators.h"
#include "plumb/report/version.h"

namespace {

/// Error messages are printed through plumb::Printable (a NUL or a binary byte quoted from a
/// file shows as \\xNN), at most this long.
constexpr std::size_t kMessageBytes = 4000;

/// Flushes the standard output (std::cout and stdio): why what was printed did not arrive
/// (a full disk, a closed or broken stdout), or nullopt.
std::optional<std::string> StandardOutputLost() {
  std::cout.flush();
  errno = 0;
  const bool failed = !std::cout.good() || std::fflush(stdout) != 0 || std::ferror(stdout) != 0;
  if (!failed) return std::nullopt;
  return std::string("cannot write the standard output") +
         (errno != 0 ? std::string(" (") + std::strerror(errno) + ")" : std::string()) +
         ": what was printed is lost";
}

std::string UsageMessage(const CLI::App* app, const CLI::Error& e) {
  const std::string name = app->get_parent() ? "plumb " + app->get_name() : "plumb";
  return "plumb: error: " + std::string(e.what()) + "\nRun '" + name +
         " --help' for the options.\n";
}

}  // namespace

namespace plumb::cli {
std::vector<std::string>& CommandLineArgs() {
  static std::vector<std::string> args;
  return args;
}
}  // namespace plumb::cli

int main(int argc, char** argv) {
  // A fit allocates and frees large blocks many times (Jacobians, each pass's work arrays).
  // glibc hands blocks over 128 KiB to mmap and returns freed memory to the kernel, so each
  // such block costs fresh page faults; kept in the heap instead, they are reused (compare
  // `/usr/bin/time -v` of a `calibrate` with and without these, e.g. on the 600-pose session
  // of docs/performance.md: less wall time, about the same peak memory).
  ::mallopt(M_MMAP_THRESHOLD, 32 << 20);
  ::mallopt(M_TRIM_THRESHOLD, 128 << 20);
  ::mallopt(M_TOP_PAD, 16 << 20);
  // Ceres reports through glog; plumb reports itself (a failed covariance falls back with a
  // warning in the result), so only fatal glog messages may reach the user's terminal.
  FLAGS_minloglevel = google::GLOG_FATAL;
  FLAGS_logtostderr = true;
  google::InitGoogleLogging(argv[0]);
  plumb::cli::CommandLineArgs().assign(argv, argv + argc);
  // The library's messages name options as this command spells them ("--acc-unit g").
  plumb::SetOptionSpeller(&plumb::cli::SpellFlag);
  CLI::App app("plumb " + plumb::report::Version() +
                   ": calibrate an IMU's accelerometer and gyroscope from real logs, with "
                   "honest uncertainty",
               "plumb");
  app.failure_message(UsageMessage);  // before the subcommands, which inherit it
  app.set_version_flag("--version", plumb::report::Version(), "Print the version and exit");
  app.require_subcommand(1);
  app.footer("Run 'plumb COMMAND --help' for the options of a command.");

  // The commands, in the order `plumb --help` lists them. A run of one command builds only
  // that one's options (building every command's is a noticeable part of a short run).
  using Factory = std::unique_ptr<plumb::cli::Command> (*)(CLI::App&);
  const std::pair<const char*, Factory> kCommands[] = {
      {"calibrate", plumb::cli::MakeCalibrateCommand}, {"diagnose", plumb::cli::MakeDiagnoseCommand},
      {"simulate", plumb::cli::MakeSimulateCommand},   {"effects", plumb::cli::MakeEffectsCommand},
      {"compare", plumb::cli::MakeCompareCommand},     {"paper", plumb::cli::MakePaperCommand},
      {"info", plumb::cli::MakeInfoCommand},           {"report", plumb::cli::MakeReportCommand},
      {"allan", plumb::cli::MakeAllanCommand},         {"sweep", plumb::cli::MakeSweepCommand},
      {"apply", plumb::cli::MakeApplyCommand}};
  std::vector<std::unique_ptr<plumb::cli::Command>> commands;
  if (argc > 1 && argv[1][0] != '-') {
    const std::string name = argv[1];
    std::string names;
    for (const auto& [command_name, make] : kCommands) {
      if (command_name == name) commands.push_back(make(app));
      names += (names.empty() ? "" : ", ") + std::string(command_name);
    }
    if (commands.empty()) {
      std::cerr << "plumb: error: unknown command '" << name << "'; the commands are " << names
                << "\nRun 'plumb --help' for an overview.\n";
      return 2;
    }
  } else {
    for (const auto& entry : kCommands) commands.push_back(entry.second(app));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Report the error against the subcommand being parsed, so the help hint names it.
    for (const auto& command : commands) {
      if (command->app()->parsed()) return command->app()->exit(e) == 0 ? 0 : 2;
    }
    return app.exit(e) == 0 ? 0 : 2;
  }
  plumb::cli::Command* selected = nullptr;
  for (auto& command : commands) {
    if (command->app()->parsed()) selected = command.get();
  }
  if (selected == nullptr) return 2;  // unreachable: require_subcommand(1)
  plumb::cli::FileRoles files;
  plumb::cli::Progress& progress = plumb::cli::Progress::Of();
  try {
    plumb::cli::RejectNonFiniteNumbers(*selected->app());
    files = selected->Files();
    plumb::cli::RefuseOverwritingInputs(files);
    progress.Start(selected->app()->get_name(), ::isatty(STDERR_FILENO) == 1);
    const int code = selected->Run();
    progress.Stop();
    // What the command printed must have reached its reader: a full disk, a closed stdout.
    if (const std::optional<std::string> lost = StandardOutputLost()) {
      std::cerr << "plumb: error: " << *lost << "\n";
      return code == 0 ? 1 : code;
    }
    return code;
  } catch (const plumb::cli::UsageError& e) {
    progress.Stop();
    std::cerr << "plumb: error: " << plumb::Printable(e.what(), kMessageBytes) << "\nRun 'plumb "
              << selected->app()->get_name() << " --help' for the options.\n";
    return 2;
  } catch (const plumb::InputError& e) {  // names its file and place already
    progress.Stop();
    std::cerr << "plumb: error: " << plumb::Printable(e.what(), kMessageBytes) << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    const std::string stage = progress.CurrentStage();
    progress.Stop();
    std::cerr << "plumb: error: out of memory"
              << (stage.empty() ? std::string() : " while " + stage)
              << ": the run needs more memory than this machine gives it; read less of the "
                 "input (--from/--to, one IMU) or run it where more memory is free\n";
    return 1;
  } catch (const std::exception& e) {
    progress.Stop();
    std::cerr << "plumb: error: "
              << plumb::Printable(plumb::cli::WithInputsNamed(e.what(), files), kMessageBytes)
              << "\n";
    return 1;
  } catch (...) {
    progress.Stop();
    std::cerr << "plumb: error: unknown exception\n";
    return 1;
  }
}

// plumb — IMU accelerometer and gyroscope calibration with honest uncertainty.
//
// The only place that catches exceptions: usage mistakes exit 2 (CLI11's parse errors and
// UsageError), every other error prints `plumb: error: <message>` on stderr and exits 1; a
// message that names no input file gets the INPUT files in front (WithInputsNamed).
#include <glog/logging.h>
#include <unistd.h>

#include <exception>
#include <iostream>
#include <memory>
#include <vector>

#include "commands.h"
#include "file_roles.h"
#include "progress.h"
#include "plumb/core/error.h"
#include "validators.h"
#include "plumb/report/version.h"

namespace {

/// Error messages are printed through plumb::Printable (a NUL or a binary byte quoted from a
/// file shows as \\xNN), at most this long.
constexpr std::size_t kMessageBytes = 4000;

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
  // Ceres reports through glog; plumb reports itself (a failed covariance falls back with a
  // warning in the result), so only fatal glog messages may reach the user's terminal.
  FLAGS_minloglevel = google::GLOG_FATAL;
  FLAGS_logtostderr = true;
  google::InitGoogleLogging(argv[0]);
  plumb::cli::CommandLineArgs().assign(argv, argv + argc);
  CLI::App app("plumb " + plumb::report::Version() +
                   ": calibrate an IMU's accelerometer and gyroscope from real logs, with "
                   "honest uncertainty",
               "plumb");
  app.failure_message(UsageMessage);  // before the subcommands, which inherit it
  app.set_version_flag("--version", plumb::report::Version(), "Print the version and exit");
  app.require_subcommand(1);
  app.footer("Run 'plumb COMMAND --help' for the options of a command.");

  std::vector<std::unique_ptr<plumb::cli::Command>> commands;
  commands.push_back(plumb::cli::MakeCalibrateCommand(app));
  commands.push_back(plumb::cli::MakeDiagnoseCommand(app));
  commands.push_back(plumb::cli::MakeSimulateCommand(app));
  commands.push_back(plumb::cli::MakeEffectsCommand(app));
  commands.push_back(plumb::cli::MakeCompareCommand(app));
  commands.push_back(plumb::cli::MakePaperCommand(app));
  commands.push_back(plumb::cli::MakeInfoCommand(app));
  commands.push_back(plumb::cli::MakeReportCommand(app));
  commands.push_back(plumb::cli::MakeAllanCommand(app));
  commands.push_back(plumb::cli::MakeSweepCommand(app));
  commands.push_back(plumb::cli::MakeApplyCommand(app));

  if (argc > 1 && argv[1][0] != '-') {
    const std::string name = argv[1];
    bool known = false;
    std::string names;
    for (const auto& command : commands) {
      known = known || command->app()->get_name() == name;
      names += (names.empty() ? "" : ", ") + command->app()->get_name();
    }
    if (!known) {
      std::cerr << "plumb: error: unknown command '" << name << "'; the commands are " << names
                << "\nRun 'plumb --help' for an overview.\n";
      return 2;
    }
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
    return code;
  } catch (const plumb::cli::UsageError& e) {
    progress.Stop();
    std::cerr << "plumb: error: " << plumb::Printable(e.what(), kMessageBytes) << "\nRun 'plumb "
              << selected->app()->get_name() << " --help' for the options.\n";
    return 2;
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

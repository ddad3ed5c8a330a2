// apps/plumb/commands.h — the subcommands of `plumb` and how main runs them.
//
// Each subcommand registers its options on a CLI11 subcommand when made, and does its work in
// Run() once parsing selected it. Run() returns the exit code; errors are thrown (plumb::Error
// and other std::exception: exit 1; UsageError: exit 2) and caught only in main.
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "file_roles.h"

namespace plumb::cli {

/// A mistake in the command line found after parsing (e.g. options that do not go together).
class UsageError : public std::runtime_error {
 public:
  explicit UsageError(const std::string& what) : std::runtime_error(what) {}
};

class Command {
 public:
  virtual ~Command() = default;
  /// The CLI11 subcommand this command registered.
  CLI::App* app() const { return app_; }
  /// Does the work; returns the process exit code.
  virtual int Run() = 0;
  /// The files the parsed command line reads and writes (file_roles.h): main refuses it
  /// before Run when an output would overwrite an input.
  virtual FileRoles Files() const { return {}; }

 protected:
  CLI::App* app_ = nullptr;
};

std::unique_ptr<Command> MakeCalibrateCommand(CLI::App& parent);
std::unique_ptr<Command> MakeSimulateCommand(CLI::App& parent);
std::unique_ptr<Command> MakeEffectsCommand(CLI::App& parent);
std::unique_ptr<Command> MakeCompareCommand(CLI::App& parent);
std::unique_ptr<Command> MakePaperCommand(CLI::App& parent);
std::unique_ptr<Command> MakeDiagnoseCommand(CLI::App& parent);
std::unique_ptr<Command> MakeInfoCommand(CLI::App& parent);
std::unique_ptr<Command> MakeReportCommand(CLI::App& parent);
std::unique_ptr<Command> MakeAllanCommand(CLI::App& parent);
std::unique_ptr<Command> MakeSweepCommand(CLI::App& parent);
std::unique_ptr<Command> MakeApplyCommand(CLI::App& parent);

/// The command line as typed (argv), stored by main before parsing; `plumb report` prints it
/// as the command that reproduces the page.
std::vector<std::string>& CommandLineArgs();

}  // namespace plumb::cli

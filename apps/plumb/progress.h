// apps/plumb/progress.h — what a long command is doing, on stderr, for a person at a terminal.
//
// Once the command has run for kQuietSeconds, the current stage and the seconds it has taken
// ("plumb diagnose: refit with gyro_g_sensitivity (2 of 3)  4.2 s") are redrawn in place on
// stderr every kRedrawSeconds, and erased when the stage ends or the command prints. Only when
// stderr is a terminal (isatty): into a pipe, a file or a test nothing is written, so scripts
// and logs see exactly the output they saw before.
//
// The library never prints; it reports its stages through callbacks (e.g.
// DiagnoseOptions::on_stage), which the command points here.
#pragma once

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <streambuf>
#include <string>
#include <thread>

namespace plumb::cli {

class Progress {
 public:
  /// Nothing is drawn before the command has run this long, s.
  static constexpr double kQuietSeconds = 1.0;
  /// The line is redrawn this often, s.
  static constexpr double kRedrawSeconds = 0.25;

  /// The process's one instance; `Start` names the command and decides whether to draw.
  static Progress& Of();

  /// Begins the command `command` ("diagnose"). `enabled`: draw at all (main passes
  /// isatty(STDERR_FILENO)).
  void Start(const std::string& command, bool enabled);

  /// The command is now doing `what` ("reading flight.bin (1.2 GB)"); thread-safe.
  void Stage(const std::string& what);

  /// The stage is over: its line is erased now.
  void Clear();

  /// The stage the command is in ("" between stages): what an error met there was doing.
  std::string CurrentStage();

  /// Erases the line (the stage goes on and is drawn again at the next redraw). std::cout
  /// and std::cerr call it before every write while progress is drawn (GuardStreams), so
  /// the command's own text never lands after a progress line.
  void Erase();

  /// Stops drawing and erases the line (main, when the command returns or throws).
  void Stop();

  ~Progress();

 private:
  Progress() = default;
  void Draw();  ///< the ticker thread's loop
  void GuardStreams();  ///< std::cout and std::cerr erase the line before writing
  void EraseLocked();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread ticker_;
  std::string command_;
  std::string stage_;  ///< "" between stages
  std::chrono::steady_clock::time_point started_, stage_started_;
  bool enabled_ = false;
  bool stopping_ = false;
  bool drawn_ = false;  ///< a progress line is on the terminal
  std::unique_ptr<std::streambuf> guarded_out_, guarded_err_;
  std::streambuf* original_out_ = nullptr;
  std::streambuf* original_err_ = nullptr;
};

}  // namespace plumb::cli

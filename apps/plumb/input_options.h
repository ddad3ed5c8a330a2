// apps/plumb/input_options.h — how `plumb calibrate` (and diagnose, report, paper) reads its
// INPUT files: the flags, turned into the options of plumb::io::OpenInputs
// (lib/plumb/io/input/open_inputs.h), which reads and joins the inputs.
//
// Three forms, chosen by the command line:
//   native CSV    the default: the header time_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z[,temp_c]
//                 is recognised (SI units, FRD); `--format native` insists on it.
//   text table    any delimited text, described by --columns (which quantity each column holds,
//                 by position) and the unit options; `--format table` or --columns selects it.
//   two files     an accelerometer table and a gyroscope table with shared times (imu_tk's
//                 `t x y z` layout): INPUT given as `acc.txt,gyr.txt`, or --acc FILE --gyr FILE.
//                 --columns then describes both files with t, x, y, z (default `t,x,y,z`).
// Conversion to SI for tables: value_SI = (value - offset) * scale * unit, per sensor
// (--acc-offset, --acc-scale, --acc-unit m/s^2|g; --gyr-offset, --gyr-scale,
// --gyr-unit rad/s|deg/s); --axis-map then turns sensor axes into body FRD axes.
// Several INPUTs are joined one after the other into one session (times kept when they
// increase, otherwise shifted, with a warning, so that no motion is assumed between files).
// Flag mistakes are UsageErrors (exit 2); a table flag is checked only when a table is read
// (a flight log or native CSV ignores it), input by input, as before.
#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "file_roles.h"
#include "plumb/core/session.h"

namespace plumb::cli {

struct InputArgs {
  std::vector<std::string> inputs;  ///< positional INPUT files (or `acc,gyr` pairs)
  std::string acc_file, gyr_file;   ///< --acc / --gyr: the two-file form
  std::string format = "auto";      ///< auto | native | table
  std::string delimiter;            ///< , ; tab space; empty = detect from the first row
  std::size_t skip_lines = 0;       ///< lines dropped at the top, >= 0
  bool header = false;              ///< the first line after skipped ones names the columns
  std::string comment = "#";        ///< comment prefix; "" = none
  std::string columns;              ///< e.g. "t,ax,ay,az,gx,gy,gz"; "-" skips a column
  double time_unit_s = 1.0;         ///< seconds per file time unit, > 0 (--time-scale)
  double rate_hz = 0.0;             ///< sample rate when there is no time column, Hz, > 0
  std::string acc_scale = "1";      ///< number or fraction "a/b", multiplies --acc-unit
  std::string gyr_scale = "1";
  double acc_offset = 0.0;  ///< file units, subtracted first
  double gyr_offset = 0.0;
  std::string acc_unit = "m/s^2";  ///< m/s^2 | g
  std::string gyr_unit = "rad/s";  ///< rad/s | deg/s
  std::string axis_map = "1,2,3";  ///< body axis i = sign * sensor axis |m_i|, e.g. 1,-2,-3
  bool drop_nan = false;           ///< drop rows with NaN/inf instead of failing
  std::string clock = "stamps";    ///< --clock: stamps | uniform | receive (io::Clock)
  // Flight logs (ArduPilot .bin/.log, MAVLink .tlog, PX4 .ulg) and ROS bags:
  int imu = 0;                     ///< --imu: IMU instance, 0-based, >= 0
  std::string stream;              ///< --stream: message/topic name; empty = the default
  std::string topic;               ///< --topic: a ROS bag's sensor_msgs/Imu topic; empty = the only one
  double from_s = 0.0, to_s = 0.0; ///< --from / --to: time window in log time, s
  CLI::Option* from = nullptr;
  CLI::Option* to = nullptr;
  bool as_logged = false;          ///< --as-logged: keep the firmware's correction
  /// --imus (commands that fit the board, AddInputOptions's `board`): "all", or instances
  /// "0,1,2" (the first is IMU 0); empty: IMU 0 alone.
  std::string imus;
  CLI::Option* imu_given = nullptr;  ///< --imu, to tell it from its default
  /// --max-memory: bytes the run may use (SIZE: 1e6, 500M, 2G, 2GiB); 0 = the memory the
  /// system says is available (MemAvailable).
  std::uint64_t max_memory = 0;

  /// Options that only describe text tables, to tell the user when they are given in vain.
  std::vector<CLI::Option*> table_only;
};

/// Registers INPUT... and every input option on `app`; with `board`, --imus too (the commands
/// that fit the board's IMUs together, SPEC 6).
void AddInputOptions(CLI::App* app, InputArgs& args, bool board = false);

/// Adds the files INPUT..., --acc and --gyr name to `roles`' inputs (file_roles.h).
void AddInputFiles(const InputArgs& args, FileRoles& roles);

/// Reads every input and joins them into one session (plumb::io::OpenInputs). Throws
/// UsageError for contradictory or malformed options, plumb::InputError naming the file for bad
/// input, plumb::Error when the session has no samples. The two-file form's files, and a large
/// .bin, .tlog or .ulg log's two parts (io::SplitReadOptions), are read at once on up to
/// `jobs` threads (0: every core).
Session ReadInputs(const InputArgs& args, int jobs = 0);

/// Registers --max-memory SIZE on `app`, into `max_memory` (see InputArgs::max_memory).
void AddMaxMemoryOption(CLI::App* app, std::uint64_t& max_memory);

/// Refuses, before anything is read, inputs whose estimated memory (plumb::io::
/// EstimateReadMemory, summed over `files`) exceeds `max_memory` (0: MemAvailable; no check
/// when the system does not say): throws plumb::Error "reading FILE needs about 1.9 GB;
/// 1.2 GB is available (--max-memory)" (exit 1).
/// Returns the estimate it compared (bytes; 0 when no file is a regular file).
std::uint64_t CheckMemory(const std::vector<std::string>& files, std::uint64_t max_memory);

/// `bytes` for people: "850 kB", "25.2 MB", "1.9 GB" (powers of 1000, 3 significant digits).
std::string FormatBytes(std::uint64_t bytes);

}  // namespace plumb::cli

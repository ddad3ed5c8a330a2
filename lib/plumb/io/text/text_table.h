// plumb/io/text/text_table.h — IMU samples from delimited text tables of any common layout.
//
// A table has optional preamble lines, optional comment lines, an optional header row and one
// sample per row. TextTableOptions say where each quantity is and how to turn file units into
// SI: value_SI = (value_file - offset) * scale, then the optional axis map turns the sensor's
// axes into the body frame (FRD). Examples (the shared data sets):
//
//   mikoff `ax ay az wx wy wz`, SI, no time, 100 Hz:
//     o.acc.axes = {0, 1, 2}; o.gyr.axes = {3, 4, 5}; o.rate_hz = 100;
//   MPU-6050 raw int16 (+-2 g, +-250 deg/s) after 4 preamble lines and a header `ax,...,gz`:
//     o.skip_lines = 4; o.header_row = true; o.rate_hz = 100;
//     o.acc.axes = {"ax", "ay", "az"}; o.acc.SetScale(units::kStandardGravity / 16384);
//     o.gyr.axes = {"gx", "gy", "gz"}; o.gyr.SetScale(units::kRadPerDeg / 131);
//   `# time tx ty tz wx wy wz ...` comment header, unix seconds:
//     o.time = "time"; o.acc.axes = {"tx", "ty", "tz"}; o.gyr.axes = {"wx", "wy", "wz"};
//
// Rows are parsed with std::from_chars from a chunked buffer (no iostreams). Errors are
// plumb::InputError naming the file, the line and what was expected (SPEC section 8); mistakes
// in the options themselves are plumb::Error.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <utility>

#include "plumb/core/jobs.h"
#include "plumb/core/session.h"

namespace plumb::io {

/// One column of the file, by 0-based index or by name (from the header row or the comment
/// line just before the data). Converts implicitly: `Column c = 3;` or `Column c = "tx";`.
struct Column {
  int index = -1;    ///< 0-based field index; -1 when given by name or not given
  std::string name;  ///< column name as written in the file (case-sensitive); empty if by index

  Column() = default;
  Column(int i) : index(i) {}                    // NOLINT(google-explicit-constructor)
  Column(const char* n) : name(n) {}             // NOLINT(google-explicit-constructor)
  Column(std::string n) : name(std::move(n)) {}  // NOLINT(google-explicit-constructor)
  bool given() const { return index >= 0 || !name.empty(); }
};

/// The three columns of one sensor triad and their conversion to SI.
struct TriadColumns {
  /// Columns of the sensor's x, y, z outputs; leave all three unset for "no such sensor".
  std::array<Column, 3> axes;
  /// Subtracted from each axis first, in file units (e.g. 32768 for offset-binary counts).
  std::array<double, 3> offset = {0.0, 0.0, 0.0};
  /// SI units per file unit, applied after the offset; finite and non-zero. Examples:
  /// deg/s -> rad/s pi/180; g -> m/s^2 9.80665; MPU-6050 +-2 g counts 9.80665/16384.
  std::array<double, 3> scale = {1.0, 1.0, 1.0};
  /// Body axis i takes sign(m_i) * sensor axis |m_i| (1-based), a signed permutation of
  /// {1, 2, 3}. Default identity; {1, -2, -3} turns FLU (x fwd, y left, z up) into FRD.
  std::array<int, 3> axis_map = {1, 2, 3};
  /// true: the file must hold the three columns. false: read them when the header names all
  /// three, leave the sensor out when it names none of them.
  bool required = true;

  bool given() const { return axes[0].given() || axes[1].given() || axes[2].given(); }
  void SetScale(double s) { scale = {s, s, s}; }
  void SetOffset(double o) { offset = {o, o, o}; }
};

/// One scalar column (temperature) and its conversion: SI = (value - offset) * scale.
struct ScalarColumn {
  Column column;         ///< unset: no such quantity
  double offset = 0.0;   ///< file units, subtracted first
  double scale = 1.0;    ///< SI units per file unit, finite and non-zero
  bool required = true;  ///< false: read it when the header names it, skip it otherwise
};

struct TextTableOptions {
  /// Field separator: ',', ';', '\t', or ' ' (any run of spaces and tabs). 0 = detect from the
  /// first data row: ',' if it has one, else ';', else '\t' if it has tabs and no spaces
  /// between fields, else ' '.
  char delimiter = 0;
  /// Lines dropped at the top before anything else (preambles such as `Fs,100`), >= 0.
  std::size_t skip_lines = 0;
  /// Lines starting with this (after leading blanks) are ignored; empty = no comments. When
  /// there is no header row, the last comment line before the first data row may name the
  /// columns (`# time tx ty tz ...`).
  std::string comment_prefix = "#";
  /// true: the first line after the skipped lines and comments names the columns.
  bool header_row = false;

  /// Time column; unset: time = row index / rate_hz (rows counted from the first data row).
  Column time;
  /// Seconds per file time unit, > 0: 1 for s, 1e-3 for ms, 1e-6 for us, 1/rate for a sample
  /// counter column.
  double time_unit_s = 1.0;
  /// Sample rate, Hz, > 0; used only when there is no time column.
  double rate_hz = 0.0;

  TriadColumns acc;   ///< accelerometer, required (-> m/s^2)
  TriadColumns gyr;   ///< gyroscope (-> rad/s); unset for an accelerometer-only table
  ScalarColumn temp;  ///< sensor temperature (-> degC); unset when there is none

  /// false: a NaN or infinite value is an error naming its line. true: such rows are dropped
  /// and counted in Session::warnings.
  bool allow_nan_rows = false;
};

/// Reads the table at `path`. Session::source is `path`. Times must increase strictly.
Session ReadTextTable(const std::string& path, const TextTableOptions& options);

/// Same as ReadTextTable on text already in memory; `name` stands for the file in errors.
Session ParseTextTable(std::string_view text, const std::string& name,
                       const TextTableOptions& options);

/// Reads an accelerometer table and a gyroscope table sharing their timestamps (imu_tk's
/// two-file layout `t x y z`). `options.acc` locates the triad in `acc_path`, `options.gyr`
/// in `gyr_path`; time, delimiter, header and comment options apply to both; temperature is
/// read from the accelerometer file. The files must have the same number of rows and times
/// equal within 1 us; otherwise an InputError names the first row (line) that differs. The
/// two files are read at once through `run_jobs` when it is given (core/jobs.h).
Session ReadSplitTables(const std::string& acc_path, const std::string& gyr_path,
                        const TextTableOptions& options, const JobRunner& run_jobs = {});

}  // namespace plumb::io

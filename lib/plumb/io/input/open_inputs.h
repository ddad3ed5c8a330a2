// plumb/io/input/open_inputs.h — any input plumb reads, one or several files joined into one
// Session, behind one call:
//
//   InputOptions o;                                   // native CSV or a flight log, by content
//   const Session s = OpenInputs({"session.csv"}, o);
//
//   InputOptions t;                                   // MPU-6050 counts, 100 Hz, no time column
//   t.format = InputFormat::kTable;
//   t.skip_lines = 4;  t.header_row = true;  t.rate_hz = 100;
//   t.columns.acc = {0, 1, 2};  t.columns.gyr = {3, 4, 5};
//   t.acc.unit = AccUnit::kStandardGravity;  t.acc.scale = 1.0 / 16384;
//   t.gyr.unit = GyrUnit::kDegreesPerSecond;  t.gyr.scale = 1.0 / 131;
//   const Session m = OpenInputs({"example_data_calibration.csv"}, t);
//
//   const Session x = OpenInputs({{"xsens_acc.mat", "xsens_gyro.mat"}}, o);  // two-file form
//
// Each input is one of (InputKind):
//   flight log    an ArduPilot DataFlash .bin or text .log, a MAVLink .tlog, a PX4 ULog .ulg, a
//                 ROS 1 bag .bag or a ROS 2 bag (.mcap, .db3),
//                 recognised by its first bytes (flight_log_file.h); `flight_log` selects the
//                 stream, the time window and whether the firmware's correction is undone;
//   native CSV    plumb's own format (native_csv.h), recognised by its header
//                 time_s,acc_x,acc_y,acc_z[,gyr_x,gyr_y,gyr_z][,temp_c];
//   text table    any delimited text (text_table.h), described by the table fields below;
//   two tables    an accelerometer table and a gyroscope table with shared times (imu_tk's
//                 `t x y z` layout), read with ReadSplitTables.
// With InputFormat::kAuto a one-file input is a flight log when its first bytes say so, else
// native CSV, and a file whose header is not native fails with an InputError that says so
// (ending with `not_native_hint`). kNative reads every one-file input as native CSV (no
// flight-log sniffing, the header not checked first); kTable reads every one-file input as a
// text table. The two-file form is always a pair of text tables.
//
// Units: text tables are converted to SI per sensor, value_SI = (value - offset) * scale *
// unit (unit: 9.80665 m/s^2 per g, pi/180 rad per deg), then `axis_map` turns sensor axes
// into body FRD axes. With the unit kCounts the values are taken as unscaled sensor counts
// and the session's acc_unit / gyr_unit say "counts" (for every input, whatever its kind).
//
// The board's other IMUs (InputOptions::all_imus, FlightLogSelection::other_imus) come with
// one input, a flight log or a native CSV, each on its own stamps, in the same window and
// clock as IMU 0.
//
// Several inputs are joined one after the other into one session: a later input's times are
// kept when they start after the previous input's last time, otherwise shifted to start 1000 s
// after it (longer than any motion the calibrator integrates, so no motion is assumed between
// files), with a warning. Every input must carry the same sensors (gyroscope, temperature).
// The joined source is the sources separated by spaces; a later input's warnings and
// firmware_left lines are prefixed with its source; the site is the first input's that has one.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/jobs.h"
#include "plumb/core/session.h"
#include "plumb/io/common/flight_log.h"
#include "plumb/io/common/stream_spool.h"  // AvailableMemory, StreamBound

namespace plumb::io {

/// How one-file inputs are read (see the file comment).
enum class InputFormat {
  kAuto,    ///< a flight log by its first bytes, else native CSV (header checked)
  kNative,  ///< native CSV
  kTable,   ///< a text table described by InputOptions
};

/// What an input turned out to be, as OpenInputs reads it.
/// Which clock the samples' times follow (SPEC 6 "The time base").
enum class Clock {
  kStamps,  ///< the times as the input states them
  /// The uniform sample clock fitted through each input's stamps (signal/time_base.h), the
  /// gaps kept where samples were dropped: for stamps a host wrote on arrival.
  kUniform,
  /// A ROS bag's record times, when the recorder received each message, instead of the
  /// messages' header stamps (FlightLogSelection::receive_time); any other input is refused.
  kReceive
};

enum class InputKind {
  kFlightLog,  ///< ArduPilot .bin/.log, MAVLink .tlog or PX4 .ulg
  kNativeCsv,  ///< plumb's native CSV
  kTextTable,  ///< a delimited text table
  kTwoTables,  ///< an accelerometer table and a gyroscope table (two-file form)
};

/// One input: a file, or the two files of the two-file form. Converts implicitly from a path:
/// `OpenInputs({"a.csv", "b.csv"})` joins two files, `OpenInputs({{"acc.txt", "gyr.txt"}})`
/// reads one pair.
struct InputFile {
  std::string path;        ///< the file; in the two-file form the accelerometer table
  std::string gyr_path;    ///< the gyroscope table of the two-file form
  bool two_files = false;  ///< the two-file form (path and gyr_path), else one file (path)

  InputFile() = default;
  InputFile(std::string file) : path(std::move(file)) {}  // NOLINT(google-explicit-constructor)
  InputFile(const char* file) : path(file) {}             // NOLINT(google-explicit-constructor)
  InputFile(std::string acc_file, std::string gyr_file)
      : path(std::move(acc_file)), gyr_path(std::move(gyr_file)), two_files(true) {}
};

/// Unit of the accelerometer values of a text table.
enum class AccUnit {
  kMetersPerSecond2,  ///< m/s^2 (factor 1)
  kStandardGravity,   ///< g (factor units::kStandardGravity, 9.80665 m/s^2 per g)
  kCounts,            ///< unscaled sensor counts (factor 1; the session's acc_unit "counts")
};

/// Unit of the gyroscope values of a text table.
enum class GyrUnit {
  kRadiansPerSecond,  ///< rad/s (factor 1)
  kDegreesPerSecond,  ///< deg/s (factor units::kRadPerDeg)
  kCounts,            ///< unscaled sensor counts (factor 1; the session's gyr_unit "counts")
};

/// SI units per unit: units::kStandardGravity m/s^2 per g, units::kRadPerDeg rad/s per deg/s,
/// 1 for m/s^2, rad/s and counts (a value in `unit` times this is in SI, or stays counts).
double UnitFactor(AccUnit unit);
double UnitFactor(GyrUnit unit);

/// Conversion of one sensor's table values to SI: (value - offset) * scale * unit factor.
template <typename Unit>
struct SensorScaling {
  Unit unit{};          ///< unit of the values after scale (see AccUnit, GyrUnit)
  double scale = 1.0;   ///< units per file value, finite and non-zero (1/16384 for +-2 g counts)
  double offset = 0.0;  ///< file units, subtracted first (32768 for offset-binary counts)
};

/// Where each quantity is in a one-file text table, by 0-based field index; -1: absent.
struct TableColumns {
  int time = -1;                           ///< time; absent: time = row / rate_hz
  std::array<int, 3> acc = {-1, -1, -1};   ///< accelerometer x, y, z (all three needed)
  std::array<int, 3> gyr = {-1, -1, -1};   ///< gyroscope x, y, z; all -1: no gyroscope
  int temp = -1;                           ///< sensor temperature, degC
};

/// Where the quantities are in each file of the two-file form, by 0-based field index.
struct TwoTableColumns {
  int time = 0;                         ///< time, shared by both files; -1: row / rate_hz
  std::array<int, 3> xyz = {1, 2, 3};   ///< x, y, z: acc in one file, gyr in the other
};

/// How OpenInputs reads its inputs. Every field has a usable default: native CSV and flight
/// logs need none of the table fields.
struct InputOptions {
  InputFormat format = InputFormat::kAuto;

  // ---- Text tables (one-file tables and the two-file form) ----
  /// Field separator: ',', ';', '\t', ' ' (any run of blanks), or 0 to detect it from the
  /// first data row (TextTableOptions::delimiter).
  char delimiter = 0;
  /// Lines dropped at the top of each file, >= 0.
  std::size_t skip_lines = 0;
  /// The first line after the skipped ones (and comments) names the columns (not data).
  bool header_row = false;
  /// Lines starting with this (after leading blanks) are ignored; empty: no comments.
  std::string comment_prefix = "#";
  /// Seconds per unit of the time column, > 0 (1e-3 for ms, 1e-6 for us).
  double time_unit_s = 1.0;
  /// Sample rate, Hz, > 0, used when there is no time column (time = row / rate_hz).
  double rate_hz = 0.0;
  /// Drop rows holding NaN or infinite values (counted in a warning) instead of failing.
  bool drop_nan_rows = false;
  /// Columns of a one-file table (InputKind::kTextTable).
  TableColumns columns;
  /// Columns of each file of the two-file form (InputKind::kTwoTables); default t, x, y, z.
  TwoTableColumns two_table_columns;
  /// Accelerometer values to m/s^2.
  SensorScaling<AccUnit> acc;
  /// Gyroscope values to rad/s.
  SensorScaling<GyrUnit> gyr;
  /// Body axis i takes sign(m_i) * sensor axis |m_i| (1-based), a signed permutation of
  /// {1, 2, 3}, for both sensors; {1, -2, -3} turns FLU into FRD.
  std::array<int, 3> axis_map = {1, 2, 3};

  // ---- Flight logs ----
  /// The stream, the time window (log time, s) and whether the firmware's correction is undone.
  /// The window (from_s, to_s) applies to every input, on its own times: a flight log's log
  /// time, a table's time column or the clock its rate gives (each file of several alike).
  FlightLogSelection flight_log;

  // ---- The board's IMUs (SPEC 6, "Several IMUs of one board") ----
  /// Every IMU the input has besides IMU 0 goes into Session::other_imus (a flight log's other
  /// instances, FlightLogSelection::other_imus then ignored; a native CSV's acc{k}_x.. columns).
  /// Otherwise flight_log.other_imus's instances (a native CSV's k), or none: IMU 0 alone, the
  /// default (a native CSV's other columns are then dropped). A native CSV's IMU 0 is its
  /// acc_x.. columns (flight_log.imu 0). Only one input, a flight log or native CSV, carries
  /// several IMUs; asking them of any other is an InputError.
  bool all_imus = false;

  // ---- Time ----
  /// Clock::kUniform replaces each input's stamps by its fitted uniform clock (said in the
  /// session's warnings, with the jitter removed and the samples found dropped).
  Clock clock = Clock::kStamps;

  // ---- Reporting ----
  /// Ends the InputError for a file that is neither a flight log nor native CSV (kAuto): how
  /// to describe it as a text table in the caller's terms.
  std::string not_native_hint = "describe its columns to read it as a text table";
  /// Called for each input, in order, once its kind is known and before it is read, with its
  /// 0-based index; it may throw to refuse the input (the command line refuses options that do
  /// not fit that kind of input this way). Empty: nothing is called.
  std::function<void(std::size_t input, InputKind kind)> before_read;

  // ---- Work ----
  /// The most bytes an input that gives its bytes once (standard input, a pipe, a FIFO,
  /// process substitution) may hold: it is read whole into memory first (StreamSpool), and
  /// one that goes on past this is refused. 0: the memory available (MemAvailable).
  std::uint64_t max_stream_bytes = 0;
  /// Runs independent jobs at once (core/jobs.h): the two files of the two-file form are read
  /// at once, a large .bin, .tlog or .ulg log in two parts, and a large .mcap's chunks
  /// decompressed ahead of their parse (FlightLog::Open). Empty: one after another. The
  /// session is the same either way.
  JobRunner run_jobs;
};

/// Reads every input (see the file comment) and joins them into one session. Throws
/// plumb::InputError naming the file for unreadable or malformed input (and as the format's
/// reader does), plumb::Error when the inputs cannot be joined (different sensors), when a
/// two-file input is given with InputFormat::kNative, when `inputs` is empty or when the
/// session has no samples; and whatever `before_read` throws.
Session OpenInputs(const std::vector<InputFile>& inputs, const InputOptions& options = {});

/// Peak memory, bytes, a run reading the file at `path` is expected to need (the process, the
/// reader's storage and the decoded samples): kReadMemoryBaseBytes + factor * file size, the
/// factor by format (SniffFlightLog; anything else is a text table):
///   DataFlash .bin and PX4 .ulg (read in two parts when large): kSplitKeptMemoryFactor, text
///   .log: kKeptMemoryFactor, times the share of the file that the session's reader keeps (the
///   bodies of its IMU, parameter and GPS messages, measured on the first
///   kEstimatePrefixBytes: FlightLog reads with ArdupilotSessionRecords / Px4SessionTopics);
///   MAVLink .tlog kTlogMemoryFactor; ROS bags kRosBagMemoryFactor; text tables and CSV
///   kTableMemoryFactor (about 50 bytes per decoded sample). Calibrated on the peak RSS of
///   `plumb info` / `plumb calibrate` on ~450 MB inputs (docs/performance.md, "Memory"),
///   rounded up. A stream held in memory (StreamSpool) is estimated from its copy, whose
///   bytes are added. 0 when `path` cannot be sized (a stream not read yet).
std::uint64_t EstimateReadMemory(const std::string& path);


/// EstimateReadMemory's sample of a log's start, bytes.
inline constexpr std::size_t kEstimatePrefixBytes = std::size_t{8} << 20;
/// Memory per byte of kept record bodies: the bodies, the decoded series (64 bytes per sample
/// against 30-50 bytes per IMU record) and the session's copy of it.
inline constexpr double kKeptMemoryFactor = 3.0;
/// kKeptMemoryFactor for the readers that read a large file in two parts (.bin, .ulg): the
/// second part's half of the decoded series is held twice while joined.
inline constexpr double kSplitKeptMemoryFactor = 3.5;
/// Memory per byte of a .tlog (its frames are kept as decoded messages; read in two parts, the
/// second part's messages are held until joined: 140 MB peak for a 150 MB .tlog).
inline constexpr double kTlogMemoryFactor = 0.85;
/// Memory per byte of a ROS bag: the decoded samples (36 bytes and an 8-byte receive time per
/// sensor_msgs/Imu message of about 370 bytes in the file's records, 3-4 times as many per byte
/// of a bz2 bag) and the session's copies of them; the mapped file's pages are released as
/// the reader passes them (62 MB peak for `plumb info` on a 150 MB uncompressed bag).
inline constexpr double kRosBagMemoryFactor = 1.0;
/// Memory per byte of a text table or CSV.
inline constexpr double kTableMemoryFactor = 0.8;

/// The fixed part of EstimateReadMemory: the process with its libraries (20 MiB).
inline constexpr std::uint64_t kReadMemoryBaseBytes = std::uint64_t{20} << 20;

}  // namespace plumb::io

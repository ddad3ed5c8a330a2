#include "input_options.h"
#include "jobs.h"
#include "progress.h"

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <optional>
#include <sstream>
#include <system_error>

#include "commands.h"
#include "plumb/core/error.h"
#include "plumb/io/input/input_spec.h"
#include "plumb/io/input/open_inputs.h"
#include "validators.h"

namespace plumb::cli {
namespace {

const char* const kTableHint =
    "describe the table, e.g. --columns t,ax,ay,az,gx,gy,gz (by position; '-' skips a column, "
    "no 't' needs --rate HZ), with --skip-lines N, --header, --acc-unit g, --gyr-unit deg/s, "
    "--acc-scale, --acc-offset (see 'plumb calibrate --help')";

/// Turns the flags that describe a table (one-file, or each file of the two-file form when
/// `two_files`) into `o`: --delimiter, --columns, --acc-scale, --gyr-scale, --axis-map, in that
/// order. Returns the message of the first malformed one, "" when all are well formed. A
/// malformed table flag is refused only when a table is read (see ReadInputs).
std::string TableFlags(const InputArgs& a, bool two_files, io::InputOptions* o) {
  try {
    const io::ColumnOptionNames names{"--columns", "--rate HZ"};
    o->delimiter = io::ParseDelimiter(a.delimiter, "--delimiter");
    if (two_files) {
      o->two_table_columns =
          io::ParseTwoTableColumns(a.columns.empty() ? "t,x,y,z" : a.columns, a.rate_hz, names);
    } else {
      o->columns = io::ParseTableColumns(a.columns, a.rate_hz, names);
    }
    o->acc.scale = io::ParseScale(a.acc_scale, "--acc-scale");
    o->gyr.scale = io::ParseScale(a.gyr_scale, "--gyr-scale");
    o->axis_map = io::ParseAxisMap(a.axis_map, "--axis-map");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

bool TableOptionsGiven(const InputArgs& args) {
  for (const CLI::Option* o : args.table_only) {
    if (o->count() > 0) return true;
  }
  return false;
}

/// --imus into `o` (io::InputOptions::all_imus, FlightLogSelection::imu and other_imus): "all",
/// or instances of which the first is IMU 0 (--imu, if given, must agree).
void SetBoard(const InputArgs& a, io::InputOptions& o) {
  if (a.imus.empty()) return;
  if (a.imus == "all") {
    o.all_imus = true;
    return;
  }
  std::vector<int> instances;
  for (const std::string& field : io::SplitList(a.imus, ',')) {
    int k = -1;
    const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), k);
    if (error != std::errc() || end != field.data() + field.size() || k < 0) {
      throw UsageError("--imus " + a.imus + ": give 'all' or instances as 0,1,2 (0-based)");
    }
    instances.push_back(k);
  }
  if (a.imu_given != nullptr && a.imu_given->count() > 0 && a.imu != instances.front()) {
    throw UsageError("--imu " + std::to_string(a.imu) + " and --imus " + a.imus +
                     " name different IMUs 0; give one");
  }
  o.flight_log.imu = instances.front();
  o.flight_log.other_imus.assign(instances.begin() + 1, instances.end());
}

/// The library's options from the flags, with `before_read` refusing, input by input, what the
/// command line does not accept for that kind of input: a malformed INPUT, the two-file form
/// with --format native, --format table without --columns, malformed table flags when a table
/// is read, table flags given in vain to a native CSV. `inputs` are the INPUT texts as given
/// (`acc,gyr` pairs included); the options refer to them and must not outlive them.
io::InputOptions MakeInputOptions(const InputArgs& a, const std::vector<std::string>& inputs) {
  io::InputOptions o;
  const bool table_asked = a.format == "table" || !a.columns.empty();
  o.format = table_asked             ? io::InputFormat::kTable
             : a.format == "native" ? io::InputFormat::kNative
                                     : io::InputFormat::kAuto;
  const std::string two_table_error = TableFlags(a, true, &o);
  const std::string table_error = TableFlags(a, false, &o);
  o.skip_lines = a.skip_lines;
  o.header_row = a.header;
  o.comment_prefix = a.comment;
  o.time_unit_s = a.time_unit_s;
  o.rate_hz = a.rate_hz;
  o.drop_nan_rows = a.drop_nan;
  o.clock = a.clock == "uniform"   ? io::Clock::kUniform
            : a.clock == "receive" ? io::Clock::kReceive
                                   : io::Clock::kStamps;
  o.acc.unit = a.acc_unit == "g"        ? io::AccUnit::kStandardGravity
               : a.acc_unit == "counts" ? io::AccUnit::kCounts
                                        : io::AccUnit::kMetersPerSecond2;
  o.gyr.unit = a.gyr_unit == "deg/s"    ? io::GyrUnit::kDegreesPerSecond
               : a.gyr_unit == "counts" ? io::GyrUnit::kCounts
                                        : io::GyrUnit::kRadiansPerSecond;
  o.acc.offset = a.acc_offset;
  o.gyr.offset = a.gyr_offset;
  o.flight_log.imu = a.imu;
  SetBoard(a, o);
  // --topic names a ROS bag's topic, --stream a log's message or topic: the library keeps
  // either in FlightLogSelection::stream (a bag's streams are its topics).
  if (!a.topic.empty() && !a.stream.empty() && a.topic != a.stream) {
    throw UsageError("--topic " + a.topic + " and --stream " + a.stream +
                     " name different streams; give one");
  }
  o.flight_log.stream = a.topic.empty() ? a.stream : a.topic;
  if (a.from != nullptr && a.from->count() > 0) o.flight_log.from_s = a.from_s;
  if (a.to != nullptr && a.to->count() > 0) o.flight_log.to_s = a.to_s;
  o.flight_log.undo_correction = !a.as_logged;
  o.not_native_hint = kTableHint;
  o.before_read = [&a, &inputs, table_error, two_table_error](std::size_t i, io::InputKind kind) {
    const std::string& input = inputs[i];
    const std::size_t parts = io::SplitList(input, ',').size();
    if (parts != 1 && parts != 2) {
      throw UsageError("input '" + input + "': give one file, or two as acc.txt,gyr.txt");
    }
    switch (kind) {
      case io::InputKind::kTwoTables:
        if (a.format == "native") {
          throw UsageError("the two-file form '" + input + "' is a table, not native CSV");
        }
        if (!two_table_error.empty()) throw UsageError(two_table_error);
        break;
      case io::InputKind::kTextTable:
        if (a.columns.empty()) {
          throw UsageError("--format table needs --columns; " + std::string(kTableHint));
        }
        if (!table_error.empty()) throw UsageError(table_error);
        break;
      case io::InputKind::kNativeCsv:
        if (TableOptionsGiven(a)) {
          throw UsageError(
              "table options (--rate, --skip-lines, ...) describe a text table: give "
              "--columns too");
        }
        break;
      case io::InputKind::kFlightLog:
        break;
    }
  };
  return o;
}

}  // namespace

void AddInputFiles(const InputArgs& args, FileRoles& roles) {
  for (const std::string& input : args.inputs) {
    for (const std::string& file : InputFiles(input)) roles.inputs.push_back({"INPUT", file});
  }
  if (!args.acc_file.empty()) roles.inputs.push_back({"--acc", args.acc_file});
  if (!args.gyr_file.empty()) roles.inputs.push_back({"--gyr", args.gyr_file});
}

void AddInputOptions(CLI::App* app, InputArgs& a, bool board) {
  app->add_option("INPUT", a.inputs,
                  "Input files: plumb's native CSV, a text table (see --columns), an "
                  "accelerometer and a gyroscope table as acc.txt,gyr.txt, or a flight log: "
                  "ArduPilot DataFlash .bin or text .log, MAVLink .tlog, PX4 ULog .ulg, ROS 1 "
                  ".bag, ROS 2 .mcap or .db3 (recognised by their first bytes)")
      ->type_name("FILE...");
  auto* logs = app->add_option_group(
      "Flight logs", "Reading an ArduPilot .bin/.log, MAVLink .tlog or PX4 .ulg log, or a ROS "
                     "bag (`plumb info LOG` lists its IMU streams)");
  a.imu_given =
      logs->add_option("--imu", a.imu, "IMU instance of the log, 0-based (IMU = 0, IMU2 = 1, ...)")
          ->check(NonNegative)
          ->capture_default_str();
  if (board) {
    logs->add_option("--imus", a.imus,
                     "The board's IMUs fitted together (one input: a flight log, or a native "
                     "CSV with acc1_x.. columns): 'all', or instances as 0,1,2, the first "
                     "IMU 0, whose accelerometer defines the body frame; the still attitudes "
                     "are shared, each IMU has its model and its rotation into the body")
        ->type_name("all|K,K,...");
  }
  logs->add_option("--stream", a.stream,
                   "IMU stream (message or topic) of that instance, as `plumb info` names it, "
                   "e.g. IMU, ACC+GYR, ISBD_ACC, SCALED_IMU2, sensor_combined, vehicle_imu, "
                   "sensor_accel; default: the one with accelerometer and gyroscope at the "
                   "highest rate")
      ->type_name("NAME");
  logs->add_option("--topic", a.topic,
                   "sensor_msgs/Imu topic of a ROS bag, as `plumb info` names it (e.g. "
                   "/imu/data_raw); default: the bag's only IMU topic")
      ->type_name("NAME");
  a.from = logs->add_option("--from", a.from_s,
                            "Use the samples from this time on, s (a log's time, a table's "
                            "time column or its --rate clock)");
  a.to = logs->add_option("--to", a.to_s,
                          "Use the samples up to this time, s (as --from)");
  logs->add_flag("--as-logged", a.as_logged,
                 "Keep the firmware's correction (ArduPilot INS_*, PX4 CAL_*/TC_*) in the "
                 "samples instead of undoing it (the calibration is then of the corrected "
                 "signal)");
  AddMaxMemoryOption(app, a.max_memory);
  app->add_option("--clock", a.clock,
                  "Which clock the times follow: stamps (as read), or uniform (the sample "
                  "clock fitted through each input's stamps, keeping the gaps where samples "
                  "were dropped: for stamps a host wrote on arrival; `plumb info` and "
                  "`plumb diagnose` say which the stamps are), or receive (a ROS bag's record "
                  "times, when the recorder received each message, instead of the header "
                  "stamps)")
      ->check(CLI::IsMember({"stamps", "uniform", "receive"}))
      ->capture_default_str();
  app->add_option("--acc", a.acc_file,
                  "Accelerometer table of the two-file form (imu_tk's `t x y z`), with --gyr")
      ->type_name("FILE");
  app->add_option("--gyr", a.gyr_file, "Gyroscope table of the two-file form, with --acc")
      ->type_name("FILE");
  app->add_option("--format", a.format,
                  "auto: native CSV when its header is found, a table when --columns is given; "
                  "native: insist on the native CSV; table: a text table (needs --columns)")
      ->check(CLI::IsMember({"auto", "native", "table"}))
      ->capture_default_str();
  auto* group = app->add_option_group("Text tables", "Describing a text table (not native CSV)");
  a.table_only = {
      group->add_option("--columns", a.columns,
                        "What each column holds, by position: t (time), ax ay az (accel), gx gy "
                        "gz (gyro), temp (degC), - (skip), e.g. -,ax,ay,az,gx,gy,gz; two-file "
                        "form: t,x,y,z (the default there)"),
      group->add_option("--delimiter", a.delimiter,
                        "Field separator: , ; tab space (default: detected from the first row)"),
      group->add_option("--skip-lines", a.skip_lines, "Lines dropped at the top of each file")
          ->check(NonNegative),
      group->add_flag("--header", a.header,
                      "The first line after the skipped ones is a header row (not data)"),
      group->add_option("--comment", a.comment,
                        "Comment prefix; such lines are ignored (default #, '' for none)"),
      group
          ->add_option("--time-scale", a.time_unit_s,
                       "Seconds per unit of the time column (1e-3 for ms, 1e-6 for us)")
          ->check(Positive),
      group
          ->add_option("--rate", a.rate_hz,
                       "Sample rate, Hz, when the table has no time column (time = row / rate)")
          ->check(SampleRate),
      group->add_option("--acc-unit", a.acc_unit,
                        "Accelerometer unit in the file: m/s^2, g, or counts (unscaled sensor "
                        "output: calibrated in counts, the matrix then in counts per m/s^2)")
          ->check(CLI::IsMember({"m/s^2", "m/s2", "g", "counts"})),
      group->add_option("--acc-scale", a.acc_scale,
                        "Accelerometer units per count, number or fraction (1/16384 for a +-2 g "
                        "MPU-6050 with --acc-unit g); SI = (value - offset) * scale * unit"),
      group->add_option("--acc-offset", a.acc_offset,
                        "Subtracted from every accelerometer value first, file units (32768 for "
                        "offset-binary counts)"),
      group->add_option("--gyr-unit", a.gyr_unit,
                        "Gyroscope unit in the file: rad/s, deg/s, or counts (unscaled sensor "
                        "output: calibrated in counts, the matrix then in counts per rad/s)")
          ->check(CLI::IsMember({"rad/s", "deg/s", "counts"})),
      group->add_option("--gyr-scale", a.gyr_scale,
                        "Gyroscope units per count, number or fraction (1/131 for a +-250 deg/s "
                        "MPU-6050 with --gyr-unit deg/s)"),
      group->add_option("--gyr-offset", a.gyr_offset,
                        "Subtracted from every gyroscope value first, file units"),
      group->add_option("--axis-map", a.axis_map,
                        "Body axis i takes sign * sensor axis |m_i|, e.g. 1,-2,-3 turns FLU "
                        "(x fwd, y left, z up) into FRD (default 1,2,3)"),
      group->add_flag("--drop-nan", a.drop_nan,
                      "Drop rows holding NaN or infinite values (counted in a warning) instead "
                      "of failing"),
  };
}

void AddMaxMemoryOption(CLI::App* app, std::uint64_t& max_memory) {
  app->add_option("--max-memory", max_memory,
                  "Refuse inputs whose estimated memory exceeds SIZE (bytes, a whole number with an "
                  "optional unit: 500M, 2G, 2GiB); a pipe or standard input is read whole "
                  "first and refused once it goes on past SIZE; "
                  "default: the memory available (MemAvailable)")
      ->transform(CLI::AsSizeValue(true))
      ->type_name("SIZE");
}

std::string FormatBytes(std::uint64_t bytes) {
  static const char* const kUnits[] = {"B", "kB", "MB", "GB", "TB"};
  double v = static_cast<double>(bytes);
  std::size_t u = 0;
  while (v >= 1000.0 && u + 1 < std::size(kUnits)) {
    v /= 1000.0;
    ++u;
  }
  std::ostringstream out;
  out << std::setprecision(3) << v << " " << kUnits[u];
  return out.str();
}

std::uint64_t CheckMemory(const std::vector<std::string>& files, std::uint64_t max_memory) {
  std::uint64_t need = 0;
  std::string names;
  for (const std::string& f : files) {
    const std::uint64_t e = io::EstimateReadMemory(f);
    if (e == 0) continue;  // not a regular file: its reader says what is wrong
    // The process itself counts once, however many files are read.
    need += need == 0 ? e : e - io::kReadMemoryBaseBytes;
    names += (names.empty() ? "" : ", ") + f;
  }
  const std::optional<std::uint64_t> available =
      max_memory > 0 ? std::optional<std::uint64_t>(max_memory) : io::AvailableMemory();
  if (need == 0 || !available || need <= *available) return need;
  throw Error("reading " + names + " needs about " + FormatBytes(need) + "; " +
              FormatBytes(*available) + " is available (" +
              (max_memory > 0 ? "--max-memory" : "MemAvailable in /proc/meminfo") + ")");
}

Session ReadInputs(const InputArgs& a, int jobs) {
  std::vector<std::string> inputs = a.inputs;
  if (!a.acc_file.empty() || !a.gyr_file.empty()) {
    if (a.acc_file.empty() || a.gyr_file.empty()) {
      throw UsageError("the two-file form needs both --acc FILE and --gyr FILE");
    }
    inputs.push_back(a.acc_file + "," + a.gyr_file);
  }
  if (inputs.empty()) throw UsageError("no input: give INPUT files (or --acc FILE --gyr FILE)");
  if (a.format == "native" && TableOptionsGiven(a)) {
    throw UsageError("--format native takes no table options (--columns, --rate, ...)");
  }
  std::string names;
  for (const std::string& input : inputs) names += (names.empty() ? "" : ", ") + input;
  std::vector<io::InputFile> files;
  std::vector<std::string> paths;
  for (const std::string& input : inputs) {
    const auto parts = io::SplitList(input, ',');
    files.push_back(parts.size() == 2 ? io::InputFile(parts[0], parts[1]) : io::InputFile(input));
    paths.insert(paths.end(), parts.begin(), parts.end());
  }
  // A pipe or standard input is read whole first (within --max-memory), then estimated.
  const io::StreamSpool streams(paths, io::StreamBound(a.max_memory));
  CheckMemory(paths, a.max_memory);
  Progress::Of().Stage("reading " + names);
  io::InputOptions options = MakeInputOptions(a, inputs);
  options.max_stream_bytes = a.max_memory;
  options.run_jobs = ParallelJobs(jobs);
  return io::OpenInputs(files, options);
}

}  // namespace plumb::cli

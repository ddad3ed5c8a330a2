#include "input_options.h"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include "commands.h"
#include "plumb/core/error.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/io/text/native_csv.h"

namespace plumb::cli {
namespace {

constexpr double kStandardGravity = 9.80665;  // m/s^2 per g
constexpr double kDegToRad = M_PI / 180.0;
/// Time gap put between joined inputs whose clocks overlap, s: longer than the calibrator's
/// longest integrated motion (120 s), so no motion is assumed across files.
constexpr double kJoinGap_s = 1000.0;

const char* const kTableHint =
    "describe the table, e.g. --columns t,ax,ay,az,gx,gy,gz (by position; '-' skips a column, "
    "no 't' needs --rate HZ), with --skip-lines N, --header, --acc-unit g, --gyr-unit deg/s, "
    "--acc-scale, --acc-offset (see 'plumb calibrate --help')";

std::vector<std::string> SplitList(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, sep)) {
    const auto b = item.find_first_not_of(" \t");
    const auto e = item.find_last_not_of(" \t");
    out.push_back(b == std::string::npos ? "" : item.substr(b, e - b + 1));
  }
  return out;
}

bool ParseDouble(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return errno == 0 && end == text.c_str() + text.size() && std::isfinite(value);
}

char Delimiter(const std::string& name) {
  if (name.empty()) return 0;
  if (name == "," || name == "comma") return ',';
  if (name == ";" || name == "semicolon") return ';';
  if (name == "tab" || name == "\\t" || name == "\t") return '\t';
  if (name == "space" || name == " ") return ' ';
  throw UsageError("--delimiter must be one of , ; tab space (got '" + name + "')");
}

/// The first line that is neither blank nor a comment, or "" when there is none.
std::string FirstContentLine(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "", std::string("cannot open the file: ") + std::strerror(errno));
  std::string line;
  for (int n = 0; n < 1000 && std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    return line;
  }
  return "";
}

bool IsNativeHeader(const std::string& line) {
  int found = 0;
  for (const auto& name : SplitList(line, ',')) {
    found += name == "time_s" || name == "acc_x" || name == "acc_y" || name == "acc_z";
  }
  return found == 4;
}

/// Reads one file in the native format, or fails telling how to describe another layout.
Session ReadNative(const std::string& path, bool insist) {
  const std::string first = FirstContentLine(path);
  // An empty file (or a missing one) gets the reader's own message.
  if (first.empty()) return io::ReadNativeCsv(path);
  if (!insist && !IsNativeHeader(first)) {
    throw InputError(path, "",
                     "not plumb's native CSV (header time_s,acc_x,acc_y,acc_z[,gyr_x,gyr_y,gyr_z]"
                     "[,temp_c] expected, found '" +
                         first.substr(0, 60) + "'); " + kTableHint);
  }
  return io::ReadNativeCsv(path);
}

std::array<int, 3> AxisMap(const std::string& text) {
  const auto items = SplitList(text, ',');
  std::array<int, 3> map{};
  bool ok = items.size() == 3;
  for (std::size_t i = 0; ok && i < 3; ++i) {
    double v = 0;
    ok = ParseDouble(items[i], v) && v == std::round(v) && std::abs(v) >= 1 && std::abs(v) <= 3;
    map[i] = static_cast<int>(v);
  }
  if (!ok)
    throw UsageError("--axis-map must be three signed axes such as 1,-2,-3 (got '" + text + "')");
  return map;
}

/// Applies the --columns spec. Tokens: t, ax ay az, gx gy gz, temp, '-' (or empty) to skip;
/// in two-file form t, x, y, z.
void AssignColumns(const std::string& spec, bool split, io::TextTableOptions& o) {
  const auto tokens = SplitList(spec, ',');
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string& tok = tokens[i];
    const int index = static_cast<int>(i);
    const auto set_once = [&](io::Column& column) {
      if (column.given()) throw UsageError("--columns names '" + tok + "' twice in '" + spec + "'");
      column = index;
    };
    if (tok == "-" || tok.empty()) continue;
    if (tok == "t" || tok == "time") {
      set_once(o.time);
    } else if (!split && (tok == "temp" || tok == "temp_c")) {
      set_once(o.temp.column);
    } else if (split && tok.size() == 1 && tok[0] >= 'x' && tok[0] <= 'z') {
      set_once(o.acc.axes[static_cast<std::size_t>(tok[0] - 'x')]);
      o.gyr.axes[static_cast<std::size_t>(tok[0] - 'x')] = index;
    } else if (!split && tok.size() == 2 && (tok[0] == 'a' || tok[0] == 'g') && tok[1] >= 'x' &&
               tok[1] <= 'z') {
      auto& triad = tok[0] == 'a' ? o.acc : o.gyr;
      set_once(triad.axes[static_cast<std::size_t>(tok[1] - 'x')]);
    } else {
      throw UsageError("--columns: unknown column '" + tok + "' in '" + spec + "'; use " +
                       (split ? "t, x, y, z" : "t, ax, ay, az, gx, gy, gz, temp") +
                       " or - to skip a column");
    }
  }
  const auto complete = [](const io::TriadColumns& t) {
    return t.axes[0].given() && t.axes[1].given() && t.axes[2].given();
  };
  if (!complete(o.acc)) {
    throw UsageError("--columns '" + spec + "' must name all three accelerometer columns (" +
                     (split ? "x,y,z" : "ax,ay,az") + ")");
  }
  if (o.gyr.given() && !complete(o.gyr)) {
    throw UsageError("--columns '" + spec + "' names only part of the gyroscope (gx,gy,gz)");
  }
  if (!o.time.given() && !(o.rate_hz > 0)) {
    throw UsageError("--columns '" + spec + "' has no time column (t): give --rate HZ");
  }
}

/// Joins `next` after `joined`, keeping the clock when it increases.
void Append(Session& joined, Session next) {
  ImuSeries& a = joined.series;
  ImuSeries& b = next.series;
  if (a.has_gyro() != b.has_gyro() || a.has_temperature() != b.has_temperature()) {
    throw Error("cannot join " + next.source + " to " + joined.source +
                ": one has a gyroscope or temperature column that the other lacks");
  }
  double shift = 0.0;
  if (!a.empty() && !b.empty() && b.t_s.front() <= a.t_s.back()) {
    shift = a.t_s.back() + kJoinGap_s - b.t_s.front();
    joined.warnings.push_back(next.source +
                              ": its times overlap the previous input's; shifted by " +
                              std::to_string(shift) + " s (no motion assumed between files)");
  }
  for (double t : b.t_s) a.t_s.push_back(t + shift);
  a.acc.insert(a.acc.end(), b.acc.begin(), b.acc.end());
  a.gyr.insert(a.gyr.end(), b.gyr.begin(), b.gyr.end());
  a.temp_c.insert(a.temp_c.end(), b.temp_c.begin(), b.temp_c.end());
  joined.source += " " + next.source;
  for (auto& w : next.warnings) joined.warnings.push_back(next.source + ": " + w);
  for (auto& l : next.firmware_left) joined.firmware_left.push_back(next.source + ": " + l);
  if (!joined.site) joined.site = next.site;
}

bool TableOptionsGiven(const InputArgs& args) {
  for (const CLI::Option* o : args.table_only) {
    if (o->count() > 0) return true;
  }
  return false;
}

}  // namespace

double ParseScale(const std::string& text, const std::string& option) {
  const auto parts = SplitList(text, '/');
  double num = 0, den = 1;
  const bool ok = (parts.size() == 1 || parts.size() == 2) && ParseDouble(parts[0], num) &&
                  (parts.size() == 1 || ParseDouble(parts[1], den)) && den != 0.0 && num != 0.0;
  if (!ok) {
    throw UsageError(option +
                     " must be a non-zero number or a fraction such as 9.80665/16384 "
                     "(got '" +
                     text + "')");
  }
  return num / den;
}

void AddInputOptions(CLI::App* app, InputArgs& a) {
  app->add_option("INPUT", a.inputs,
                  "Input files: plumb's native CSV, a text table (see --columns), an "
                  "accelerometer and a gyroscope table as acc.txt,gyr.txt, or a flight log: "
                  "ArduPilot DataFlash .bin or text .log, MAVLink .tlog, PX4 ULog .ulg "
                  "(recognised by their first bytes)")
      ->type_name("FILE...");
  auto* logs = app->add_option_group(
      "Flight logs", "Reading an ArduPilot .bin/.log, MAVLink .tlog or PX4 .ulg log "
                     "(`plumb info LOG` lists its IMU streams)");
  logs->add_option("--imu", a.imu, "IMU instance of the log, 0-based (IMU = 0, IMU2 = 1, ...)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  logs->add_option("--stream", a.stream,
                   "IMU stream (message or topic) of that instance, as `plumb info` names it, "
                   "e.g. IMU, ACC+GYR, ISBD_ACC, SCALED_IMU2, sensor_combined, vehicle_imu, "
                   "sensor_accel; default: the one with accelerometer and gyroscope at the "
                   "highest rate")
      ->type_name("NAME");
  a.from = logs->add_option("--from", a.from_s, "Use the samples from this log time on, s");
  a.to = logs->add_option("--to", a.to_s, "Use the samples up to this log time, s");
  logs->add_flag("--as-logged", a.as_logged,
                 "Keep the firmware's correction (ArduPilot INS_*, PX4 CAL_*/TC_*) in the "
                 "samples instead of undoing it (the calibration is then of the corrected "
                 "signal)");
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
      group->add_option("--skip-lines", a.skip_lines, "Lines dropped at the top of each file"),
      group->add_flag("--header", a.header,
                      "The first line after the skipped ones is a header row (not data)"),
      group->add_option("--comment", a.comment,
                        "Comment prefix; such lines are ignored (default #, '' for none)"),
      group
          ->add_option("--time-scale", a.time_unit_s,
                       "Seconds per unit of the time column (1e-3 for ms, 1e-6 for us)")
          ->check(CLI::PositiveNumber),
      group
          ->add_option("--rate", a.rate_hz,
                       "Sample rate, Hz, when the table has no time column (time = row / rate)")
          ->check(CLI::PositiveNumber),
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

io::TextTableOptions MakeTableOptions(const InputArgs& a, bool split) {
  io::TextTableOptions o;
  o.delimiter = Delimiter(a.delimiter);
  o.skip_lines = a.skip_lines;
  o.header_row = a.header;
  o.comment_prefix = a.comment;
  o.time_unit_s = a.time_unit_s;
  o.rate_hz = a.rate_hz;
  o.allow_nan_rows = a.drop_nan;
  AssignColumns(a.columns.empty() && split ? "t,x,y,z" : a.columns, split, o);
  const double acc_unit = a.acc_unit == "g" ? kStandardGravity : 1.0;
  const double gyr_unit = a.gyr_unit == "deg/s" ? kDegToRad : 1.0;
  o.acc.SetScale(ParseScale(a.acc_scale, "--acc-scale") * acc_unit);
  o.gyr.SetScale(ParseScale(a.gyr_scale, "--gyr-scale") * gyr_unit);
  o.acc.SetOffset(a.acc_offset);
  o.gyr.SetOffset(a.gyr_offset);
  o.acc.axis_map = o.gyr.axis_map = AxisMap(a.axis_map);
  return o;
}

Session ReadInputs(const InputArgs& a) {
  std::vector<std::string> inputs = a.inputs;
  if (!a.acc_file.empty() || !a.gyr_file.empty()) {
    if (a.acc_file.empty() || a.gyr_file.empty()) {
      throw UsageError("the two-file form needs both --acc FILE and --gyr FILE");
    }
    inputs.push_back(a.acc_file + "," + a.gyr_file);
  }
  if (inputs.empty()) throw UsageError("no input: give INPUT files (or --acc FILE --gyr FILE)");
  const bool table_asked = a.format == "table" || !a.columns.empty();
  if (a.format == "native" && TableOptionsGiven(a)) {
    throw UsageError("--format native takes no table options (--columns, --rate, ...)");
  }
  std::optional<Session> joined;
  for (const auto& input : inputs) {
    const auto parts = SplitList(input, ',');
    Session s;
    if (parts.size() == 2) {
      if (a.format == "native")
        throw UsageError("the two-file form '" + input + "' is a table, not native CSV");
      s = io::ReadSplitTables(parts[0], parts[1], MakeTableOptions(a, true));
    } else if (parts.size() != 1) {
      throw UsageError("input '" + input + "': give one file, or two as acc.txt,gyr.txt");
    } else if (!table_asked && a.format != "native" &&
               io::SniffFlightLog(input) != io::FlightLogFormat::kNone) {
      io::FlightLogSelection o;
      o.imu = a.imu;
      o.stream = a.stream;
      if (a.from != nullptr && a.from->count() > 0) o.from_s = a.from_s;
      if (a.to != nullptr && a.to->count() > 0) o.to_s = a.to_s;
      o.undo_correction = !a.as_logged;
      s = io::FlightLog::Open(input).Select(o);
    } else if (table_asked) {
      if (a.columns.empty())
        throw UsageError("--format table needs --columns; " + std::string(kTableHint));
      s = io::ReadTextTable(input, MakeTableOptions(a, false));
    } else {
      if (TableOptionsGiven(a)) {
        throw UsageError(
            "table options (--rate, --skip-lines, ...) describe a text table: give "
            "--columns too");
      }
      s = ReadNative(input, a.format == "native");
    }
    if (a.acc_unit == "counts") s.series.acc_unit = "counts";
    if (a.gyr_unit == "counts") s.series.gyr_unit = "counts";
    if (!joined) {
      joined = std::move(s);
    } else {
      Append(*joined, std::move(s));
    }
  }
  if (joined->series.empty()) throw Error(joined->source + ": no samples");
  return std::move(*joined);
}

}  // namespace plumb::cli

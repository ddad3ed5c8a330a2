// plumb/io/input/open_inputs.cc — see open_inputs.h.
#include "plumb/io/input/open_inputs.h"

#include <algorithm>
#include <cstdint>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>
#include <string_view>

#include <sys/stat.h>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/text_scan.h"
#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/io/px4/px4_session.h"
#include "plumb/io/px4/ulog.h"
#include "plumb/io/text/native_csv.h"
#include "plumb/io/text/text_table.h"
#include "plumb/signal/time_base.h"
#include "plumb/io/common/stream_spool.h"

namespace plumb::io {
namespace {

/// Time gap put between joined inputs whose clocks overlap, s: longer than the calibrator's
/// longest integrated motion (120 s), so no motion is assumed across files.
constexpr double kJoinGap_s = 1000.0;

/// A header line is looked for in the first 64 KiB, lines cut at 4 KiB: a binary file with
/// no newline is not read whole to find one.
constexpr std::streamsize kHeaderSearchBytes = 64 * 1024;
constexpr std::streamsize kHeaderLineBytes = 4 * 1024;

/// The first line that is neither blank nor a comment, or "" when there is none.
std::string FirstContentLine(const std::string& path) {
  std::ifstream in(OpenPath(path), std::ios::binary);
  if (!in) throw InputError(path, "", std::string("cannot open the file: ") + std::strerror(errno));
  std::string head(kHeaderSearchBytes, '\0');
  in.read(head.data(), kHeaderSearchBytes);
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::istringstream lines(head);
  std::string line;
  for (int n = 0; n < 1000 && std::getline(lines, line); ++n) {
    if (line.size() > static_cast<std::size_t>(kHeaderLineBytes)) line.resize(kHeaderLineBytes);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    return line;
  }
  return "";
}

/// True when the comma-separated `line` names time_s, acc_x, acc_y and acc_z.
bool IsNativeHeader(std::string_view line) {
  int found = 0;
  detail::FieldCursor fields(line, ',');
  std::string_view name;
  while (fields.Next(name)) {
    found += name == "time_s" || name == "acc_x" || name == "acc_y" || name == "acc_z";
  }
  return found == 4;
}

/// True when `line` holds bytes text does not: NUL and the other control bytes but tab, CR,
/// LF and form feed.
bool LooksBinary(std::string_view line) {
  return std::any_of(line.begin(), line.end(), [](char ch) {
    const auto c = static_cast<unsigned char>(ch);
    return (c < 0x20 && c != '\t' && c != '\r' && c != '\n' && c != '\f') || c == 0x7f;
  });
}

/// Reads one file in the native format; unless `insist`, first checks its header and fails
/// with `hint` when it is not native CSV.
Session ReadNative(const std::string& path, bool insist, const std::string& hint) {
  const std::string first = FirstContentLine(path);
  // An empty file (or a missing one) gets the reader's own message.
  if (first.empty()) return ReadNativeCsv(path);
  if (!insist && LooksBinary(first)) {
    throw InputError(path, "",
                     "neither a flight log plumb recognises by its first bytes (ArduPilot "
                     "DataFlash .bin, MAVLink .tlog, PX4 .ulg) nor text: it starts '" +
                         Printable(first, 24) + "' (a damaged log, or a format plumb does not read)");
  }
  if (!insist && !IsNativeHeader(first)) {
    throw InputError(path, "",
                     "not plumb's native CSV (header time_s,acc_x,acc_y,acc_z[,gyr_x,gyr_y,gyr_z]"
                     "[,temp_c] expected, found '" +
                         Printable(first, 60) + "'); " + hint);
  }
  return ReadNativeCsv(path);
}

/// The text-table options of a one-file table, or of each file of the two-file form.
TextTableOptions TableOptions(const InputOptions& o, bool two_files) {
  TextTableOptions t;
  t.delimiter = o.delimiter;
  t.skip_lines = o.skip_lines;
  t.header_row = o.header_row;
  t.comment_prefix = o.comment_prefix;
  t.time_unit_s = o.time_unit_s;
  t.rate_hz = o.rate_hz;
  t.allow_nan_rows = o.drop_nan_rows;
  if (two_files) {
    const TwoTableColumns& c = o.two_table_columns;
    if (c.time >= 0) t.time = c.time;
    for (std::size_t i = 0; i < 3; ++i) {
      if (c.xyz[i] >= 0) t.acc.axes[i] = t.gyr.axes[i] = c.xyz[i];
    }
  } else {
    const TableColumns& c = o.columns;
    if (c.time >= 0) t.time = c.time;
    if (c.temp >= 0) t.temp.column = c.temp;
    for (std::size_t i = 0; i < 3; ++i) {
      if (c.acc[i] >= 0) t.acc.axes[i] = c.acc[i];
      if (c.gyr[i] >= 0) t.gyr.axes[i] = c.gyr[i];
    }
  }
  t.acc.SetScale(o.acc.scale * UnitFactor(o.acc.unit));
  t.gyr.SetScale(o.gyr.scale * UnitFactor(o.gyr.unit));
  t.acc.SetOffset(o.acc.offset);
  t.gyr.SetOffset(o.gyr.offset);
  t.acc.axis_map = t.gyr.axis_map = o.axis_map;
  return t;
}

InputKind KindOf(const InputFile& input, const InputOptions& o) {
  if (input.two_files) return InputKind::kTwoTables;
  if (o.format == InputFormat::kTable) return InputKind::kTextTable;
  if (o.format == InputFormat::kAuto && SniffFlightLog(input.path) != FlightLogFormat::kNone) {
    return InputKind::kFlightLog;
  }
  return InputKind::kNativeCsv;
}

/// The samples of `in` inside the time window [from_s, to_s] (the file's own times: its time
/// column, or the clock InputOptions::rate_hz gives), as a flight log's reader keeps its
/// window. Throws InputError naming `source` when fewer than 2 samples are left.
void KeepWindow(ImuSeries& in, const FlightLogSelection& window, const std::string& source) {
  if (!window.from_s && !window.to_s) return;
  if (in.empty()) return;
  const double t_start = in.t_s.front(), t_end = in.t_s.back();
  ImuSeries out;
  out.acc_unit = in.acc_unit;
  out.gyr_unit = in.gyr_unit;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const double t = in.t_s[i];
    if ((window.from_s && t < *window.from_s) || (window.to_s && t > *window.to_s)) continue;
    out.t_s.push_back(t);
    out.acc.push_back(in.acc[i]);
    if (in.has_gyro()) out.gyr.push_back(in.gyr[i]);
    if (in.has_temperature()) out.temp_c.push_back(in.temp_c[i]);
  }
  if (out.size() < 2) {
    throw InputError(source, "", EmptyWindowMessage(window.from_s, window.to_s, t_start, t_end));
  }
  in = std::move(out);
}

/// Whether `o` asks for the board's other IMUs.
bool BoardAsked(const InputOptions& o) { return o.all_imus || !o.flight_log.other_imus.empty(); }

/// A native CSV's board as `o` asks for it (InputOptions::all_imus): every other IMU, the
/// instances listed in their order, or none.
void ChooseNativeBoard(Session& s, const InputOptions& o) {
  if (o.all_imus) return;
  if (BoardAsked(o) && o.flight_log.imu != 0) {
    throw InputError(s.source, "",
                     "a native CSV's IMU 0 is its acc_x.. columns: list it first (0," +
                         std::to_string(o.flight_log.imu) + ")");
  }
  std::vector<BoardImu> chosen;
  for (const int k : o.flight_log.other_imus) {
    const auto it = std::find_if(s.other_imus.begin(), s.other_imus.end(),
                                 [k](const BoardImu& b) { return b.instance == k; });
    if (it == s.other_imus.end()) {
      throw InputError(s.source, "",
                       "no IMU " + std::to_string(k) + " (columns acc" + std::to_string(k) +
                           "_x..): the file has " + std::to_string(s.other_imus.size() + 1) +
                           " IMU(s)");
    }
    chosen.push_back(*it);
  }
  s.other_imus = std::move(chosen);
}

Session Read(const InputFile& input, InputKind kind, const InputOptions& o) {
  if (BoardAsked(o) && kind != InputKind::kFlightLog && kind != InputKind::kNativeCsv) {
    throw InputError(input.path, "",
                     "only a flight log or plumb's native CSV carries several IMUs (" +
                         OptionText(Option::kImus) + ")",
                     {Option::kImus});
  }
  const auto windowed = [&](Session s) {
    KeepWindow(s.series, o.flight_log, s.source);
    for (BoardImu& b : s.other_imus) KeepWindow(b.series, o.flight_log, s.source + " " + b.name);
    return s;
  };
  switch (kind) {
    case InputKind::kTwoTables:
      if (o.format == InputFormat::kNative) {
        throw Error(input.path + "," + input.gyr_path +
                    ": the two-file form is a table, not native CSV");
      }
      return windowed(
          ReadSplitTables(input.path, input.gyr_path, TableOptions(o, true), o.run_jobs));
    case InputKind::kFlightLog: {
      FlightLogSelection selection = o.flight_log;
      if (o.clock == Clock::kReceive) selection.receive_time = true;
      const FlightLog log = FlightLog::Open(input.path, o.run_jobs);
      if (o.all_imus) selection.other_imus = BoardInstances(log.Summary(), selection.imu);
      return log.Select(selection);
    }
    case InputKind::kTextTable:
      return windowed(ReadTextTable(input.path, TableOptions(o, false)));
    case InputKind::kNativeCsv:
      break;
  }
  Session s = ReadNative(input.path, o.format == InputFormat::kNative, o.not_native_hint);
  ChooseNativeBoard(s, o);
  return windowed(std::move(s));
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
    joined.warnings.push_back(Notice{"inputs_overlap",
                                     next.source +
                                         ": its times overlap the previous input's; shifted by " +
                                         std::to_string(shift) +
                                         " s (no motion assumed between files)",
                                     {}});
  }
  for (double t : b.t_s) a.t_s.push_back(t + shift);
  a.acc.insert(a.acc.end(), b.acc.begin(), b.acc.end());
  a.gyr.insert(a.gyr.end(), b.gyr.begin(), b.gyr.end());
  a.temp_c.insert(a.temp_c.end(), b.temp_c.begin(), b.temp_c.end());
  joined.source += " " + next.source;
  for (Notice& w : next.warnings) {
    w.message = next.source + ": " + w.message;  // the input's own notice, its code kept
    joined.warnings.push_back(std::move(w));
  }
  for (auto& l : next.firmware_left) joined.firmware_left.push_back(next.source + ": " + l);
  if (!joined.site) joined.site = next.site;
  if (joined.log_params.empty()) joined.log_params = std::move(next.log_params);
  if (!joined.system_id) joined.system_id = next.system_id;
}

}  // namespace

namespace {

/// Replaces the stamps of `series` (of `s`, named `name`) by the uniform clock fitted through
/// them, and says so in s's warnings.
void UseUniformClock(Session& s, ImuSeries& series, const std::string& name) {
  const signal::TimeBase base = signal::AnalyseTimeBase(series.t_s);
  if (base.kind == signal::ClockKind::kTooShort) {
    s.warnings.push_back(Notice{"clock_kept",
                                name + ": too few samples (" + std::to_string(base.samples) +
                                    ") to fit a uniform clock; the stamps are kept",
                                {}});
    return;
  }
  if (base.kind == signal::ClockKind::kIrregular) {
    s.warnings.push_back(Notice{"clock_kept",
                                name + ": no uniform clock fits these stamps (irregular "
                                           "intervals, e.g. telemetry); the stamps are kept",
                                {}});
    return;
  }
  signal::ApplyUniformClock(base, series.t_s);
  std::ostringstream note;
  note << std::setprecision(6) << name << ": times from a uniform " << base.rate_hz()
       << " Hz clock fitted through the stamps (jitter RMS " << std::setprecision(3)
       << base.jitter_rms_s * 1e3 << " ms removed; " << base.dropped
       << " dropped samples kept as gaps)";
  s.warnings.push_back(Notice{"clock_uniform", note.str(), {}});
}

/// UseUniformClock on IMU 0 and every other IMU of the board.
void UseUniformClock(Session& s) {
  UseUniformClock(s, s.series, s.source);
  for (BoardImu& b : s.other_imus) UseUniformClock(s, b.series, s.source + " " + b.name);
}

}  // namespace

double UnitFactor(AccUnit unit) {
  return unit == AccUnit::kStandardGravity ? units::kStandardGravity : 1.0;
}

double UnitFactor(GyrUnit unit) {
  return unit == GyrUnit::kDegreesPerSecond ? units::kRadPerDeg : 1.0;
}

Session OpenInputs(const std::vector<InputFile>& inputs, const InputOptions& options) {
  if (inputs.empty()) throw Error("OpenInputs: no input");
  if (BoardAsked(options) && inputs.size() > 1) {
    throw InputError(inputs[1].path, "",
                     "the board's IMUs (" + OptionText(Option::kImus) + ") come from one input",
                     {Option::kImus});
  }
  std::vector<std::string> paths;
  for (const InputFile& input : inputs) {
    paths.push_back(input.path);
    if (input.two_files) paths.push_back(input.gyr_path);
  }
  const StreamSpool streams(paths, StreamBound(options.max_stream_bytes));
  std::optional<Session> joined;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const InputKind kind = KindOf(inputs[i], options);
    if (options.before_read) options.before_read(i, kind);
    if (options.clock == Clock::kReceive && kind != InputKind::kFlightLog) {
      throw InputError(inputs[i].path, "",
                       "a table has no receive times (" + OptionText(Option::kClock, "receive") +
                           " is for ROS bags)",
                       {Option::kClock});
    }
    Session s = Read(inputs[i], kind, options);
    if (options.clock == Clock::kUniform) UseUniformClock(s);
    if (options.acc.unit == AccUnit::kCounts) s.series.acc_unit = "counts";
    if (options.gyr.unit == GyrUnit::kCounts) s.series.gyr_unit = "counts";
    if (!joined) {
      joined = std::move(s);
    } else {
      Append(*joined, std::move(s));
    }
  }
  if (joined->series.empty()) throw Error(joined->source + ": no samples");
  return std::move(*joined);
}

namespace {

/// Bytes of record bodies a session's reader keeps (ArdupilotSessionRecords,
/// Px4SessionTopics) per byte of file, measured on the first kEstimatePrefixBytes of `path`;
/// 1 (the most it can be) when that start does not decode.
double KeptFraction(const std::string& path, FlightLogFormat format) {
  std::ifstream in(OpenPath(path), std::ios::binary);
  std::string prefix(kEstimatePrefixBytes, '\0');
  in.read(prefix.data(), static_cast<std::streamsize>(prefix.size()));
  prefix.resize(static_cast<std::size_t>(in.gcount()));
  if (prefix.empty()) return 1.0;
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(prefix.data());
  std::size_t kept = 0;
  try {
    switch (format) {
      case FlightLogFormat::kDataflashBinary:
        for (const DataflashType& t :
             ParseDataflash(bytes, prefix.size(), path, ArdupilotSessionRecords()).types) {
          kept += t.KeptBytes();
        }
        break;
      case FlightLogFormat::kDataflashText:
        for (const DataflashType& t : ParseDataflashText(prefix.data(), prefix.size(), path,
                                                         ArdupilotSessionRecords()).types) {
          kept += t.KeptBytes();
        }
        break;
      case FlightLogFormat::kPx4ULog:
        for (const ULogTopic& t : ParseULog(bytes, prefix.size(), path, Px4SessionTopics()).topics) {
          kept += t.KeptBytes();
        }
        break;
      case FlightLogFormat::kMavlinkTlog:
      case FlightLogFormat::kRosBag:
      case FlightLogFormat::kRos2Mcap:
      case FlightLogFormat::kRos2Db3:
      case FlightLogFormat::kNone:
        return 1.0;
    }
  } catch (const Error&) {
    return 1.0;  // a start that does not decode: assume the most
  }
  return std::min(1.0, static_cast<double>(kept) / static_cast<double>(prefix.size()));
}

}  // namespace

std::uint64_t EstimateReadMemory(const std::string& path) {
  struct stat info {};
  if (::stat(OpenPath(path).c_str(), &info) != 0 || !S_ISREG(info.st_mode)) return 0;
  double factor = kTableMemoryFactor;
  switch (const FlightLogFormat format = SniffFlightLog(path)) {
    case FlightLogFormat::kDataflashBinary:
    case FlightLogFormat::kPx4ULog:
      factor = kSplitKeptMemoryFactor * KeptFraction(path, format);
      break;
    case FlightLogFormat::kDataflashText:
      factor = kKeptMemoryFactor * KeptFraction(path, format);
      break;
    case FlightLogFormat::kMavlinkTlog: factor = kTlogMemoryFactor; break;
    case FlightLogFormat::kRosBag:
    case FlightLogFormat::kRos2Mcap:
    case FlightLogFormat::kRos2Db3: factor = kRosBagMemoryFactor; break;
    case FlightLogFormat::kNone: break;
  }
  return kReadMemoryBaseBytes + SpooledBytes(path) +
         static_cast<std::uint64_t>(factor * static_cast<double>(info.st_size));
}


}  // namespace plumb::io

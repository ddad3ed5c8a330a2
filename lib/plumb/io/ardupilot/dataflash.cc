// plumb/io/ardupilot/dataflash.cc — see dataflash.h for the format and the decoding contract.
#include "plumb/io/ardupilot/dataflash.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/ardupilot/dataflash_format.h"
#include "plumb/io/ardupilot/dataflash_parser.h"
#include "plumb/io/common/split_read.h"

namespace plumb::io {
namespace {

using detail::DataflashFormat;
using detail::DataflashParser;
using detail::DataflashStorage;
using TimeColumn = detail::DataflashTimeColumn;
constexpr auto FindTime = detail::FindDataflashTime;
constexpr auto TemperatureColumn = detail::DataflashTemperatureColumn;

/// A value asked of a type whose bodies the reader's RecordFilter left out: a caller's bug.
[[noreturn]] void NotKept(const std::string& name) {
  throw Error("DataFlash type " + name + ": its record bodies were not kept (RecordFilter)");
}

/// The message holding IMU `instance` and the column of its instance field (-1 if none).
const DataflashType* ImuType(const DataflashLog& log, int instance, int* instance_col) {
  return detail::DataflashInstanceMessage(log, "IMU", instance, false, instance_col);
}

}  // namespace

int DataflashType::ColumnIndex(std::string_view column) const {
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c].name == column) return static_cast<int>(c);
  }
  return -1;
}

double DataflashType::Value(std::size_t row, std::size_t col) const {
  if (!bodies_kept) NotKept(name);
  const DataflashColumn& c = columns[col];
  const detail::DataflashFormatChar& f = DataflashFormat(c.format);
  return detail::DecodeDataflashValue(bodies.Row(row) + c.offset, f.storage, f.scale);
}

std::string DataflashType::Text(std::size_t row, std::size_t col) const {
  return std::string(TextView(row, col));
}

std::string_view DataflashType::TextView(std::size_t row, std::size_t col) const {
  if (!bodies_kept) NotKept(name);
  const DataflashColumn& c = columns[col];
  if (DataflashFormat(c.format).storage != DataflashStorage::kText) return {};
  const auto* p = reinterpret_cast<const char*>(bodies.Row(row) + c.offset);
  return {p, strnlen(p, c.size)};
}

std::array<std::int16_t, 32> DataflashType::Array(std::size_t row, std::size_t col) const {
  if (!bodies_kept) NotKept(name);
  std::array<std::int16_t, 32> out{};
  const DataflashColumn& c = columns[col];
  if (DataflashFormat(c.format).storage == DataflashStorage::kArray) {
    std::memcpy(out.data(), bodies.Row(row) + c.offset, sizeof(out));
  }
  return out;
}

std::vector<double> DataflashType::Column(std::string_view column) const {
  const int c = ColumnIndex(column);
  if (c < 0) {
    throw Error("DataFlash message " + name + " has no column " + std::string(column));
  }
  std::vector<double> out(rows);
  for (std::size_t r = 0; r < rows; ++r) out[r] = Value(r, static_cast<std::size_t>(c));
  return out;
}

bool DataflashWarnings::any() const {
  return bytes_skipped || truncated_records || fmt_length_mismatches || fmt_conflicts ||
         fmt_invalid || fmt_unknown_chars || text_header_lines || text_bad_lines ||
         text_mode_names;
}

std::vector<std::string> DataflashWarnings::Describe() const {
  std::vector<std::string> out;
  if (bytes_skipped) {
    out.push_back("skipped " + std::to_string(bytes_skipped) + " bytes in " +
                  std::to_string(skip_runs) + " run(s) not forming a known record (first at byte " +
                  std::to_string(first_skip_offset) + ")");
  }
  if (truncated_records) {
    out.push_back("dropped the truncated last record (" + std::to_string(truncated_bytes) +
                  " bytes)");
  }
  if (fmt_length_mismatches) {
    out.push_back(std::to_string(fmt_length_mismatches) +
                  " FMT(s) whose fields do not fill their length (length trusted)");
  }
  if (fmt_conflicts) {
    out.push_back(std::to_string(fmt_conflicts) + " FMT(s) redefining a type, ignored");
  }
  if (fmt_invalid) out.push_back(std::to_string(fmt_invalid) + " FMT(s) with length < 3, ignored");
  if (fmt_unknown_chars) {
    out.push_back(std::to_string(fmt_unknown_chars) +
                  " FMT(s) with an unknown format character (columns after it not decoded)");
  }
  if (text_header_lines) {
    out.push_back("ignored " + std::to_string(text_header_lines) +
                  " header line(s) before the first FMT line");
  }
  if (text_bad_lines) {
    out.push_back("skipped " + std::to_string(text_bad_lines) +
                  " malformed line(s) (first: line " + std::to_string(text_first_bad_line) +
                  ": " + text_first_bad_what + ")");
  }
  if (text_mode_names) {
    out.push_back(std::to_string(text_mode_names) +
                  " flight mode(s) written as a name, stored as mode number 255");
  }
  return out;
}

const DataflashType* DataflashLog::Find(std::string_view name) const {
  for (const DataflashType& t : types) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

std::vector<std::pair<std::string, std::size_t>> DataflashLog::MessageCounts() const {
  std::vector<std::pair<std::string, std::size_t>> out;
  for (const DataflashType& t : types) {
    if (t.rows > 0) out.emplace_back(t.name, t.rows);
  }
  return out;
}

namespace {

/// Checks that the parsed `log` (`size` bytes) held an FMT record and completes it (units,
/// params).
void FinishParse(DataflashLog* log, std::size_t size) {
  if (log->types.front().rows == 0) {
    throw InputError(log->source, "byte 0",
                     "no FMT record (0xA3 0x95 0x80) in " + std::to_string(size) +
                         " bytes: not an ArduPilot DataFlash .bin log");
  }
  detail::FinishDataflashLog(log);
}

/// The log of `source` (`size` bytes; 0: unknown), named `name`, decoded in one part or two
/// (options).
DataflashLog Decode(const ByteSource& source, std::size_t size, const std::string& name,
                    const RecordFilter& filter, const DataflashReadOptions& options) {
  DataflashLog log;
  log.source = name;
  DataflashParser parser(&log, filter, size);
  const std::size_t from = detail::DecodeStart<DataflashLog>(source, size, parser, options);
  // One pass (the rest of it), in chunks: every record is decoded from the read buffer as it
  // goes by.
  source(from, [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
    if (at_end) log.size_bytes = offset + n;
    return parser.Feed(data, n, offset, at_end);
  });
  parser.Finish();
  FinishParse(&log, log.size_bytes);
  return log;
}

}  // namespace

DataflashLog ParseDataflash(const std::uint8_t* data, std::size_t size,
                            const std::string& source, const RecordFilter& filter,
                            const DataflashReadOptions& options) {
  return Decode(MemoryBytes(data, size), size, source, filter, options);
}

DataflashLog ReadDataflash(const std::string& path, const RecordFilter& filter,
                           const DataflashReadOptions& options) {
  return Decode(FileBytes(path, "DataFlash log", DataflashParser::kMaxRecord),
                RegularFileSize(path), path, filter, options);
}

namespace {

/// The description of IMU `instance` of message `type`: `samples` records, the first and last
/// with the (unscaled) times `first` and `last`.
DataflashImuInfo ImuInfo(const DataflashType& type, int instance, std::size_t samples,
                         double first, double last) {
  DataflashImuInfo info;
  info.instance = instance;
  info.message = type.name;
  info.samples = samples;
  info.has_temperature = TemperatureColumn(type) >= 0;
  const TimeColumn time = FindTime(type);
  if (time.col >= 0 && samples >= 2) {
    const double span = (last - first) * time.scale;
    if (span > 0.0) info.rate_hz = static_cast<double>(samples - 1) / span;
  }
  return info;
}

}  // namespace

std::vector<DataflashImuInfo> DataflashImuInstances(const DataflashLog& log) {
  using Reader = detail::DataflashColumnReader;
  // Candidate (instance, message) pairs: the I values of IMU, or IMU, IMU2, IMU3, ...
  std::vector<int> instances;
  int probe_col = -1;
  const DataflashType* probe = ImuType(log, 0, &probe_col);
  if (probe != nullptr && probe_col >= 0 && probe->imu_decoded) {
    for (std::size_t k = 0; k < probe->imu.size(); ++k) {
      if (probe->imu[k].records > 0) instances.push_back(static_cast<int>(k));
    }
  } else if (probe != nullptr && probe_col >= 0) {
    if (!probe->bodies_kept) NotKept(probe->name);
    const Reader inst = Reader::Of(*probe, probe_col);
    std::array<bool, 256> seen{};
    for (std::size_t r = 0; r < probe->rows; ++r) {
      const double v = inst.Read(probe->bodies.Row(r));
      if (v >= 0 && v < 256) seen[static_cast<std::size_t>(v)] = true;
    }
    for (int k = 0; k < 256; ++k) {
      if (seen[static_cast<std::size_t>(k)]) instances.push_back(k);
    }
  } else {
    for (int k = 0; k < 16; ++k) instances.push_back(k);
  }
  std::vector<DataflashImuInfo> out;
  for (int instance : instances) {
    int instance_col = -1;
    const DataflashType* type = ImuType(log, instance, &instance_col);
    if (type == nullptr || type->rows == 0) continue;
    if (type->imu_decoded) {
      const std::size_t k = instance_col >= 0 ? static_cast<std::size_t>(instance) : 0;
      if (k < type->imu.size() && type->imu[k].records > 0) {
        out.push_back(ImuInfo(*type, instance, type->imu[k].records, type->imu[k].first_time,
                              type->imu[k].last_time));
      }
      continue;
    }
    if (!type->bodies_kept) NotKept(type->name);
    const Reader inst = instance_col >= 0 ? Reader::Of(*type, instance_col) : Reader{};
    const TimeColumn time = FindTime(*type);
    const Reader t_col = time.col >= 0 ? Reader::Of(*type, time.col) : Reader{};
    std::size_t samples = 0;
    double first = 0.0, last = 0.0;  // raw times of the instance's first and last rows
    for (std::size_t r = 0; r < type->rows; ++r) {
      const std::uint8_t* body = type->bodies.Row(r);
      if (instance_col >= 0 && inst.Read(body) != instance) continue;
      if (time.col >= 0) (samples == 0 ? first : last) = t_col.Read(body);
      ++samples;
    }
    if (samples == 0) continue;
    out.push_back(ImuInfo(*type, instance, samples, first, last));
  }
  return out;
}

const ImuSeries* DecodedDataflashImu(const DataflashLog& log, int instance) {
  int col = -1;
  const DataflashType* t = instance >= 0 ? ImuType(log, instance, &col) : nullptr;
  if (t == nullptr || !t->imu_decoded) return nullptr;
  const std::size_t k = col >= 0 ? static_cast<std::size_t>(instance) : 0;
  if (k >= t->imu.size() || t->imu[k].records == 0) return nullptr;
  return &t->imu[k].series;
}

std::size_t DataflashImuRecords(const DataflashLog& log, int instance) {
  int col = -1;
  const DataflashType* t = instance >= 0 ? ImuType(log, instance, &col) : nullptr;
  if (t == nullptr) return 0;
  if (t->imu_decoded) {
    const std::size_t k = col >= 0 ? static_cast<std::size_t>(instance) : 0;
    return k < t->imu.size() ? t->imu[k].records : 0;
  }
  if (!t->bodies_kept) return 0;
  if (col < 0) return t->rows;
  const auto inst = detail::DataflashColumnReader::Of(*t, col);
  std::size_t n = 0;
  for (std::size_t r = 0; r < t->rows; ++r) n += inst.Read(t->bodies.Row(r)) == instance ? 1 : 0;
  return n;
}

namespace {

/// ImuFromDataflash, noting in `first_dropped` the time of the first record its rule leaves
/// out (from the reader's notes for samples it decoded in its pass).
ImuSeries ImuSamples(const DataflashLog& log, int instance, std::optional<double>& first_dropped) {
  int instance_col = -1;
  const DataflashType* type = instance >= 0 ? ImuType(log, instance, &instance_col) : nullptr;
  const std::string what = "IMU instance " + std::to_string(instance);
  if (type == nullptr) {
    throw InputError(log.source, "", "no IMU message for " + what + " (IMU, IMU2, ... or I)");
  }
  const TimeColumn time = FindTime(*type);
  const int acc[3] = {type->ColumnIndex("AccX"), type->ColumnIndex("AccY"),
                      type->ColumnIndex("AccZ")};
  const int gyr[3] = {type->ColumnIndex("GyrX"), type->ColumnIndex("GyrY"),
                      type->ColumnIndex("GyrZ")};
  const bool has_gyr = gyr[0] >= 0 && gyr[1] >= 0 && gyr[2] >= 0;
  const int temp = TemperatureColumn(*type);
  if (time.col < 0 || acc[0] < 0 || acc[1] < 0 || acc[2] < 0) {
    throw InputError(log.source, "",
                     type->name + " has no TimeUS/TimeMS or AccX/AccY/AccZ column");
  }
  if (type->rows == 0) {
    throw InputError(log.source, "",
                     "the log defines " + type->name + " (FMT) but holds no " + type->name +
                         " rows: no IMU samples were logged (LOG_BITMASK without IMU?)");
  }
  if (type->imu_decoded) {  // decoded by the reader, with the rule below
    if (const ImuSeries* decoded = DecodedDataflashImu(log, instance)) {
      const std::size_t k = instance_col >= 0 ? static_cast<std::size_t>(instance) : 0;
      if (const auto& dropped = type->imu[k].first_dropped) first_dropped = dropped->t_s;
      return CopySeries(*decoded);
    }
    throw InputError(log.source, "", "no " + type->name + " rows with I == " +
                                         std::to_string(instance) + " for " + what);
  }
  if (!type->bodies_kept) NotKept(type->name);
  using Reader = detail::DataflashColumnReader;
  const Reader inst = instance_col >= 0 ? Reader::Of(*type, instance_col) : Reader{};
  const auto mine = [&](const std::uint8_t* body) {
    return instance_col < 0 || inst.Read(body) == instance;
  };
  std::size_t count = 0;
  for (std::size_t r = 0; r < type->rows; ++r) count += mine(type->bodies.Row(r)) ? 1 : 0;
  if (count == 0) {
    throw InputError(log.source, "", "no " + type->name + " rows with I == " +
                                         std::to_string(instance) + " for " + what);
  }
  const Reader t_col = Reader::Of(*type, time.col);
  const Reader a[3] = {Reader::Of(*type, acc[0]), Reader::Of(*type, acc[1]),
                       Reader::Of(*type, acc[2])};
  Reader g[3];
  if (has_gyr) {
    for (int k = 0; k < 3; ++k) g[k] = Reader::Of(*type, gyr[k]);
  }
  const Reader temp_col = temp >= 0 ? Reader::Of(*type, temp) : Reader{};
  ImuSeries s;
  s.reserve(count);
  const auto keep = [&](const std::uint8_t* body, double t_s) {
    s.t_s.push_back(t_s);
    s.acc.emplace_back(static_cast<float>(a[0].Read(body)), static_cast<float>(a[1].Read(body)),
                       static_cast<float>(a[2].Read(body)));
    if (has_gyr) {
      s.gyr.emplace_back(static_cast<float>(g[0].Read(body)),
                         static_cast<float>(g[1].Read(body)),
                         static_cast<float>(g[2].Read(body)));
    }
    if (temp >= 0) s.temp_c.push_back(static_cast<float>(temp_col.Read(body)));
  };
  // A sample is kept when its time is finite, above the last kept one and below the next
  // record's (a time above the next record's is a corrupted spike: keeping it would drop every
  // later sample); each record is decided when the next one of the instance is met.
  const std::uint8_t* pending = nullptr;
  double pending_t = 0.0;
  const auto decide = [&](bool below_next) {
    if (pending == nullptr) return;
    const bool kept = std::isfinite(pending_t) && (s.t_s.empty() || pending_t > s.t_s.back()) &&
                      below_next;
    if (kept) {
      keep(pending, pending_t);
    } else if (!first_dropped) {
      first_dropped = pending_t;
    }
  };
  for (std::size_t r = 0; r < type->rows; ++r) {
    const std::uint8_t* body = type->bodies.Row(r);
    if (!mine(body)) continue;
    const double t_s = t_col.Read(body) * time.scale;
    decide(pending_t < t_s);
    pending = body;
    pending_t = t_s;
  }
  decide(true);
  return s;
}

}  // namespace

ImuSeries ImuFromDataflash(const DataflashLog& log, int instance) {
  std::optional<double> first_dropped;
  return ImuSamples(log, instance, first_dropped);
}

std::optional<double> DataflashImuFirstDropped(const DataflashLog& log, int instance) {
  std::optional<double> first_dropped;
  try {
    (void)ImuSamples(log, instance, first_dropped);
  } catch (const InputError&) {
    return std::nullopt;  // no such instance, no samples
  }
  return first_dropped;
}

}  // namespace plumb::io

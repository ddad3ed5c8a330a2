// plumb/io/ardupilot/dataflash.cc — see dataflash.h for the format and the decoding contract.
#include "plumb/io/ardupilot/dataflash.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/ardupilot/dataflash_format.h"

namespace plumb::io {
namespace {

using detail::DataflashFormat;
using detail::DataflashStorage;
constexpr std::uint8_t kHead1 = detail::kDataflashHead1;
constexpr std::uint8_t kHead2 = detail::kDataflashHead2;
constexpr std::uint8_t kFmtType = detail::kDataflashFmtType;
constexpr std::size_t kHeaderSize = detail::kDataflashHeaderSize;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <typename T>
T Load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // little endian on every supported host
  return v;
}

/// A value asked of a type whose bodies the reader's RecordFilter left out: a caller's bug.
[[noreturn]] void NotKept(const std::string& name) {
  throw Error("DataFlash type " + name + ": its record bodies were not kept (RecordFilter)");
}

/// Text of a fixed-width char field up to its first NUL.
std::string FixedText(const std::uint8_t* p, std::size_t n) {
  const auto* c = reinterpret_cast<const char*>(p);
  return std::string(c, strnlen(c, n));
}

/// The one-pass decoder state.
class Parser {
 public:
  /// `expected_rows`: records per type id from a counting pass (to size each type's storage
  /// once), or nullptr for a counting pass itself, which stores no bodies.
  /// `file`: the mapped file `data` is, told what has been read (LogFile::Release), or nullptr.
  /// `filter`: the types whose bodies the storing pass keeps.
  Parser(const std::uint8_t* data, std::size_t size, DataflashLog* log,
         const std::array<std::size_t, 256>* expected_rows, const LogFile* file,
         const RecordFilter& filter)
      : data_(data), size_(size), log_(log), expected_rows_(expected_rows), file_(file),
        filter_(filter) {
    index_.fill(-1);
    AddType(detail::DataflashFmtType(&log_->warnings));
  }

  void Run() {
    std::size_t pos = 0;
    while (size_ - pos >= kHeaderSize) {
      if (file_ != nullptr) file_->Release(pos);
      if (data_[pos] == kHead1 && data_[pos + 1] == kHead2) {
        const int idx = index_[data_[pos + 2]];
        if (idx >= 0) {
          DataflashType& t = log_->types[static_cast<std::size_t>(idx)];
          if (t.length > size_ - pos) {
            Truncated(size_ - pos);
            return;
          }
          const std::uint8_t* body = data_ + pos + kHeaderSize;
          if (expected_rows_ != nullptr && t.bodies_kept) {
            t.bodies.insert(t.bodies.end(), body, body + t.body_size);
          }
          ++t.rows;
          pos += t.length;
          if (t.id == kFmtType) HandleFmt(body, t.body_size);
          continue;
        }
      }
      Skip(pos);
      ++pos;
    }
    const std::size_t tail = size_ - pos;
    if (tail == 0) return;
    const bool header_prefix = data_[pos] == kHead1 && (tail == 1 || data_[pos + 1] == kHead2);
    if (header_prefix) {
      Truncated(tail);
    } else {
      for (std::size_t k = 0; k < tail; ++k) Skip(pos + k);
    }
  }

 private:
  void AddType(DataflashType t) {
    t.bodies_kept = t.id == kFmtType || filter_.Keeps(t.name);
    if (expected_rows_ != nullptr && t.bodies_kept) {
      t.bodies.reserve((*expected_rows_)[t.id] * t.body_size);
    }
    index_[t.id] = static_cast<int>(log_->types.size());
    log_->types.push_back(std::move(t));
  }

  void Skip(std::size_t pos) { CountSkipped(log_->warnings, pos, pos + 1, skip_end_); }

  void Truncated(std::size_t bytes) {
    ++log_->warnings.truncated_records;
    log_->warnings.truncated_bytes += bytes;
  }

  // FMT body: Type (B), Length (B), Name (n), Format (N), Columns (Z) = 86 bytes.
  void HandleFmt(const std::uint8_t* body, std::size_t body_size) {
    if (body_size < detail::kFmtBodySize) return;  // cannot happen with the built-in FMT
    const std::uint8_t id = body[detail::kFmtTypeOffset];
    const std::size_t length = body[detail::kFmtLengthOffset];
    const std::string name = FixedText(body + detail::kFmtNameOffset, detail::kFmtNameSize);
    const std::string format = FixedText(body + detail::kFmtFormatOffset, detail::kFmtFormatSize);
    const std::string columns =
        FixedText(body + detail::kFmtColumnsOffset, detail::kFmtColumnsSize);
    const int existing = index_[id];
    const DataflashType* known =
        existing >= 0 ? &log_->types[static_cast<std::size_t>(existing)] : nullptr;
    if (!detail::AcceptFmt(known, length, name, format, &log_->warnings)) return;
    AddType(detail::MakeDataflashType(id, length, name, format, columns, &log_->warnings));
  }

  const std::uint8_t* data_;
  std::size_t size_;
  DataflashLog* log_;
  const std::array<std::size_t, 256>* expected_rows_;
  const LogFile* file_;
  const RecordFilter& filter_;
  std::array<int, 256> index_;
  std::size_t skip_end_ = 0;  ///< end of the last skipped range (CountSkipped)
};

/// Rows of `type` that belong to IMU `instance` (all rows when `instance_col` < 0).
std::vector<std::size_t> InstanceRows(const DataflashType& type, int instance_col,
                                      int instance) {
  std::vector<std::size_t> rows;
  rows.reserve(instance_col < 0 ? type.rows : type.rows / 2);
  for (std::size_t r = 0; r < type.rows; ++r) {
    if (instance_col < 0 || type.Value(r, instance_col) == instance) rows.push_back(r);
  }
  return rows;
}

/// The message holding IMU `instance` and the column of its instance field (-1 if none).
const DataflashType* ImuType(const DataflashLog& log, int instance, int* instance_col) {
  return detail::DataflashInstanceMessage(log, "IMU", instance, false, instance_col);
}

/// Time of record `row` in seconds from TimeUS or TimeMS (`scale` 1e-6 or 1e-3).
struct TimeColumn {
  int col = -1;
  double scale = 0.0;
};

TimeColumn FindTime(const DataflashType& t) {
  if (const int c = t.ColumnIndex("TimeUS"); c >= 0) return {c, 1e-6};
  if (const int c = t.ColumnIndex("TimeMS"); c >= 0) return {c, 1e-3};
  return {};
}

int TemperatureColumn(const DataflashType& t) {
  const int c = t.ColumnIndex("T");
  return c >= 0 ? c : t.ColumnIndex("Temp");
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
  const std::uint8_t* p = bodies.data() + row * body_size + c.offset;
  const detail::DataflashFormatChar& f = DataflashFormat(c.format);
  double v = 0.0;
  switch (f.storage) {
    case DataflashStorage::kInt8: v = Load<std::int8_t>(p); break;
    case DataflashStorage::kUInt8: v = Load<std::uint8_t>(p); break;
    case DataflashStorage::kInt16: v = Load<std::int16_t>(p); break;
    case DataflashStorage::kUInt16: v = Load<std::uint16_t>(p); break;
    case DataflashStorage::kInt32: v = Load<std::int32_t>(p); break;
    case DataflashStorage::kUInt32: v = Load<std::uint32_t>(p); break;
    case DataflashStorage::kInt64: v = static_cast<double>(Load<std::int64_t>(p)); break;
    case DataflashStorage::kUInt64: v = static_cast<double>(Load<std::uint64_t>(p)); break;
    case DataflashStorage::kFloat: v = Load<float>(p); break;
    case DataflashStorage::kDouble: v = Load<double>(p); break;
    case DataflashStorage::kText: case DataflashStorage::kArray: case DataflashStorage::kUnknown:
      return kNaN;
  }
  return f.scale == 1.0 ? v : v * f.scale;
}

std::string DataflashType::Text(std::size_t row, std::size_t col) const {
  if (!bodies_kept) NotKept(name);
  const DataflashColumn& c = columns[col];
  if (DataflashFormat(c.format).storage != DataflashStorage::kText) return {};
  return FixedText(bodies.data() + row * body_size + c.offset, c.size);
}

std::array<std::int16_t, 32> DataflashType::Array(std::size_t row, std::size_t col) const {
  if (!bodies_kept) NotKept(name);
  std::array<std::int16_t, 32> out{};
  const DataflashColumn& c = columns[col];
  if (DataflashFormat(c.format).storage == DataflashStorage::kArray) {
    std::memcpy(out.data(), bodies.data() + row * body_size + c.offset, sizeof(out));
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

/// ParseDataflash, telling `file` (nullptr: none) what each pass has read.
DataflashLog ParseDataflashFrom(const std::uint8_t* data, std::size_t size,
                                const std::string& source, const LogFile* file,
                                const RecordFilter& filter) {
  DataflashLog log;
  log.source = source;
  log.size_bytes = size;
  // Two passes: the first counts the records of each type (no copy), so that the second
  // copies every body once into storage of the right size (no reallocation).
  std::array<std::size_t, 256> rows{};
  {
    DataflashLog counted;
    Parser counter(data, size, &counted, nullptr, file, filter);
    counter.Run();
    for (const DataflashType& t : counted.types) rows[t.id] = t.rows;
  }
  Parser parser(data, size, &log, &rows, file, filter);
  parser.Run();
  if (log.types.front().rows == 0) {
    throw InputError(source, "byte 0",
                     "no FMT record (0xA3 0x95 0x80) in " + std::to_string(size) +
                         " bytes: not an ArduPilot DataFlash .bin log");
  }
  detail::FinishDataflashLog(&log);
  return log;
}

}  // namespace

DataflashLog ParseDataflash(const std::uint8_t* data, std::size_t size,
                            const std::string& source, const RecordFilter& filter) {
  return ParseDataflashFrom(data, size, source, nullptr, filter);
}

DataflashLog ReadDataflash(const std::string& path, const RecordFilter& filter) {
  const LogFile file(path, "DataFlash log");
  return ParseDataflashFrom(file.data(), file.size(), path, &file, filter);
}

std::vector<DataflashImuInfo> DataflashImuInstances(const DataflashLog& log) {
  // Candidate (instance, message) pairs: the I values of IMU, or IMU, IMU2, IMU3, ...
  std::vector<int> instances;
  int probe_col = -1;
  const DataflashType* probe = ImuType(log, 0, &probe_col);
  if (probe != nullptr && probe_col >= 0) {
    std::array<bool, 256> seen{};
    for (std::size_t r = 0; r < probe->rows; ++r) {
      const double v = probe->Value(r, static_cast<std::size_t>(probe_col));
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
    if (type == nullptr) continue;
    const std::vector<std::size_t> rows = InstanceRows(*type, instance_col, instance);
    if (rows.empty()) continue;
    DataflashImuInfo info;
    info.instance = instance;
    info.message = type->name;
    info.samples = rows.size();
    info.has_temperature = TemperatureColumn(*type) >= 0;
    const TimeColumn time = FindTime(*type);
    if (time.col >= 0 && rows.size() >= 2) {
      const auto col = static_cast<std::size_t>(time.col);
      const double span =
          (type->Value(rows.back(), col) - type->Value(rows.front(), col)) * time.scale;
      if (span > 0.0) info.rate_hz = static_cast<double>(rows.size() - 1) / span;
    }
    out.push_back(info);
  }
  return out;
}

ImuSeries ImuFromDataflash(const DataflashLog& log, int instance) {
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
  const std::vector<std::size_t> rows = InstanceRows(*type, instance_col, instance);
  if (type->rows == 0) {
    throw InputError(log.source, "",
                     "the log defines " + type->name + " (FMT) but holds no " + type->name +
                         " rows: no IMU samples were logged (LOG_BITMASK without IMU?)");
  }
  if (rows.empty()) {
    throw InputError(log.source, "", "no " + type->name + " rows with I == " +
                                         std::to_string(instance) + " for " + what);
  }

  ImuSeries s;
  s.reserve(rows.size());
  const auto time_col = static_cast<std::size_t>(time.col);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::size_t r = rows[i];
    const double t_s = type->Value(r, time_col) * time.scale;
    if (!std::isfinite(t_s) || (!s.t_s.empty() && !(t_s > s.t_s.back()))) continue;
    // A time above the next record's is a corrupted spike: keeping it would drop every later
    // sample.
    if (i + 1 < rows.size() && !(t_s < type->Value(rows[i + 1], time_col) * time.scale)) continue;
    s.t_s.push_back(t_s);
    s.acc.emplace_back(static_cast<float>(type->Value(r, acc[0])),
                       static_cast<float>(type->Value(r, acc[1])),
                       static_cast<float>(type->Value(r, acc[2])));
    if (has_gyr) {
      s.gyr.emplace_back(static_cast<float>(type->Value(r, gyr[0])),
                         static_cast<float>(type->Value(r, gyr[1])),
                         static_cast<float>(type->Value(r, gyr[2])));
    }
    if (temp >= 0) s.temp_c.push_back(static_cast<float>(type->Value(r, temp)));
  }
  return s;
}

}  // namespace plumb::io

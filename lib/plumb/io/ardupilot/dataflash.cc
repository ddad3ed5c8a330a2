// plumb/io/ardupilot/dataflash.cc — see dataflash.h for the format and the decoding contract.
#include "plumb/io/ardupilot/dataflash.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/ardupilot/dataflash_internal.h"

namespace plumb::io {
namespace {

constexpr std::uint8_t kHead1 = 0xA3;
constexpr std::uint8_t kHead2 = 0x95;
constexpr std::uint8_t kFmtType = detail::kDataflashFmtType;
constexpr std::size_t kHeaderSize = detail::kDataflashHeaderSize;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

std::size_t detail::DataflashFormatSize(char c) {
  switch (c) {
    case 'b': case 'B': case 'M': return 1;
    case 'h': case 'H': case 'c': case 'C': return 2;
    case 'i': case 'I': case 'f': case 'e': case 'E': case 'L': case 'n': return 4;
    case 'd': case 'q': case 'Q': return 8;
    case 'N': return 16;
    case 'Z': case 'a': return 64;
    default: return 0;
  }
}

namespace {

template <typename T>
T Load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // little endian on every supported host
  return v;
}

/// Text of a fixed-width char field up to its first NUL.
std::string FixedText(const std::uint8_t* p, std::size_t n) {
  const auto* c = reinterpret_cast<const char*>(p);
  return std::string(c, strnlen(c, n));
}

std::vector<std::string> SplitColumns(const std::string& text) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    out.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

DataflashType detail::MakeDataflashType(std::uint8_t id, std::size_t length,
                                        const std::string& name, const std::string& format,
                                        const std::string& columns, DataflashWarnings* w) {
  DataflashType t;
  t.id = id;
  t.name = name;
  t.length = length;
  t.format = format;
  t.body_size = length - kHeaderSize;
  const std::vector<std::string> names = SplitColumns(columns);
  std::size_t offset = 0;
  bool known = true;
  for (std::size_t k = 0; k < format.size(); ++k) {
    const std::size_t size = DataflashFormatSize(format[k]);
    if (size == 0) {
      known = false;
      break;
    }
    if (offset + size <= t.body_size) {
      DataflashColumn col;
      col.name = k < names.size() ? names[k] : "col" + std::to_string(k);
      col.format = format[k];
      col.offset = offset;
      col.size = size;
      t.columns.push_back(std::move(col));
    }
    offset += size;
  }
  if (!known) {
    ++w->fmt_unknown_chars;
  } else if (offset != t.body_size) {
    ++w->fmt_length_mismatches;
  }
  return t;
}

DataflashType detail::DataflashFmtType(DataflashWarnings* w) {
  return MakeDataflashType(kFmtType, detail::kDataflashFmtLength, "FMT", "BBnNZ",
                           "Type,Length,Name,Format,Columns", w);
}

namespace {

/// The one-pass decoder state.
class Parser {
 public:
  /// `expected_rows`: records per type id from a counting pass (to size each type's storage
  /// once), or nullptr for a counting pass itself, which stores no bodies.
  Parser(const std::uint8_t* data, std::size_t size, DataflashLog* log,
         const std::array<std::size_t, 256>* expected_rows)
      : data_(data), size_(size), log_(log), expected_rows_(expected_rows) {
    index_.fill(-1);
    AddType(detail::DataflashFmtType(&log_->warnings));
  }

  void Run() {
    std::size_t pos = 0;
    while (size_ - pos >= kHeaderSize) {
      if (data_[pos] == kHead1 && data_[pos + 1] == kHead2) {
        const int idx = index_[data_[pos + 2]];
        if (idx >= 0) {
          DataflashType& t = log_->types[static_cast<std::size_t>(idx)];
          if (t.length > size_ - pos) {
            Truncated(size_ - pos);
            return;
          }
          const std::uint8_t* body = data_ + pos + kHeaderSize;
          if (expected_rows_ != nullptr) t.bodies.insert(t.bodies.end(), body, body + t.body_size);
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
    if (expected_rows_ != nullptr) t.bodies.reserve((*expected_rows_)[t.id] * t.body_size);
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
    if (body_size < 86) return;  // cannot happen with the built-in FMT
    const std::uint8_t id = body[0];
    const std::size_t length = body[1];
    const std::string name = FixedText(body + 2, 4);
    const std::string format = FixedText(body + 6, 16);
    const std::string columns = FixedText(body + 22, 64);
    DataflashWarnings& w = log_->warnings;
    if (length < kHeaderSize) {
      ++w.fmt_invalid;
      return;
    }
    const int existing = index_[id];
    if (existing >= 0) {
      const DataflashType& t = log_->types[static_cast<std::size_t>(existing)];
      if (t.length != length || t.name != name || t.format != format) ++w.fmt_conflicts;
      return;
    }
    AddType(detail::MakeDataflashType(id, length, name, format, columns, &w));
  }

  const std::uint8_t* data_;
  std::size_t size_;
  DataflashLog* log_;
  const std::array<std::size_t, 256>* expected_rows_;
  std::array<int, 256> index_;
  std::size_t skip_end_ = 0;  ///< end of the last skipped range (CountSkipped)
};

/// Fills column units and multipliers from FMTU (FmtType, UnitIds, MultIds), UNIT (Id, Label)
/// and MULT (Id, Mult), when the log has them.
void ApplyUnits(DataflashLog* log) {
  const DataflashType* fmtu = log->Find("FMTU");
  if (fmtu == nullptr) return;
  std::map<char, std::string> units;
  std::map<char, double> mults;
  if (const DataflashType* u = log->Find("UNIT")) {
    const int id = u->ColumnIndex("Id");
    const int label = u->ColumnIndex("Label");
    if (id >= 0 && label >= 0) {
      for (std::size_t r = 0; r < u->rows; ++r) {
        const double key = u->Value(r, id);
        if (key >= -128 && key < 256) {
          units[static_cast<char>(static_cast<int>(key))] = u->Text(r, label);
        }
      }
    }
  }
  if (const DataflashType* m = log->Find("MULT")) {
    const int id = m->ColumnIndex("Id");
    const int mult = m->ColumnIndex("Mult");
    if (id >= 0 && mult >= 0) {
      for (std::size_t r = 0; r < m->rows; ++r) {
        const double key = m->Value(r, id);
        if (key >= -128 && key < 256) {
          mults[static_cast<char>(static_cast<int>(key))] = m->Value(r, mult);
        }
      }
    }
  }
  const int type_col = fmtu->ColumnIndex("FmtType");
  const int unit_col = fmtu->ColumnIndex("UnitIds");
  const int mult_col = fmtu->ColumnIndex("MultIds");
  if (type_col < 0) return;
  for (std::size_t r = 0; r < fmtu->rows; ++r) {
    const double type_id = fmtu->Value(r, type_col);
    auto it = std::find_if(log->types.begin(), log->types.end(),
                           [&](const DataflashType& t) { return t.id == type_id; });
    if (it == log->types.end()) continue;
    const std::string unit_ids = unit_col >= 0 ? fmtu->Text(r, unit_col) : "";
    const std::string mult_ids = mult_col >= 0 ? fmtu->Text(r, mult_col) : "";
    for (std::size_t c = 0; c < it->columns.size(); ++c) {
      if (c < unit_ids.size() && units.count(unit_ids[c])) it->columns[c].unit = units[unit_ids[c]];
      if (c < mult_ids.size() && mults.count(mult_ids[c])) {
        it->columns[c].multiplier = mults[mult_ids[c]];
      }
    }
  }
}

void CollectParams(DataflashLog* log) {
  const DataflashType* parm = log->Find("PARM");
  if (parm == nullptr) return;
  const int name = parm->ColumnIndex("Name");
  const int value = parm->ColumnIndex("Value");
  if (name < 0 || value < 0) return;
  for (std::size_t r = 0; r < parm->rows; ++r) {
    log->params[parm->Text(r, name)] = parm->Value(r, value);
  }
}

}  // namespace

void detail::FinishDataflashLog(DataflashLog* log) {
  ApplyUnits(log);
  CollectParams(log);
}

namespace {

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
  *instance_col = -1;
  const DataflashType* imu = log.Find("IMU");
  if (imu != nullptr) {
    const int col = imu->ColumnIndex("I");
    if (col >= 0) {
      *instance_col = col;
      return imu;
    }
  }
  if (instance == 0) return imu;
  return log.Find("IMU" + std::to_string(instance + 1));
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
  const DataflashColumn& c = columns[col];
  const std::uint8_t* p = bodies.data() + row * body_size + c.offset;
  switch (c.format) {
    case 'b': return Load<std::int8_t>(p);
    case 'B': case 'M': return Load<std::uint8_t>(p);
    case 'h': return Load<std::int16_t>(p);
    case 'H': return Load<std::uint16_t>(p);
    case 'i': return Load<std::int32_t>(p);
    case 'I': return Load<std::uint32_t>(p);
    case 'f': return Load<float>(p);
    case 'd': return Load<double>(p);
    case 'q': return static_cast<double>(Load<std::int64_t>(p));
    case 'Q': return static_cast<double>(Load<std::uint64_t>(p));
    case 'c': return Load<std::int16_t>(p) * 0.01;
    case 'C': return Load<std::uint16_t>(p) * 0.01;
    case 'e': return Load<std::int32_t>(p) * 0.01;
    case 'E': return Load<std::uint32_t>(p) * 0.01;
    case 'L': return Load<std::int32_t>(p) * 1e-7;
    default: return kNaN;
  }
}

std::string DataflashType::Text(std::size_t row, std::size_t col) const {
  const DataflashColumn& c = columns[col];
  if (c.format != 'n' && c.format != 'N' && c.format != 'Z') return {};
  return FixedText(bodies.data() + row * body_size + c.offset, c.size);
}

std::array<std::int16_t, 32> DataflashType::Array(std::size_t row, std::size_t col) const {
  std::array<std::int16_t, 32> out{};
  const DataflashColumn& c = columns[col];
  if (c.format == 'a') {
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

DataflashLog ParseDataflash(const std::uint8_t* data, std::size_t size,
                            const std::string& source) {
  DataflashLog log;
  log.source = source;
  log.size_bytes = size;
  // Two passes: the first counts the records of each type (no copy), so that the second
  // copies every body once into storage of the right size (no reallocation).
  std::array<std::size_t, 256> rows{};
  {
    DataflashLog counted;
    Parser counter(data, size, &counted, nullptr);
    counter.Run();
    for (const DataflashType& t : counted.types) rows[t.id] = t.rows;
  }
  Parser parser(data, size, &log, &rows);
  parser.Run();
  if (log.types.front().rows == 0) {
    throw InputError(source, "byte 0",
                     "no FMT record (0xA3 0x95 0x80) in " + std::to_string(size) +
                         " bytes: not an ArduPilot DataFlash .bin log");
  }
  detail::FinishDataflashLog(&log);
  return log;
}

DataflashLog ReadDataflash(const std::string& path) {
  const LogFile file(path, "DataFlash log");
  return ParseDataflash(file.data(), file.size(), path);
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

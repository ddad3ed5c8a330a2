// plumb/io/ardupilot/dataflash.cc — see dataflash.h for the format and the decoding contract.
#include "plumb/io/ardupilot/dataflash.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>

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

/// A value asked of a type whose bodies the reader's RecordFilter left out: a caller's bug.
[[noreturn]] void NotKept(const std::string& name) {
  throw Error("DataFlash type " + name + ": its record bodies were not kept (RecordFilter)");
}

/// Text of a fixed-width char field up to its first NUL.
std::string FixedText(const std::uint8_t* p, std::size_t n) {
  const auto* c = reinterpret_cast<const char*>(p);
  return std::string(c, strnlen(c, n));
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

/// Decodes the IMU samples of one message inside the reader's pass (RecordFilter::decode):
/// the columns ImuFromDataflash reads, and its rule for times applied record by record.
class ImuDecoder {
 public:
  /// The decoder of `t`, or nullopt when `t` lacks a time or AccX/Y/Z column (its bodies are
  /// then kept, and ImuFromDataflash says what is missing). `rows_bound`: at most this many
  /// records are coming (0: unknown), to reserve each instance's samples once.
  static std::optional<ImuDecoder> For(const DataflashType& t, std::size_t rows_bound) {
    using Reader = detail::DataflashColumnReader;
    const TimeColumn time = FindTime(t);
    const int acc[3] = {t.ColumnIndex("AccX"), t.ColumnIndex("AccY"), t.ColumnIndex("AccZ")};
    if (time.col < 0 || acc[0] < 0 || acc[1] < 0 || acc[2] < 0) return std::nullopt;
    const int gyr[3] = {t.ColumnIndex("GyrX"), t.ColumnIndex("GyrY"), t.ColumnIndex("GyrZ")};
    ImuDecoder d;
    d.time_ = Reader::Of(t, time.col);
    d.time_scale_ = time.scale;
    for (int k = 0; k < 3; ++k) d.acc_[k] = Reader::Of(t, acc[k]);
    d.has_gyr_ = gyr[0] >= 0 && gyr[1] >= 0 && gyr[2] >= 0;
    if (d.has_gyr_) {
      for (int k = 0; k < 3; ++k) d.gyr_[k] = Reader::Of(t, gyr[k]);
    }
    const int temp = TemperatureColumn(t);
    d.has_temp_ = temp >= 0;
    if (d.has_temp_) d.temp_ = Reader::Of(t, temp);
    // As ImuFromDataflash finds its instances (DataflashInstanceMessage): the I column of
    // "IMU"; any other message (IMU2, ...) is one instance.
    const int instance = t.name == "IMU" ? t.ColumnIndex("I") : -1;
    d.has_instance_ = instance >= 0;
    if (d.has_instance_) d.instance_ = Reader::Of(t, instance);
    const auto plain_float = [](const Reader& r) {
      return r.storage == detail::DataflashStorage::kFloat && r.scale == 1.0;
    };
    bool usual = d.time_.storage == detail::DataflashStorage::kUInt64 && d.time_.scale == 1.0;
    usual = usual && (!d.has_instance_ || d.instance_.storage == detail::DataflashStorage::kUInt8);
    usual = usual && (!d.has_temp_ || plain_float(d.temp_));
    for (int k = 0; k < 3; ++k) {
      usual = usual && plain_float(d.acc_[k]) && (!d.has_gyr_ || plain_float(d.gyr_[k]));
    }
    d.usual_layout_ = usual;
    d.rows_bound_ = std::min(rows_bound, kMaxReserve);
    return d;
  }

  /// Decodes the record body `body` of `t` (the type this decoder was made for).
  void Add(DataflashType& t, const std::uint8_t* body) const {
    if (usual_layout_) {
      AddWith(t, body, UsualColumns{*this});
    } else {
      AddWith(t, body, AnyColumns{*this});
    }
  }

  /// After the last record: every instance's last sample stays (no record follows it).
  void Finish(DataflashType& t) const {
    for (DataflashImuDecoded& d : t.imu) d.last_on_trial = false;
  }

 private:
  /// Reserved samples per instance at most (beyond, the series grow by doubling).
  static constexpr std::size_t kMaxReserve = std::size_t{1} << 24;

  /// The columns read through their readers (DataflashColumnReader::Read, any format
  /// character), the values cast to the series' types.
  struct AnyColumns {
    const ImuDecoder& d;
    /// The record's instance 0..255, or -1 when its I value names none.
    int Instance(const std::uint8_t* body) const {
      const double v = d.instance_.Read(body);
      return v >= 0 && v < 256 && v == std::floor(v) ? static_cast<int>(v) : -1;
    }
    double RawTime(const std::uint8_t* body) const { return d.time_.Read(body); }
    Vec3f Axes(const std::uint8_t* body, const detail::DataflashColumnReader* c) const {
      return Vec3f(static_cast<float>(c[0].Read(body)), static_cast<float>(c[1].Read(body)),
                   static_cast<float>(c[2].Read(body)));
    }
    float Temperature(const std::uint8_t* body) const {
      return static_cast<float>(d.temp_.Read(body));
    }
  };

  /// The columns of the layout ArduPilot writes (usual_layout_: TimeUS 'Q', I 'B', the axes
  /// and T 'f'): the stored values loaded as they are, which are AnyColumns' values without
  /// its switch on the format character.
  struct UsualColumns {
    const ImuDecoder& d;
    int Instance(const std::uint8_t* body) const { return body[d.instance_.offset]; }
    double RawTime(const std::uint8_t* body) const {
      return static_cast<double>(LoadLittleEndian<std::uint64_t>(body + d.time_.offset));
    }
    Vec3f Axes(const std::uint8_t* body, const detail::DataflashColumnReader* c) const {
      return Vec3f(LoadLittleEndian<float>(body + c[0].offset),
                   LoadLittleEndian<float>(body + c[1].offset),
                   LoadLittleEndian<float>(body + c[2].offset));
    }
    float Temperature(const std::uint8_t* body) const {
      return LoadLittleEndian<float>(body + d.temp_.offset);
    }
  };

  /// Add with the columns read by `columns` (AnyColumns or UsualColumns).
  template <typename Columns>
  void AddWith(DataflashType& t, const std::uint8_t* body, const Columns& columns) const {
    std::size_t k = 0;
    if (has_instance_) {
      const int instance = columns.Instance(body);
      if (instance < 0) return;  // no instance's record
      k = static_cast<std::size_t>(instance);
    }
    if (k >= t.imu.size()) t.imu.resize(k + 1);
    DataflashImuDecoded& d = t.imu[k];
    const double raw_t = columns.RawTime(body);
    const double t_s = raw_t * time_scale_;
    if (d.records == 0) {
      d.first_time = raw_t;
      Reserve(d.series);
    }
    d.last_time = raw_t;
    ++d.records;
    ImuSeries& s = d.series;
    if (d.last_on_trial && !(s.t_s.back() < t_s)) PopBack(s);  // it was a spike
    // Kept for now when its time is finite and above the last kept sample's; its fate is
    // sealed by the next record's time (ImuFromDataflash's rule).
    d.last_on_trial = std::isfinite(t_s) && (s.t_s.empty() || t_s > s.t_s.back());
    if (!d.last_on_trial) return;
    s.t_s.push_back(t_s);
    s.acc.push_back(columns.Axes(body, acc_));
    if (has_gyr_) s.gyr.push_back(columns.Axes(body, gyr_));
    if (has_temp_) s.temp_c.push_back(columns.Temperature(body));
  }

  void Reserve(ImuSeries& s) const {
    if (rows_bound_ == 0) return;
    ReserveHugePages(s.t_s, rows_bound_);
    ReserveHugePages(s.acc, rows_bound_);
    if (has_gyr_) ReserveHugePages(s.gyr, rows_bound_);
    if (has_temp_) ReserveHugePages(s.temp_c, rows_bound_);
  }

  /// Takes the last sample out of `s`.
  void PopBack(ImuSeries& s) const {
    s.t_s.pop_back();
    s.acc.pop_back();
    if (has_gyr_) s.gyr.pop_back();
    if (has_temp_) s.temp_c.pop_back();
  }

  detail::DataflashColumnReader time_, acc_[3], gyr_[3], temp_, instance_;
  double time_scale_ = 0.0;
  bool has_gyr_ = false;
  bool has_temp_ = false;
  bool has_instance_ = false;
  /// The time column is 'Q', the instance column 'B', the axes and temperature 'f' (scale 1):
  /// Add reads them with UsualColumns.
  bool usual_layout_ = false;
  std::size_t rows_bound_ = 0;
};

/// The one-pass decoder state: fed the file's bytes in order, in one piece (ParseDataflash) or
/// in chunks (ReadDataflash, through ReadForward).
class Parser {
 public:
  /// The longest record: its length is one byte, header included.
  static constexpr std::size_t kMaxRecord = 255;

  /// `filter`: the types whose bodies are kept or samples decoded; `size_hint`: the input's
  /// size in bytes (0: unknown), to reserve decoded samples once.
  Parser(DataflashLog* log, const RecordFilter& filter, std::size_t size_hint)
      : log_(log), filter_(filter), size_hint_(size_hint) {
    index_.fill(-1);
    decoder_of_.fill(-1);
    rows_.fill(0);
    AddType(detail::DataflashFmtType(&log_->warnings));
  }

  /// After the last Feed: the record counts go to the types, and the decoded IMU messages'
  /// waiting records are decided.
  void Finish() {
    for (DataflashType& t : log_->types) t.rows = rows_[t.id];
    for (std::size_t id = 0; id < decoder_of_.size(); ++id) {
      if (decoder_of_[id] < 0) continue;
      decoders_[static_cast<std::size_t>(decoder_of_[id])].Finish(
          log_->types[static_cast<std::size_t>(index_[id])]);
    }
  }

  /// Decodes the records starting in the bytes [offset, offset + n) of the input held at
  /// `data`; returns the offset to go on from (unless `at_end`, at least kMaxRecord bytes
  /// before offset + n, so that every record starting before it is whole). `at_end`: the bytes
  /// end the input (the truncated last record and trailing bytes are counted).
  std::size_t Feed(const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
    // The loop reads one table per record (length and action by type byte) and touches a
    // type only for the records it keeps or decodes: the walk from record to record is the
    // chain of loads byte -> length -> next byte, nothing more.
    const std::size_t room = at_end ? kHeaderSize : kMaxRecord;  // bytes a record may need
    std::size_t i = 0;
    while (n - i >= room) {
      const std::uint8_t* p = data + i;
      const Entry e = table_[p[2]];
      if (p[0] == kHead1 && p[1] == kHead2 && e.length != 0) {
        if (e.length > n - i) {
          Truncated(n - i);
          return offset + n;
        }
        ++rows_[p[2]];
        i += e.length;
        if (e.action != Action::kCount) Act(e.action, p[2], p + kHeaderSize, offset + i);
        continue;
      }
      Skip(offset + i);
      ++i;
    }
    if (!at_end) return offset + i;
    const std::size_t tail = n - i;
    if (tail == 0) return offset + n;
    const bool header_prefix = data[i] == kHead1 && (tail == 1 || data[i + 1] == kHead2);
    if (header_prefix) {
      Truncated(tail);
    } else {
      for (std::size_t k = 0; k < tail; ++k) Skip(offset + i + k);
    }
    return offset + n;
  }

 private:
  /// What the loop does with a record of a type besides counting it.
  enum class Action : std::uint8_t { kCount, kKeep, kDecode, kFmt };
  /// A type's entry in the loop's table, by type byte.
  struct Entry {
    std::uint8_t length = 0;  ///< record length with the header; 0: no type has this byte
    Action action = Action::kCount;
  };

  /// Keeps (kKeep, kFmt) or decodes (kDecode) the record body `body` of type `id`; an FMT
  /// (kFmt, its record ending at byte `end`) defines a type.
  void Act(Action action, std::uint8_t id, const std::uint8_t* body, std::size_t end) {
    DataflashType& t = log_->types[static_cast<std::size_t>(index_[id])];
    if (action == Action::kDecode) {
      decoders_[static_cast<std::size_t>(decoder_of_[id])].Add(t, body);
      return;
    }
    t.bodies.Append(body);
    if (action == Action::kFmt) HandleFmt(body, t.body_size, end);
  }

  /// Adds a type from its FMT, found at byte `offset`.
  void AddType(DataflashType t, std::size_t offset = 0) {
    t.bodies_kept = t.id == kFmtType || filter_.Keeps(t.name);
    if (t.id != kFmtType && filter_.Decodes(t.name) && t.length > 0) {
      const std::size_t rest = size_hint_ > offset ? size_hint_ - offset : 0;
      if (std::optional<ImuDecoder> d = ImuDecoder::For(t, rest / t.length + 1)) {
        t.imu_decoded = true;
        t.bodies_kept = false;
        decoder_of_[t.id] = static_cast<int>(decoders_.size());
        decoders_.push_back(*d);
      }
    }
    Entry& e = table_[t.id];
    e.length = static_cast<std::uint8_t>(t.length);  // 3..255 (AcceptFmt, one byte)
    e.action = t.id == kFmtType ? Action::kFmt
               : t.imu_decoded  ? Action::kDecode
               : t.bodies_kept  ? Action::kKeep
                                : Action::kCount;
    index_[t.id] = static_cast<int>(log_->types.size());
    log_->types.push_back(std::move(t));
  }

  void Skip(std::size_t pos) { CountSkipped(log_->warnings, pos, pos + 1, skip_end_); }

  void Truncated(std::size_t bytes) {
    ++log_->warnings.truncated_records;
    log_->warnings.truncated_bytes += bytes;
  }

  // FMT body: Type (B), Length (B), Name (n), Format (N), Columns (Z) = 86 bytes.
  void HandleFmt(const std::uint8_t* body, std::size_t body_size, std::size_t offset) {
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
    AddType(detail::MakeDataflashType(id, length, name, format, columns, &log_->warnings),
            offset);
  }

  DataflashLog* log_;
  const RecordFilter& filter_;
  std::size_t size_hint_ = 0;   ///< the input's size, bytes (0: unknown)
  std::array<int, 256> index_;
  std::array<int, 256> decoder_of_;  ///< index in decoders_ by type id, -1: not decoded
  std::array<Entry, 256> table_{};    ///< the loop's table by type id
  std::array<std::size_t, 256> rows_;  ///< records counted by type id
  std::vector<ImuDecoder> decoders_;
  std::size_t skip_end_ = 0;  ///< end of the last skipped range (CountSkipped)
};

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

}  // namespace

DataflashLog ParseDataflash(const std::uint8_t* data, std::size_t size,
                            const std::string& source, const RecordFilter& filter) {
  DataflashLog log;
  log.source = source;
  log.size_bytes = size;
  Parser parser(&log, filter, size);
  parser.Feed(data, size, 0, true);
  parser.Finish();
  FinishParse(&log, size);
  return log;
}

DataflashLog ReadDataflash(const std::string& path, const RecordFilter& filter) {
  DataflashLog log;
  log.source = path;
  Parser parser(&log, filter, RegularFileSize(path));
  // One pass, in chunks: every record is decoded from the read buffer as it goes by.
  ReadForward(path, "DataFlash log", Parser::kMaxRecord,
              [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
                if (at_end) log.size_bytes = offset + n;
                return parser.Feed(data, n, offset, at_end);
              });
  parser.Finish();
  FinishParse(&log, log.size_bytes);
  return log;
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
  if (type->rows == 0) {
    throw InputError(log.source, "",
                     "the log defines " + type->name + " (FMT) but holds no " + type->name +
                         " rows: no IMU samples were logged (LOG_BITMASK without IMU?)");
  }
  if (type->imu_decoded) {  // decoded by the reader, with the rule below
    if (const ImuSeries* decoded = DecodedDataflashImu(log, instance)) return CopySeries(*decoded);
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
    if (pending == nullptr || !std::isfinite(pending_t)) return;
    if (!s.t_s.empty() && !(pending_t > s.t_s.back())) return;
    if (below_next) keep(pending, pending_t);
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

}  // namespace plumb::io

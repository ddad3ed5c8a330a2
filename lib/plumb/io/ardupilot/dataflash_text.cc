// plumb/io/ardupilot/dataflash_text.cc — ArduPilot text logs (.log); see dataflash.h for the
// contract.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <string_view>
#include <type_traits>

#include "plumb/core/error.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/ardupilot/dataflash_format.h"
#include "plumb/io/common/text_scan.h"
#include "plumb/io/common/stream_spool.h"

namespace plumb::io {
namespace {

constexpr std::uint8_t kModeNameValue = 255;      // stored for an 'M' field holding a name
constexpr std::size_t kSniffBytes = 8192;         // LooksLikeDataflashText reads this much
constexpr std::size_t kSniffMaxHeaderLines = 16;  // non-blank lines allowed before the FMT

using detail::DataflashStorage;

bool IsTextFormat(char c) { return detail::DataflashFormat(c).storage == DataflashStorage::kText; }

/// One line split at its commas: trimmed fields and where each starts in the line.
struct SplitLine {
  std::vector<std::string_view> fields;
  std::vector<std::size_t> starts;

  void Split(std::string_view line) {
    fields.clear();
    starts.clear();
    std::size_t pos = 0;
    while (true) {
      const std::size_t comma = line.find(',', pos);
      const std::size_t stop = comma == std::string_view::npos ? line.size() : comma;
      fields.push_back(detail::Trim(line.substr(pos, stop - pos)));
      starts.push_back(pos);
      if (comma == std::string_view::npos) break;
      pos = comma + 1;
    }
  }
};

template <typename T>
void Store(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof(T));
}

/// A whole-field number that is integral and inside [lo, hi].
bool ParseIntegral(std::string_view text, double lo, double hi, double* value) {
  double v;
  if (!detail::ParseNumber(text, v) || !std::isfinite(v) || v != std::floor(v)) return false;
  if (v < lo || v > hi) return false;
  *value = v;
  return true;
}

template <typename T>
bool EncodeInteger(std::string_view text, std::uint8_t* p) {
  double v;
  if (!ParseIntegral(text, static_cast<double>(std::numeric_limits<T>::lowest()),
                     static_cast<double>(std::numeric_limits<T>::max()), &v)) {
    return false;
  }
  Store<T>(p, static_cast<T>(v));
  return true;
}

/// 64-bit integers: exactly when written as plain digits, else through a double.
template <typename T>
bool EncodeInteger64(std::string_view text, std::uint8_t* p) {
  T v{};
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec == std::errc() && r.ptr == text.data() + text.size()) {
    Store<T>(p, v);
    return true;
  }
  double d;
  // 2^63 and 2^64 are exact doubles; the limits below keep the cast defined.
  const double hi = std::is_signed_v<T> ? 9223372036854775808.0 : 18446744073709551616.0;
  const double lo = std::is_signed_v<T> ? -hi : 0.0;
  if (!ParseIntegral(text, lo, hi, &d) || d == hi) return false;
  Store<T>(p, static_cast<T>(d));
  return true;
}

/// A scaled integer (c/C/e/E/L): the text holds value * `scale`, stored round(value / scale).
template <typename T>
bool EncodeScaled(std::string_view text, double inverse_scale, std::uint8_t* p) {
  double v;
  if (!detail::ParseNumber(text, v) || !std::isfinite(v)) return false;
  const double stored = std::round(v * inverse_scale);
  if (stored < static_cast<double>(std::numeric_limits<T>::lowest()) ||
      stored > static_cast<double>(std::numeric_limits<T>::max())) {
    return false;
  }
  Store<T>(p, static_cast<T>(stored));
  return true;
}

/// A scaled integer field (c/C/e/E/L) of `storage`: see EncodeScaled.
bool EncodeScaledField(DataflashStorage storage, std::string_view text, double inverse_scale,
                       std::uint8_t* p) {
  switch (storage) {
    case DataflashStorage::kInt16: return EncodeScaled<std::int16_t>(text, inverse_scale, p);
    case DataflashStorage::kUInt16: return EncodeScaled<std::uint16_t>(text, inverse_scale, p);
    case DataflashStorage::kInt32: return EncodeScaled<std::int32_t>(text, inverse_scale, p);
    case DataflashStorage::kUInt32: return EncodeScaled<std::uint32_t>(text, inverse_scale, p);
    default: return false;
  }
}

/// Encodes one text field into the binary field at `p` (`size` bytes) as the format table
/// says. False when it does not parse or fit; sets *mode_name for an 'M' field holding a name.
bool EncodeField(char format, std::string_view text, std::uint8_t* p, std::size_t size,
                 bool* mode_name) {
  const detail::DataflashFormatChar& f = detail::DataflashFormat(format);
  if (f.flight_mode) {
    double number;
    if (detail::ParseNumber(text, number)) return EncodeInteger<std::uint8_t>(text, p);
    if (text.empty()) return false;
    Store<std::uint8_t>(p, kModeNameValue);  // a mode name ("Stabilize")
    *mode_name = true;
    return true;
  }
  if (f.inverse_scale != 0.0) return EncodeScaledField(f.storage, text, f.inverse_scale, p);
  switch (f.storage) {
    case DataflashStorage::kInt8: return EncodeInteger<std::int8_t>(text, p);
    case DataflashStorage::kUInt8: return EncodeInteger<std::uint8_t>(text, p);
    case DataflashStorage::kInt16: return EncodeInteger<std::int16_t>(text, p);
    case DataflashStorage::kUInt16: return EncodeInteger<std::uint16_t>(text, p);
    case DataflashStorage::kInt32: return EncodeInteger<std::int32_t>(text, p);
    case DataflashStorage::kUInt32: return EncodeInteger<std::uint32_t>(text, p);
    case DataflashStorage::kInt64: return EncodeInteger64<std::int64_t>(text, p);
    case DataflashStorage::kUInt64: return EncodeInteger64<std::uint64_t>(text, p);
    case DataflashStorage::kFloat: {
      double v;
      if (!detail::ParseNumber(text, v)) return false;
      // Out of float range: not a value ArduPilot could have logged.
      if (std::isfinite(v) && std::abs(v) > std::numeric_limits<float>::max()) return false;
      Store<float>(p, static_cast<float>(v));
      return true;
    }
    case DataflashStorage::kDouble: {
      double v;
      if (!detail::ParseNumber(text, v)) return false;
      Store<double>(p, v);
      return true;
    }
    case DataflashStorage::kText:
      std::memcpy(p, text.data(), std::min(text.size(), size));
      return true;
    case DataflashStorage::kArray:
      return true;  // arrays are not written in text logs in a known form: zeros
    case DataflashStorage::kUnknown:
      return false;
  }
  return false;
}

class TextParser {
 public:
  /// `filter`: the types whose rows are stored (all are still checked and counted).
  TextParser(DataflashLog* log, const RecordFilter& filter) : log_(log), filter_(filter) {
    AddType(detail::DataflashFmtType(&log_->warnings));
  }

  /// Decodes every line of `source` (a file read in chunks or text in memory).
  void Run(detail::LineSource& source) {
    std::string_view line;
    while (source.Next(line)) {
      line_number_ = source.line_number();
      const std::string_view trimmed = detail::Trim(line);
      if (trimmed.empty()) continue;
      split_.Split(trimmed);
      const std::string_view name = split_.fields.front();
      if (!seen_fmt_) {
        if (name != "FMT") {
          ++log_->warnings.text_header_lines;
          continue;
        }
        seen_fmt_ = true;
      }
      HandleRecord(trimmed, name);
    }
  }

  std::size_t lines() const { return line_number_; }

 private:
  void AddType(DataflashType t) {
    t.bodies_kept = t.id == detail::kDataflashFmtType || filter_.Keeps(t.name);
    index_[t.id] = static_cast<int>(log_->types.size());
    by_name_[t.name] = static_cast<int>(log_->types.size());
    log_->types.push_back(std::move(t));
  }

  void Bad(const std::string& what) {
    DataflashWarnings& w = log_->warnings;
    if (w.text_bad_lines == 0) {
      w.text_first_bad_line = line_number_;
      w.text_first_bad_what = what;
    }
    ++w.text_bad_lines;
  }

  void HandleRecord(std::string_view line, std::string_view name) {
    const auto it = by_name_.find(std::string(name));
    if (it == by_name_.end()) {
      Bad("message " + detail::Quote(name) + " has no FMT");
      return;
    }
    DataflashType& t = log_->types[static_cast<std::size_t>(it->second)];
    const std::vector<std::string_view>& f = split_.fields;
    std::size_t values = f.size() - 1;
    // The number of values the FMT asks for: every format character (fields past the
    // length are read and dropped); with an unknown character, at least the decodable ones.
    const bool all_known = t.format.size() == t.columns.size() ||
                           std::all_of(t.format.begin(), t.format.end(), [](char c) {
                             return detail::DataflashFormatSize(c) > 0;
                           });
    const std::size_t expected = all_known ? t.format.size() : t.columns.size();
    while (values > expected && f[values].empty()) --values;  // trailing ", "
    std::string_view last_text;  // a last text column taking the rest of the line
    const bool rest_is_text = all_known && expected > 0 && IsTextFormat(t.format.back());
    if (rest_is_text && values > expected) {
      last_text = detail::Trim(line.substr(split_.starts[expected]));
      values = expected;
    }
    if (all_known ? values != expected : values < expected) {
      Bad(std::to_string(values) + " values for " + t.name + ", its FMT has " +
          std::to_string(expected));
      return;
    }
    row_.assign(t.body_size, 0);
    bool mode_name = false;
    for (std::size_t c = 0; c < t.columns.size(); ++c) {
      const DataflashColumn& col = t.columns[c];
      const std::string_view text =
          (!last_text.empty() && c + 1 == expected) ? last_text : f[c + 1];
      if (!EncodeField(col.format, text, row_.data() + col.offset, col.size, &mode_name)) {
        Bad(t.name + "." + col.name + " = " + detail::Quote(text) + " is not a value of format '" +
            std::string(1, col.format) + "'");
        return;
      }
    }
    if (t.id == detail::kDataflashFmtType && !CheckFmt(f)) return;
    if (mode_name) ++log_->warnings.text_mode_names;
    if (t.bodies_kept) t.bodies.Append(row_.data());
    ++t.rows;
    if (t.id == detail::kDataflashFmtType) DefineType(f);
  }

  /// An FMT line whose name or format does not fit its binary field is malformed.
  bool CheckFmt(const std::vector<std::string_view>& f) {
    if (f[3].empty() || f[3].size() > detail::kFmtNameSize ||
        f[4].size() > detail::kFmtFormatSize) {
      Bad("FMT name " + detail::Quote(f[3]) + " (1..4 characters) or format " +
          detail::Quote(f[4]) + " (up to 16) does not fit");
      return false;
    }
    return true;
  }

  /// Registers the type an FMT line defines (fields: FMT, type, length, name, format, cols...).
  void DefineType(const std::vector<std::string_view>& f) {
    double id_value = 0, length_value = 0;
    ParseIntegral(f[1], 0, 255, &id_value);  // both checked by EncodeField ('B')
    ParseIntegral(f[2], 0, 255, &length_value);
    const auto id = static_cast<std::uint8_t>(id_value);
    const auto length = static_cast<std::size_t>(length_value);
    const std::string name(f[3]);
    const std::string format(f[4]);
    std::size_t last = f.size();
    while (last > 5 && f[last - 1].empty()) --last;
    std::string columns;
    for (std::size_t k = 5; k < last; ++k) {
      columns += (k > 5 ? "," : "") + std::string(f[k]);
    }
    DataflashWarnings& w = log_->warnings;
    const int existing = index_[id];
    const DataflashType* known =
        existing >= 0 ? &log_->types[static_cast<std::size_t>(existing)] : nullptr;
    if (!detail::AcceptFmt(known, length, name, format, &w)) return;
    if (by_name_.count(name)) {
      ++w.fmt_conflicts;  // a second type id under a known name: lines could not tell them apart
      return;
    }
    DataflashType t = detail::MakeDataflashType(id, length, name, format, columns, &w);
    // A text row stores only the bytes its columns occupy: an FMT claiming a long record for
    // a short format must not make each short line cost the claimed length in memory.
    std::size_t used = 0;
    for (const DataflashColumn& c : t.columns) used = std::max(used, c.offset + c.size);
    t.body_size = std::min(t.body_size, used);
    AddType(std::move(t));
  }

  DataflashLog* log_;
  const RecordFilter& filter_;
  std::array<int, 256> index_ = MinusOnes();
  std::map<std::string, int> by_name_;
  SplitLine split_;
  std::vector<std::uint8_t> row_;
  std::size_t line_number_ = 0;
  bool seen_fmt_ = false;

  static std::array<int, 256> MinusOnes() {
    std::array<int, 256> a;
    a.fill(-1);
    return a;
  }
};

/// Decodes the lines of `lines`; `source` names the log in errors.
DataflashLog ParseDataflashLines(detail::LineSource& lines, const std::string& source,
                                 const RecordFilter& filter) {
  DataflashLog log;
  log.source = source;
  log.size_bytes = lines.size_bytes();
  TextParser parser(&log, filter);
  parser.Run(lines);
  if (log.types.front().rows == 0) {
    throw InputError(source, "line " + std::to_string(std::max<std::size_t>(parser.lines(), 1)),
                     "no valid FMT line (\"FMT, <type>, <length>, <name>, <format>, <columns>\") "
                     "in " + std::to_string(parser.lines()) +
                         " lines: not an ArduPilot text log");
  }
  detail::FinishDataflashLog(&log);
  return log;
}

}  // namespace

DataflashLog ParseDataflashText(const char* data, std::size_t size, const std::string& source,
                                const RecordFilter& filter) {
  detail::LineSource lines = detail::LineSource::FromText(std::string_view(data, size), source);
  return ParseDataflashLines(lines, source, filter);
}

DataflashLog ReadDataflashText(const std::string& path, const RecordFilter& filter) {
  // Streamed: the file is read in chunks (1 MiB, more only for a longer line), never held whole (issue 13 point 4).
  detail::LineSource lines = detail::LineSource::FromFile(path);
  return ParseDataflashLines(lines, path, filter);
}

bool LooksLikeDataflashText(const std::string& path) {
  std::ifstream in(OpenPath(path), std::ios::binary);
  if (!in) return false;
  std::string head(kSniffBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.size() >= 2 && static_cast<unsigned char>(head[0]) == detail::kDataflashHead1 &&
      static_cast<unsigned char>(head[1]) == detail::kDataflashHead2) {
    return false;
  }
  std::size_t header_lines = 0;
  std::size_t pos = 0;
  while (pos < head.size() && header_lines <= kSniffMaxHeaderLines) {
    std::size_t end = head.find('\n', pos);
    if (end == std::string::npos) end = head.size();
    const std::string_view line = detail::Trim(std::string_view(head).substr(pos, end - pos));
    pos = end + 1;
    for (char c : line) {
      const auto u = static_cast<unsigned char>(c);
      if (u < 0x20 && c != '\t' && c != '\r') return false;  // binary, not text
    }
    if (line.empty() || line == "\r") continue;
    if (line.substr(0, 4) == "FMT,") return true;
    ++header_lines;
  }
  return false;
}

}  // namespace plumb::io

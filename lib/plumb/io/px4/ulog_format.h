// plumb/io/px4/ulog_format.h — INTERNAL to plumb::io_px4: the ULog definitions (the file
// header and the message header, the size rules of the message types, the key-value bodies of
// I/P/Q/M messages, timestamps, the basic field types, F message parsing, and the resolution of
// a subscribed format into flattened columns) apart from the reading of messages and data (the
// parser, ulog_parser.h). See ulog.h for the format and the decoding contract. Not part of the
// public interface.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plumb/io/px4/ulog.h"

namespace plumb::io::detail {

/// The first 7 bytes of every ULog file.
inline constexpr std::uint8_t kULogMagic[7] = {'U', 'L', 'o', 'g', 0x01, 0x12, 0x35};
/// The file header: the magic, the version byte, the uint64 start time.
inline constexpr std::size_t kULogFileHeaderSize = 16;
/// Every message's header: uint16 msg_size (the bytes after the header), uint8 type.
inline constexpr std::size_t kULogMsgHeaderSize = 3;
/// The B (flag bits) body: uint8 compat[8], uint8 incompat[8], uint64 appended_offsets[3].
inline constexpr std::size_t kULogFlagBitsSize = 40;  // 8 + 8 + 3 * 8
/// The body of an S (sync) message.
inline constexpr std::uint8_t kULogSyncMagic[8] = {0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12};
/// The largest D body after its msg_id, bytes.
inline constexpr std::size_t kULogMaxDataBody = 65535 - 2;
/// The deepest nesting of formats resolved.
inline constexpr int kULogMaxNesting = 32;

/// The message types of ULog version 1.
inline bool ULogIsKnownType(std::uint8_t c) {
  return std::memchr("BFIMPQARDLCSO", c, 13) != nullptr && c != 0;
}

/// The size rule of a D message. The PX4 "ULog File Format" lays it out as uint16 msg_id, then
/// data[msg_size - 2], the subscribed format's bytes ("'D': Logged Data Message"), and lets a
/// writer leave out a `_padding` field that ends the format, the data being shorter by its size
/// ("'F': Format Message"). So a D message of `size` bytes after its header fits a topic whose
/// format is `full_size` bytes, `body_size` without its trailing padding fields, when it holds
/// the msg_id and between body_size and full_size bytes after it. The one statement of the
/// rule: the parser's common case, its check of a header and its resynchronisation ask it.
constexpr bool ULogDataSizeFits(std::size_t size, std::size_t body_size, std::size_t full_size) {
  return size >= 2 && size - 2 >= body_size && size - 2 <= full_size;
}

/// True when a message of type S, O, R, L or C of `size` bytes breaks its type's rule (an S
/// of 8 bytes with the sync magic, checked when its body `body` is whole: else nullptr; an O
/// or R of 2 bytes; an L of 9 bytes or more, a C of 11 or more). False for other types.
inline bool ULogFixedRuleBroken(std::uint8_t type, std::size_t size, const std::uint8_t* body) {
  switch (type) {
    case 'S':
      return size != sizeof(kULogSyncMagic) ||
             (body != nullptr && std::memcmp(body, kULogSyncMagic, sizeof(kULogSyncMagic)) != 0);
    case 'O': case 'R': return size != 2;
    case 'L': return size < 9;
    case 'C': return size < 11;
    default: return false;
  }
}

/// Key and value of an I/P/Q/M body after its leading bytes: uint8 key_len, key, value.
struct ULogKeyValue {
  std::string type;   ///< e.g. "int32_t", "char[5]"
  std::string name;
  const std::uint8_t* value = nullptr;
  std::size_t value_size = 0;
};

/// The key and value of the `n` bytes at `p`; nullopt when they do not parse.
std::optional<ULogKeyValue> ParseULogKeyValue(const std::uint8_t* p, std::size_t n);

/// A parameter value (int32_t or float, 4 bytes); nullopt otherwise.
std::optional<double> ULogParamValue(const ULogKeyValue& kv);

/// An info value as text: strings as they are, numbers in decimal, anything else in hex.
std::string ULogInfoText(const ULogKeyValue& kv);

/// A "timestamp" field of type `type` stored at `p`, us (uint8 timestamps are milliseconds by
/// the format; other types: 0).
inline std::uint64_t ULogTimestampAt(const std::uint8_t* p, ULogType type) {
  switch (type) {
    case ULogType::kUInt64: return LoadLittleEndian<std::uint64_t>(p);
    case ULogType::kUInt32: return LoadLittleEndian<std::uint32_t>(p);
    case ULogType::kUInt16: return LoadLittleEndian<std::uint16_t>(p);
    case ULogType::kUInt8: return std::uint64_t{LoadLittleEndian<std::uint8_t>(p)} * 1000u;
    default: return 0;
  }
}

/// The type and size in bytes of a basic type name ("int8_t" .. "char"), or nullopt for a
/// nested type name.
std::optional<std::pair<ULogType, std::size_t>> ULogBasicType(std::string_view name);

/// True for a field that only pads ("_padding0", ...): it keeps its bytes but is no column.
inline bool ULogIsPadding(std::string_view field) { return field.substr(0, 8) == "_padding"; }

/// Parses an F body "name:type field;type[n] field;..."; false when malformed.
bool ParseULogFormat(std::string_view text, std::string* name,
                     std::vector<ULogFormatField>* fields);

/// Resolves a subscribed format into flattened columns (see the contract in ulog.h). Sizes and
/// column counts of resolved types are cached (a redefined format clears the cache), and the
/// columns created over the whole log are limited to a budget proportional to the input, so
/// that no input makes resolution slow or large.
class ULogFormatResolver {
 public:
  ULogFormatResolver(const std::map<std::string, std::vector<ULogFormatField>>& formats,
                     std::size_t column_budget)
      : formats_(formats), column_budget_(column_budget) {}

  /// Forgets cached layouts (call when a format is redefined).
  void Invalidate() { cache_.clear(); }

  /// Columns the topics resolved from now on may still take (the budget left).
  std::size_t budget_left() const { return column_budget_; }
  /// Sets the budget left: a parser taking over another's resolutions (the two-part read).
  void set_budget_left(std::size_t columns) { column_budget_ = columns; }

  /// Fills columns, body_size, full_size and timestamp_col of `topic`; false if unresolvable
  /// or over the column budget.
  bool Resolve(ULogTopic* topic);

 private:
  struct Layout {
    std::size_t size = 0;     ///< bytes
    std::size_t columns = 0;  ///< non-padding basic fields after flattening
  };

  /// Layout of a type; nullopt when unknown, circular or nested deeper than kULogMaxNesting,
  /// empty, or larger than a D message. Only successes are cached: they do not depend on the
  /// depth they were computed at.
  std::optional<Layout> LayoutOf(const std::string& type, int depth);

  void Flatten(const std::vector<ULogFormatField>& fields, const std::string& prefix,
               std::size_t* offset, std::vector<ULogColumn>* out);

  const std::map<std::string, std::vector<ULogFormatField>>& formats_;
  std::size_t column_budget_;
  std::map<std::string, Layout> cache_;
};

}  // namespace plumb::io::detail

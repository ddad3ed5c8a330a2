// plumb/io/px4/ulog_format.h — INTERNAL to plumb::io_px4: the ULog definitions (the file magic,
// the basic field types, F message parsing, and the resolution of a subscribed format into
// flattened columns) apart from the reading of messages and data (ulog.cc). See ulog.h for the
// format and the decoding contract. Not part of the public interface.
#pragma once

#include <cstddef>
#include <cstdint>
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
/// The largest D body after its msg_id, bytes.
inline constexpr std::size_t kULogMaxDataBody = 65535 - 2;
/// The deepest nesting of formats resolved.
inline constexpr int kULogMaxNesting = 32;

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

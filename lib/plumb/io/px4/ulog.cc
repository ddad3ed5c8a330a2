// plumb/io/px4/ulog.cc — see ulog.h for the format and the decoding contract: the reader's
// entry points (ReadULog, ParseULog: the file or bytes through the parser, ulog_parser.h, in one
// part or in parts) and the decoded log's own functions.
#include "plumb/io/px4/ulog.h"

#include <optional>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/split_read.h"
#include "plumb/io/px4/ulog_format.h"
#include "plumb/io/px4/ulog_parser.h"

namespace plumb::io {
namespace {

using detail::ULogParser;

/// The "timestamp" field of the message body `body` of `t`, us; 0 when the topic has none.
std::uint64_t TimestampOf(const ULogTopic& t, const std::uint8_t* body) {
  if (t.timestamp_col < 0) return 0;
  const ULogColumn& c = t.columns[static_cast<std::size_t>(t.timestamp_col)];
  return detail::ULogTimestampAt(body + c.offset, c.type);
}

/// A value asked of a topic whose bodies the reader's RecordFilter left out: a caller's bug.
[[noreturn]] void NotKept(const std::string& name) {
  throw Error("ULog topic " + name + ": its message bodies were not kept (RecordFilter)");
}

}  // namespace

int ULogTopic::ColumnIndex(std::string_view column) const {
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c].name == column) return static_cast<int>(c);
  }
  return -1;
}

void ULogTopic::ThrowNotKept() const { NotKept(name); }

std::uint64_t ULogTopic::TimestampUs(std::size_t row) const {
  if (!bodies_kept) NotKept(name);
  return TimestampOf(*this, bodies.Row(row));
}

std::vector<double> ULogTopic::Column(std::string_view column) const {
  const int c = ColumnIndex(column);
  if (c < 0) throw Error("ULog topic " + name + " has no field " + std::string(column));
  std::vector<double> out(rows);
  for (std::size_t r = 0; r < rows; ++r) out[r] = Value(r, static_cast<std::size_t>(c));
  return out;
}

bool ULogWarnings::any() const {
  return bytes_skipped || truncated_records || unknown_msg_id_messages ||
         unknown_type_messages || malformed_messages || unresolved_subscriptions ||
         bad_appended_offsets || unknown_version;
}

std::vector<std::string> ULogWarnings::Describe() const {
  std::vector<std::string> out;
  const auto n = [](std::size_t v) { return std::to_string(v); };
  if (bytes_skipped) {
    out.push_back("skipped " + n(bytes_skipped) + " bytes in " + n(skip_runs) +
                  " run(s) after corrupt message headers (first at byte " +
                  n(first_skip_offset) + ")");
  }
  if (truncated_records) {
    out.push_back("dropped " + n(truncated_records) + " truncated message(s) (" +
                  n(truncated_bytes) + " bytes)");
  }
  if (unknown_msg_id_messages) {
    out.push_back(n(unknown_msg_id_messages) + " data message(s) of an unsubscribed msg_id");
  }
  if (unknown_type_messages) {
    out.push_back(n(unknown_type_messages) + " message(s) of an unknown type, skipped");
  }
  if (malformed_messages) {
    out.push_back(n(malformed_messages) + " malformed definition/info message(s), skipped");
  }
  if (unresolved_subscriptions) {
    out.push_back(n(unresolved_subscriptions) +
                  " subscription(s) whose format cannot be resolved (their data is skipped)");
  }
  if (bad_appended_offsets) {
    out.push_back(n(bad_appended_offsets) + " invalid appended-data offset(s), ignored");
  }
  if (unknown_version) out.push_back("ULog version byte above 1: read as version 1");
  return out;
}

const ULogTopic* ULog::Find(std::string_view name, int multi_id) const {
  const ULogTopic* best = nullptr;
  for (const ULogTopic& t : topics) {
    if (t.name == name && t.multi_id == multi_id && (best == nullptr || t.rows > best->rows)) {
      best = &t;
    }
  }
  return best;
}

std::vector<std::pair<std::string, std::size_t>> ULog::MessageCounts() const {
  std::vector<std::pair<std::string, std::size_t>> out;
  for (const ULogTopic& t : topics) {
    if (t.rows > 0) out.emplace_back(t.name + "/" + std::to_string(t.multi_id), t.rows);
  }
  return out;
}

namespace {

/// The log of `source` (`size` bytes; 0: unknown, a pipe), named `name`, decoded in one part
/// or two (options).
ULog Decode(const ByteSource& source, std::size_t size, const std::string& name,
            const RecordFilter& filter, const ULogReadOptions& options) {
  ULog log;
  log.source = name;
  log.size_bytes = size;
  std::optional<ULogParser> parser;  // made at the first call when the size is not known before
  if (size > 0) parser.emplace(size, &log, filter);
  const std::size_t from = parser ? detail::DecodeStart<ULog>(source, size, *parser, options) : 0;
  // One pass (the rest of it), in chunks: every message is decoded from the read buffer as it
  // goes by.
  source(from, [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
    if (at_end) log.size_bytes = offset + n;
    if (!parser) parser.emplace(log.size_bytes, &log, filter);
    return parser->Feed(data, n, offset, at_end);
  });
  if (parser) parser->Finish();
  for (ULogTopic& t : log.topics) {
    if (t.imu_decoded) t.imu_left_out = KeepIncreasingTimes(t.imu);
  }
  return log;
}

}  // namespace

ULog ParseULog(const std::uint8_t* data, std::size_t size, const std::string& source,
               const RecordFilter& filter, const ULogReadOptions& options) {
  return Decode(MemoryBytes(data, size), size, source, filter, options);
}

ULog ReadULog(const std::string& path, const RecordFilter& filter,
              const ULogReadOptions& options) {
  return Decode(FileBytes(path, "ULog file", ULogParser::kLookahead), RegularFileSize(path),
                path, filter, options);
}

}  // namespace plumb::io

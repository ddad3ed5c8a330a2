// plumb/io/px4/ulog.h — PX4 ULog files (.ulg), driven by the log's own format definitions.
//
// Format (PX4 "ULog File Format", little endian): a 16-byte header — the magic 'U' 'L' 'o' 'g'
// 0x01 0x12 0x35, a version byte (0 in 2016 logs, 1 since; both read the same way, higher
// versions are read with a warning) and the uint64 start time in microseconds — then a stream
// of messages, each a 3-byte header (uint16 msg_size = bytes after the header, uint8 type)
// and a body:
//   B flag bits (first message only): uint8 compat[8], uint8 incompat[8], uint64
//     appended_offsets[3]; incompat[0] bit 0 = data appended at those file offsets; any other
//     incompat bit means the log cannot be read.
//   F format "name:type field;type[n] field;..." (types int8_t..uint64_t, float, double, bool,
//     char, or another format's name: nested); I info / P parameter: uint8 key_len, key
//     "type name", value (P: int32_t or float); M info multiple: uint8 is_continued first;
//     Q default parameter: uint8 default-type bits first.
//   A add logged: uint8 multi_id, uint16 msg_id, topic name; R remove; D data: uint16 msg_id
//     and the topic's bytes; L logging: uint8 level, uint64 time (us), text; C tagged logging:
//     uint8 level, uint16 tag, uint64 time, text; S sync: 8 magic bytes 2F 73 13 20 25 0C BB
//     12; O dropout: uint16 duration (ms).
//
// Decoding contract (one pass over the file, read forward in chunks by ReadULog):
//  * Parameters: P messages before the first A, L or C are the initial values (`params`);
//    later ones are changes (`param_changes`).
//  * A subscription's format is resolved when its A message arrives: nested formats are
//    flattened into columns named "outer.inner[2].x" with byte offsets; fields whose name
//    starts with "_padding" are not columns but keep their bytes. A format that cannot be
//    resolved (unknown or circular type, more than 32 levels, empty, or larger than a D message
//    can hold) leaves its msg_id unsubscribed (counted); so does a subscription that would take
//    the columns of all topics past (input bytes + 65536), a bound no real log comes near.
//  * Trailing top-level padding fields need not be logged: a D body is accepted when its size
//    lies between the format's size without and with them; the bytes without it are stored.
//  * Appended data (incompat bit 0 and non-zero offsets): the data section is read in segments
//    [data start, offset0), [offset0, offset1), ..., [last offset, end of file). Offsets that
//    are not increasing or lie past the end of the file are ignored (counted).
//  * A message running past its segment's end is that segment's truncated record: dropped and
//    counted; reading goes on in the next segment. Fewer than 3 bytes at a segment's end count
//    the same way.
//  * A corrupt message header — size 0, a type byte that is not an ASCII letter, a D whose size
//    does not fit its subscription, an S without the sync magic or not 8 bytes, an O or R not
//    2 bytes, an A shorter than 4, an L shorter than 9, a C shorter than 11 — starts a resync:
//    bytes are skipped one by one (counted) until a complete D message of a subscribed msg_id
//    with a fitting size starts, or a complete S message with its magic, or a chain of 4
//    complete, non-corrupt messages of known types (B F I M P Q A R D L C S O; fewer when the
//    segment ends right after them) — the last rule recovers the definitions section, which
//    has no D or S to resynchronise on.
//  * A D whose msg_id was never subscribed is skipped by its size (counted); so is a message
//    of an unknown letter type (a future ULog message, counted). A known message whose body
//    does not parse (e.g. a key length past its end) is skipped (counted as malformed).
//
// Storage ("compact per-topic table", as the DataFlash reader): each kept subscription
// (RecordFilter) keeps the bodies of its D messages (RecordStore: row-major blocks, `body_size`
// bytes each, as in the file); columns are decoded on access from their byte offsets. No
// allocation per data message, no counting pass. A topic the filter asks to decode
// (RecordFilter::decode; a session reads sensor_combined so) keeps no bodies: its IMU samples
// are decoded as each message goes by, while it is in the cache (ULogTopic::imu).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/split_read.h"

namespace plumb::io {

/// The basic ULog field types.
enum class ULogType : std::uint8_t {
  kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kInt64, kUInt64, kFloat, kDouble, kBool, kChar
};

/// The value of a field of type `type` stored at `p` (little endian) as a double (bool 0/1,
/// char its code).
inline double DecodeULogValue(const std::uint8_t* p, ULogType type) {
  switch (type) {
    case ULogType::kInt8: return LoadLittleEndian<std::int8_t>(p);
    case ULogType::kUInt8: case ULogType::kChar: return LoadLittleEndian<std::uint8_t>(p);
    case ULogType::kBool: return LoadLittleEndian<std::uint8_t>(p) != 0 ? 1.0 : 0.0;
    case ULogType::kInt16: return LoadLittleEndian<std::int16_t>(p);
    case ULogType::kUInt16: return LoadLittleEndian<std::uint16_t>(p);
    case ULogType::kInt32: return LoadLittleEndian<std::int32_t>(p);
    case ULogType::kUInt32: return LoadLittleEndian<std::uint32_t>(p);
    case ULogType::kInt64: return static_cast<double>(LoadLittleEndian<std::int64_t>(p));
    case ULogType::kUInt64: return static_cast<double>(LoadLittleEndian<std::uint64_t>(p));
    case ULogType::kFloat: return LoadLittleEndian<float>(p);
    case ULogType::kDouble: return LoadLittleEndian<double>(p);
  }
  return 0.0;
}

/// One flattened field of a subscribed topic.
struct ULogColumn {
  std::string name;        ///< e.g. "timestamp", "gyro_rad[1]", "nested.x"
  ULogType type = ULogType::kUInt8;
  std::size_t offset = 0;  ///< byte offset inside the D body (after the msg_id), bytes
};

/// All D messages of one subscription (one msg_id: a topic and its multi_id instance).
struct ULogTopic {
  std::string name;              ///< topic (format) name, e.g. "sensor_combined"
  int multi_id = 0;              ///< instance of the topic, 0..255
  std::uint16_t msg_id = 0;      ///< id the log gave the subscription, 0..65535
  std::vector<ULogColumn> columns;  ///< every non-padding field, in body order
  std::size_t body_size = 0;     ///< bytes stored per message: format size without trailing padding
  std::size_t full_size = 0;     ///< format size with trailing padding, bytes (>= body_size)
  int timestamp_col = -1;        ///< column of the top-level "timestamp" field, -1 if none
  std::size_t rows = 0;          ///< D messages stored
  RecordStore bodies;            ///< the kept D bodies in log order, body_size bytes each
  /// False when the reader's RecordFilter left this topic's bodies out (rows still counted):
  /// Value, TimestampUs and Column then throw plumb::Error.
  bool bodies_kept = true;
  /// The "timestamp" of the last message, us (as TimestampUs), kept or not; 0 before any.
  std::uint64_t last_timestamp_us = 0;
  /// True when the reader decoded this topic's IMU samples in its pass instead of keeping its
  /// bodies (RecordFilter::decode; sensor_combined with a timestamp, accelerometer_m_s2[3]
  /// and gyro_rad[3] or gyro_rad_s[3]): bodies_kept is then false and `imu` holds them.
  bool imu_decoded = false;
  /// With imu_decoded: the samples, t_s = timestamp * 1e-6, acc and gyr saturated to float,
  /// those KeepIncreasingTimes leaves out left out once the whole log is read (as the PX4
  /// session reads sensor_combined from bodies).
  ImuSeries imu;
  /// With imu_decoded: what KeepIncreasingTimes left out of `imu`.
  LeftOutTimes imu_left_out;

  /// Bytes this topic holds of the log: its bodies, or with imu_decoded its messages counted
  /// at body size (the decoded samples take a little less).
  std::size_t KeptBytes() const { return imu_decoded ? rows * body_size : bodies.size(); }

  /// Index of the column called `column`, or -1.
  int ColumnIndex(std::string_view column) const;
  /// Value of message `row`, column `col` as a double (bool 0/1, char its code). Precondition:
  /// indices valid. Inline: sessions call it for every sample.
  double Value(std::size_t row, std::size_t col) const {
    if (!bodies_kept) ThrowNotKept();
    const ULogColumn& c = columns[col];
    return DecodeULogValue(bodies.Row(row) + c.offset, c.type);
  }
  /// The "timestamp" field of message `row`, microseconds (uint8 timestamps are milliseconds
  /// by the format and are scaled by 1000 here); 0 when the topic has none.
  std::uint64_t TimestampUs(std::size_t row) const;
  /// Every value of the column called `column` (see Value()). Throws plumb::Error if absent.
  std::vector<double> Column(std::string_view column) const;

 private:
  /// Throws the plumb::Error of a value asked of a topic whose bodies were not kept.
  [[noreturn]] void ThrowNotKept() const;
};

/// One field of an F message, as written.
struct ULogFormatField {
  std::string type;          ///< basic type name or a nested format's name
  std::size_t count = 1;     ///< array length, 1..65535 (1 for scalars)
  bool is_array = false;     ///< declared as type[n]
  std::string name;          ///< field name
};

/// A parameter change logged in the data section.
struct ULogParamChange {
  std::uint64_t timestamp_us = 0;  ///< newest timestamp among the topics' latest messages, us since boot
  std::string name;
  double value = 0.0;
};

/// A Q message: a default value of a parameter.
struct ULogDefaultParam {
  std::string name;
  double value = 0.0;
  std::uint8_t default_types = 0;  ///< bit 0: system default, bit 1: current airframe default
};

/// An L or C message.
struct ULogText {
  std::uint8_t level = 0;          ///< '0' (emergency) .. '7' (debug)
  int tag = -1;                    ///< C tag, 0..65535; -1 for L
  std::uint64_t timestamp_us = 0;  ///< us since boot
  std::string text;
};

/// What the reader skipped or repaired. Counts, never fatal.
struct ULogWarnings {
  std::size_t bytes_skipped = 0;        ///< bytes skipped while resynchronising
  std::size_t skip_runs = 0;            ///< separate runs of skipped bytes
  std::size_t first_skip_offset = 0;    ///< file offset of the first skipped byte
  std::size_t truncated_records = 0;    ///< messages cut by the end of a segment, dropped
  std::size_t truncated_bytes = 0;      ///< bytes of those messages
  std::size_t unknown_msg_id_messages = 0;  ///< D messages of a msg_id never subscribed
  std::size_t unknown_type_messages = 0;    ///< messages of an unknown letter type, skipped
  std::size_t malformed_messages = 0;       ///< known messages whose body does not parse
  std::size_t unresolved_subscriptions = 0; ///< A messages whose format cannot be resolved
  std::size_t bad_appended_offsets = 0;     ///< appended offsets ignored (see the contract)
  bool unknown_version = false;             ///< header version byte > 1 (read anyway)

  bool any() const;
  /// One readable line per non-zero count.
  std::vector<std::string> Describe() const;
};

/// A decoded ULog file.
struct ULog {
  std::string source;                 ///< file name (or the name given to ParseULog)
  std::size_t size_bytes = 0;         ///< input size, bytes
  int version = 0;                    ///< header version byte, 0..255
  std::uint64_t start_timestamp_us = 0;  ///< header timestamp, us since boot
  std::array<std::uint8_t, 8> compat_flags{};    ///< from B; zeros without it
  std::array<std::uint8_t, 8> incompat_flags{};  ///< from B; zeros without it
  bool data_appended = false;         ///< incompat bit 0 with at least one offset used
  std::vector<std::uint64_t> appended_offsets;   ///< file offsets used, increasing
  std::map<std::string, std::vector<ULogFormatField>> formats;  ///< F messages by name
  std::vector<ULogTopic> topics;      ///< every resolved subscription, in A order
  std::map<std::string, std::string> info;  ///< I messages: key -> value (numbers as decimal text)
  std::map<std::string, std::vector<std::string>> info_multiple;  ///< M messages, continued ones joined
  std::map<std::string, double> params;      ///< initial P values (int32 or float) by name
  std::vector<ULogParamChange> param_changes;  ///< P messages in the data section
  std::vector<ULogDefaultParam> default_params;  ///< Q messages
  std::vector<ULogText> texts;        ///< L and C messages
  std::size_t dropouts = 0;           ///< O messages
  std::uint64_t dropout_total_ms = 0; ///< sum of their durations, ms
  std::size_t sync_messages = 0;      ///< S messages
  ULogWarnings warnings;

  /// The subscription of `name` with `multi_id` holding the most rows, or nullptr.
  const ULogTopic* Find(std::string_view name, int multi_id = 0) const;
  /// ("name/multi_id", D message count) of every subscription with data, in A order.
  std::vector<std::pair<std::string, std::size_t>> MessageCounts() const;
};

/// How ReadULog reads a file: in one part, or in parts at once, two by default (SplitReadOptions).
/// A ULog's later part starts at a message boundary (16 messages it decodes in a row) and knows the
/// formats, subscriptions and column budget of the lead. It decodes D messages of subscribed
/// topics; S, O, L, C and R messages; parameter changes (their timestamps completed from the first
/// part's topics in the join), default parameters, info and continued info; and subscriptions whose
/// id is free and whose format it resolves. It stops, leaving the rest to the first part, at a
/// format, a subscription it cannot take, a message that does not parse, a D of an id not
/// subscribed, an unknown type, a corrupt header or a message cut by the end. What it read joins
/// after the first part's (a decoded topic's samples under its rule, ULogTopic::imu); its
/// subscriptions only when the first part subscribed none and defined no format after the lead. A
/// log with appended data is read in one part.
using ULogReadOptions = SplitReadOptions;

/// Reads and decodes a .ulg file. Throws plumb::InputError(path, "byte N", what) when the file
/// cannot be read, is shorter than the 16-byte header, lacks the magic, or sets an
/// incompatible flag bit this reader does not know.
/// `filter`: the topics whose message bodies are kept (RecordFilter; default all).
/// `options`: in one part or two at once (ULogReadOptions; default one). The same log either way.
ULog ReadULog(const std::string& path, const RecordFilter& filter = {},
              const ULogReadOptions& options = {});

/// Decodes a log held in memory; `source` names it in errors. Same contract as ReadULog.
ULog ParseULog(const std::uint8_t* data, std::size_t size, const std::string& source,
               const RecordFilter& filter = {}, const ULogReadOptions& options = {});

}  // namespace plumb::io

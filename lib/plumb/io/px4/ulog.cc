// plumb/io/px4/ulog.cc — see ulog.h for the format and the decoding contract.
#include "plumb/io/px4/ulog.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/split_read.h"
#include "plumb/io/px4/ulog_format.h"

namespace plumb::io {
namespace {

using detail::kULogMagic;
using detail::ULogBasicType;

constexpr std::uint8_t kSyncMagic[8] = {0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12};
constexpr std::size_t kFileHeaderSize = 16;
constexpr std::size_t kMsgHeaderSize = 3;
constexpr std::size_t kFlagBitsSize = 40;        // 8 + 8 + 3 * 8
constexpr int kResyncChain = 4;  // consecutive valid headers that end a resync without D or S
constexpr std::size_t kMinColumnBudget = 65536;  // columns allowed beyond one per input byte

bool IsLetter(std::uint8_t c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }

/// The message types of ULog version 1.
bool IsKnownType(std::uint8_t c) {
  return std::memchr("BFIMPQARDLCSO", c, 13) != nullptr && c != 0;
}

/// Key and value of an I/P/Q/M body after its leading bytes: uint8 key_len, key, value.
struct KeyValue {
  std::string type;   ///< e.g. "int32_t", "char[5]"
  std::string name;
  const std::uint8_t* value = nullptr;
  std::size_t value_size = 0;
};

std::optional<KeyValue> ParseKeyValue(const std::uint8_t* p, std::size_t n) {
  if (n < 1) return std::nullopt;
  const std::size_t key_len = p[0];
  if (key_len == 0 || 1 + key_len > n) return std::nullopt;
  const std::string key(reinterpret_cast<const char*>(p + 1), key_len);
  const std::size_t space = key.find(' ');
  if (space == std::string::npos || space == 0 || space + 1 >= key.size()) return std::nullopt;
  KeyValue kv;
  kv.type = key.substr(0, space);
  kv.name = key.substr(space + 1);
  kv.value = p + 1 + key_len;
  kv.value_size = n - 1 - key_len;
  return kv;
}

/// A parameter value (int32_t or float, 4 bytes); nullopt otherwise.
std::optional<double> ParamValue(const KeyValue& kv) {
  if (kv.value_size != 4) return std::nullopt;
  if (kv.type == "int32_t") return LoadLittleEndian<std::int32_t>(kv.value);
  if (kv.type == "float") return LoadLittleEndian<float>(kv.value);
  return std::nullopt;
}

/// An info value as text: strings as they are, numbers in decimal, anything else in hex.
std::string InfoText(const KeyValue& kv) {
  if (kv.type.rfind("char[", 0) == 0) {
    return std::string(reinterpret_cast<const char*>(kv.value), kv.value_size);
  }
  if (const auto basic = ULogBasicType(kv.type); basic && basic->second == kv.value_size) {
    const std::uint8_t* p = kv.value;
    switch (basic->first) {
      case ULogType::kInt8: return std::to_string(LoadLittleEndian<std::int8_t>(p));
      case ULogType::kUInt8: case ULogType::kBool: case ULogType::kChar:
        return std::to_string(LoadLittleEndian<std::uint8_t>(p));
      case ULogType::kInt16: return std::to_string(LoadLittleEndian<std::int16_t>(p));
      case ULogType::kUInt16: return std::to_string(LoadLittleEndian<std::uint16_t>(p));
      case ULogType::kInt32: return std::to_string(LoadLittleEndian<std::int32_t>(p));
      case ULogType::kUInt32: return std::to_string(LoadLittleEndian<std::uint32_t>(p));
      case ULogType::kInt64: return std::to_string(LoadLittleEndian<std::int64_t>(p));
      case ULogType::kUInt64: return std::to_string(LoadLittleEndian<std::uint64_t>(p));
      case ULogType::kFloat: return std::to_string(LoadLittleEndian<float>(p));
      case ULogType::kDouble: return std::to_string(LoadLittleEndian<double>(p));
    }
  }
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  for (std::size_t k = 0; k < kv.value_size; ++k) {
    out += kHex[kv.value[k] >> 4];
    out += kHex[kv.value[k] & 15];
  }
  return out;
}

/// A "timestamp" field of type `type` stored at `p`, us (uint8 timestamps are milliseconds by
/// the format; other types: 0).
std::uint64_t TimestampAt(const std::uint8_t* p, ULogType type) {
  switch (type) {
    case ULogType::kUInt64: return LoadLittleEndian<std::uint64_t>(p);
    case ULogType::kUInt32: return LoadLittleEndian<std::uint32_t>(p);
    case ULogType::kUInt16: return LoadLittleEndian<std::uint16_t>(p);
    case ULogType::kUInt8: return std::uint64_t{LoadLittleEndian<std::uint8_t>(p)} * 1000u;
    default: return 0;
  }
}

/// The "timestamp" field of the message body `body` of `t`, us; 0 when the topic has none.
std::uint64_t TimestampOf(const ULogTopic& t, const std::uint8_t* body) {
  if (t.timestamp_col < 0) return 0;
  const ULogColumn& c = t.columns[static_cast<std::size_t>(t.timestamp_col)];
  return TimestampAt(body + c.offset, c.type);
}

/// A value asked of a topic whose bodies the reader's RecordFilter left out: a caller's bug.
[[noreturn]] void NotKept(const std::string& name) {
  throw Error("ULog topic " + name + ": its message bodies were not kept (RecordFilter)");
}

/// Decodes sensor_combined's IMU samples inside the reader's pass (RecordFilter::decode), as
/// the PX4 session reads them from bodies (px4_session.cc, FromCombined): t_s = timestamp *
/// 1e-6, accelerometer_m_s2[0..2] and gyro_rad[0..2] (or gyro_rad_s) saturated to float,
/// every message's sample in order (KeepIncreasingTimes leaves out bad times once the whole
/// log is read: a spike is told only by the message after it).
class CombinedDecoder {
 public:
  /// The decoder of `t`, or nullopt when `t` is not sensor_combined or lacks a column.
  static std::optional<CombinedDecoder> For(const ULogTopic& t) {
    if (t.name != "sensor_combined" || t.timestamp_col < 0) return std::nullopt;
    CombinedDecoder d;
    d.time_ = t.columns[static_cast<std::size_t>(t.timestamp_col)];
    if (!Triad(t, "accelerometer_m_s2", d.acc_) ||
        (!Triad(t, "gyro_rad", d.gyr_) && !Triad(t, "gyro_rad_s", d.gyr_))) {
      return std::nullopt;
    }
    const auto is_float = [](const ULogColumn* c) {
      return c[0].type == ULogType::kFloat && c[1].type == ULogType::kFloat &&
             c[2].type == ULogType::kFloat;
    };
    d.float_triads_ = is_float(d.acc_) && is_float(d.gyr_);
    return d;
  }

  /// Decodes the message body `body` (after the msg_id) into `s`.
  void Add(ImuSeries& s, const std::uint8_t* body) const {
    s.t_s.push_back(DecodeULogValue(body + time_.offset, time_.type) * 1e-6);
    s.acc.push_back(Triad3(body, acc_));
    s.gyr.push_back(Triad3(body, gyr_));
  }

  /// Reserves `rows` samples of `s`, backed by huge pages where large.
  static void Reserve(ImuSeries& s, std::size_t rows) {
    ReserveHugePages(s.t_s, rows);
    ReserveHugePages(s.acc, rows);
    ReserveHugePages(s.gyr, rows);
  }

 private:
  static bool Triad(const ULogTopic& t, const std::string& base, ULogColumn* out) {
    for (int i = 0; i < 3; ++i) {
      const int c = t.ColumnIndex(base + "[" + std::to_string(i) + "]");
      if (c < 0) return false;
      out[i] = t.columns[static_cast<std::size_t>(c)];
    }
    return true;
  }

  static Vec3f Read3(const std::uint8_t* body, const ULogColumn* c) {
    return SaturatedFloat(Vec3(DecodeULogValue(body + c[0].offset, c[0].type),
                               DecodeULogValue(body + c[1].offset, c[1].type),
                               DecodeULogValue(body + c[2].offset, c[2].type)));
  }

  /// Read3, or (float_triads_, the usual float[3] fields) the stored floats themselves: the
  /// same values without the decoding switch and the round trip through double.
  Vec3f Triad3(const std::uint8_t* body, const ULogColumn* c) const {
    if (!float_triads_) return Read3(body, c);
    return Vec3f(LoadLittleEndian<float>(body + c[0].offset),
                 LoadLittleEndian<float>(body + c[1].offset),
                 LoadLittleEndian<float>(body + c[2].offset));
  }

  ULogColumn time_, acc_[3], gyr_[3];
  bool float_triads_ = false;  ///< every accelerometer and gyroscope field is a float
};

/// The one-pass decoder state: fed the file's bytes in order, in one piece (ParseULog) or in
/// chunks (ReadULog, through ReadForward); the position, the segment and the resync state
/// carry over from one call to the next.
class Parser {
 public:
  /// Bytes a decision at a position may look at: a resync's chain of kResyncChain messages of
  /// at most 65535 bytes each, and the next header.
  static constexpr std::size_t kLookahead =
      kResyncChain * (kMsgHeaderSize + 65535) + kMsgHeaderSize;

  /// `size`: the input's size in bytes (corrected by the call with at_end); `filter`: the
  /// topics whose bodies are kept.
  Parser(std::size_t size, ULog* log, const RecordFilter& filter)
      : size_(size), end_(size), log_(log), filter_(filter),
        resolver_(log->formats, size + kMinColumnBudget) {}

  /// After the last Feed: the topics get their message counts and last timestamps.
  void Finish() {
    for (std::size_t k = 0; k < data_entries_.size(); ++k) {
      log_->topics[k].rows = data_entries_[k].rows;
      log_->topics[k].last_timestamp_us = data_entries_[k].last_timestamp_us;
    }
  }

  /// Decodes the messages starting in the bytes [offset, offset + n) of the input held at
  /// `data` and returns the offset to go on from: unless `at_end`, the first message not
  /// whole in the bytes (or, resynchronising, the first position less than kLookahead bytes
  /// before offset + n), or the start of the next appended segment (a jump forward). `at_end`:
  /// the bytes end the input. The first call starts at offset 0 (the file header).
  std::size_t Feed(const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
    data_ = data;
    base_ = offset;
    avail_ = offset + n;
    if (at_end && avail_ < size_) {  // a shorter input than announced: it ends here
      size_ = avail_;
      end_ = std::min(end_, size_);
    }
    if (pos_ == 0) {
      if (avail_ < kFileHeaderSize && !at_end) return offset;  // a part ending before it
      ReadFileHeader(at_end);
      pos_ = kFileHeaderSize;
    }
    Run(at_end);
    return std::max(pos_, offset);
  }

  /// Bytes past a position Feed must be given to decode no message starting at or after it
  /// (and every one ending by it): none, Feed decodes only whole messages (split_read.h).
  static constexpr std::size_t kUntilSlack = 0;

  /// A parser for the messages from a later byte of the same input on, to run beside this one
  /// (the read in parts, split_read.h): it knows the formats, subscriptions and column
  /// budget this one knows now, decodes into `out` (which gets their formats and topics,
  /// without messages), reserves samples for the messages of about `bytes` bytes, and is fed
  /// with FeedAhead.
  Parser Ahead(ULog* out, std::size_t bytes) const {
    Parser ahead(size_, out, filter_);
    ahead.ahead_ = true;
    ahead.reserve_bytes_ = bytes;
    ahead.pos_ = kNotStarted;
    ahead.index_ = index_;
    ahead.decoders_ = decoders_;
    ahead.data_entries_ = data_entries_;
    for (DataEntry& e : ahead.data_entries_) e.rows = 0, e.last_timestamp_us = 0;
    ahead.in_definitions_ = in_definitions_;
    ahead.maker_topics_ = log_->topics.size();
    ahead.maker_formats_seen_ = formats_seen_;
    out->formats = log_->formats;
    ahead.resolver_.set_budget_left(resolver_.budget_left());
    out->topics.reserve(log_->topics.size());
    for (const ULogTopic& t : log_->topics) out->topics.push_back(WithoutMessages(t));
    return ahead;
  }

  /// Feed for a parser made by Ahead: decodes the messages from `offset` (at the first call) on
  /// that it can decide as its maker would there: D messages of a subscribed topic with a
  /// fitting size; S, O, L, C and R messages; P (once past the definitions), Q, I and M
  /// messages that parse (an M continuing a key only when it has that key's first part); an A
  /// whose msg_id is free and whose format it resolves. It stops (stopped()) at the first whole
  /// message it cannot: an F or B, any other A, a message that does not parse, a D of an id not
  /// subscribed, an unknown type, a corrupt header. It never decodes a message cut by the
  /// input's end. Returns the offset it reached.
  std::size_t FeedAhead(const std::uint8_t* data, std::size_t n, std::size_t offset) {
    if (pos_ == kNotStarted) pos_ = offset;
    data_ = data;
    base_ = offset;
    avail_ = offset + n;
    Run(false);
    return std::max(pos_, offset);
  }
  /// True once FeedAhead stopped.
  bool stopped() const { return stopped_; }

  /// The first position in [0, n) of `data` from which `records` messages that a parser made
  /// by Ahead decodes (D messages of subscribed topics with fitting sizes, AheadOther) follow
  /// one another inside the n bytes; n when there is none, and always in a log with appended
  /// data (its segments are read by one parser). A guess at a message boundary in the middle
  /// of a log.
  std::size_t FindRecordChain(const std::uint8_t* data, std::size_t n, int records) const {
    if (log_->incompat_flags[0] != 0) return n;  // data appended (or its bit set): one part
    for (std::size_t i = 0; i < n; ++i) {
      std::size_t at = i;
      int k = 0;
      for (; k < records; ++k) {
        std::size_t size = 0;
        if (FittingData(data + at, n - at, &size) < 0) size = AheadOther(data + at, n - at);
        if (size == 0) break;
        at += kMsgHeaderSize + size;
      }
      if (k == records) return i;
    }
    return n;
  }

  /// Adds what `ahead` (made by this parser's Ahead, decoding into `ahead_log`) decoded to
  /// this parser's log, as if this parser had gone on through the same messages from where it
  /// is now (the byte `ahead` started at), and goes on from where `ahead` stopped: messages
  /// counted, bodies kept, texts, sync and dropout counts added; a decoded topic's samples
  /// joined under its rule (a sample is kept when its time is above the last kept one: of
  /// `ahead`'s kept samples, those above this part's last). False, with nothing changed, when
  /// this parser is resynchronising (not at a message boundary) or the log has data appended.
  /// The samples' copies are jobs run through `run_jobs`.
  bool Absorb(const Parser& ahead, ULog& ahead_log, const JobRunner& run_jobs) {
    // Resynchronising, not at a message boundary; data appended (flags read after the lead):
    // its segments' ends are not `ahead`'s.
    if (resync_ || log_->incompat_flags[0] != 0) return false;
    if (ahead_log.warnings.any()) return false;  // never: `ahead` stops before any warning
    // `ahead` knows the topics subscribed in the lead; this parser may know more since (their
    // D messages stopped `ahead`), with the same indices for those it knows. Topics `ahead`
    // subscribed take the next indices, the column budget and the formats as this parser's
    // were at the lead: they join only when this parser subscribed none and defined no format
    // since.
    const bool ahead_subscribed = ahead_log.topics.size() > ahead.maker_topics_;
    if (ahead_subscribed && (log_->topics.size() != ahead.maker_topics_ ||
                             formats_seen_ != ahead.maker_formats_seen_)) {
      return false;
    }
    AbsorbParamChanges(ahead, ahead_log);  // before the counts change: they read this part's
    for (std::size_t k = 0; k < ahead.maker_topics_; ++k) {
      const DataEntry& a = ahead.data_entries_[k];
      if (a.rows == 0) continue;
      DataEntry& e = data_entries_[k];
      ULogTopic& t = log_->topics[k];
      ULogTopic& more = ahead_log.topics[k];
      if (t.imu_decoded) {
        JoinSamples(t.imu, more.imu, run_jobs);
      } else if (t.bodies_kept) {
        t.bodies.Append(more.bodies);
      }
      e.rows += a.rows;
      e.last_timestamp_us = a.last_timestamp_us;
    }
    for (std::size_t k = ahead.maker_topics_; k < ahead_log.topics.size(); ++k) {
      Subscribe(std::move(ahead_log.topics[k]), ahead.decoders_[k], ahead.data_entries_[k]);
    }
    if (ahead_subscribed) resolver_.set_budget_left(ahead.resolver_.budget_left());
    AbsorbMessages(ahead_log);
    in_definitions_ = in_definitions_ && ahead.in_definitions_;
    pos_ = ahead.pos_;
    return true;
  }

  /// The messages from pos_ on, while the look-ahead is in the bytes held (or `at_end`).
  void Run(bool at_end) {
    while (true) {
      if (pos_ >= end_) {
        if (next_segment_ < log_->appended_offsets.size()) {
          pos_ = std::min(size_, static_cast<std::size_t>(log_->appended_offsets[next_segment_]));
          ++next_segment_;
          end_ = next_segment_ < log_->appended_offsets.size()
                     ? static_cast<std::size_t>(log_->appended_offsets[next_segment_])
                     : size_;
          end_ = std::min(end_, size_);
          resync_ = false;
          continue;
        }
        pos_ = std::max(pos_, size_);
        return;
      }
      if (!resync_ && DataMessage()) continue;
      if (!at_end && !Held(pos_)) return;
      if (ahead_) {
        if (!AheadMessage()) {
          stopped_ = true;
          return;
        }
        continue;
      }
      if (resync_) {
        if (!ResyncPoint(pos_, end_)) {
          Skip(pos_);
          ++pos_;
          continue;
        }
        resync_ = false;
      }
      if (end_ - pos_ < kMsgHeaderSize) {
        Truncated(end_ - pos_);
        pos_ = end_;
        continue;
      }
      const std::size_t size = LoadLittleEndian<std::uint16_t>(At(pos_));
      const std::uint8_t type = At(pos_)[2];
      if (Corrupt(pos_, end_, size, type)) {
        resync_ = true;
        continue;
      }
      if (size > end_ - pos_ - kMsgHeaderSize) {
        Truncated(end_ - pos_);
        pos_ = end_;
        continue;
      }
      const std::uint8_t* body = At(pos_) + kMsgHeaderSize;
      const std::size_t at = pos_;
      pos_ += kMsgHeaderSize + size;
      if (type == 'D') {
        Data(body, size);
      } else {
        Other(at, type, body, size, &end_);
      }
    }
  }

 private:
  /// True when the bytes held decide the message at `pos`: while resynchronising, kLookahead
  /// bytes (a chain of messages); else its header and body.
  bool Held(std::size_t pos) const {
    if (resync_) return pos + kLookahead <= avail_;
    return pos + kMsgHeaderSize <= avail_ &&
           pos + kMsgHeaderSize + LoadLittleEndian<std::uint16_t>(At(pos)) <= avail_;
  }

  /// The byte of the input at file offset `pos` (in the bytes held).
  const std::uint8_t* At(std::size_t pos) const { return data_ + (pos - base_); }

  /// pos_ of a parser made by Ahead before its first FeedAhead.
  static constexpr std::size_t kNotStarted = static_cast<std::size_t>(-1);

  /// `t` without its messages: its definition, and empty bodies or samples (field by field:
  /// a copy would copy the blocks of its bodies).
  static ULogTopic WithoutMessages(const ULogTopic& t) {
    ULogTopic out;
    out.name = t.name;
    out.multi_id = t.multi_id;
    out.msg_id = t.msg_id;
    out.columns = t.columns;
    out.body_size = t.body_size;
    out.full_size = t.full_size;
    out.timestamp_col = t.timestamp_col;
    out.bodies = RecordStore(t.body_size);
    out.bodies_kept = t.bodies_kept;
    out.imu_decoded = t.imu_decoded;
    return out;
  }

  /// Appends the samples of `more` (decoded from the messages after those of `s`) to `s`:
  /// every message's, as one decoder keeps them.
  static void JoinSamples(ImuSeries& s, ImuSeries& more, const JobRunner& run_jobs) {
    if (s.empty()) {
      s = std::move(more);
      return;
    }
    AppendSamples(s, more, 0, run_jobs);
  }

  /// The parameter changes `ahead` logged, added after this part's with their timestamps as
  /// one parser would have them: the newest among every topic's last message, taken from this
  /// part for the topics `ahead` had no message of yet (PendingChange).
  void AbsorbParamChanges(const Parser& ahead, ULog& ahead_log) {
    for (const PendingChange& c : ahead.pending_changes_) {
      std::uint64_t& newest = ahead_log.param_changes[c.change].timestamp_us;
      for (const std::uint32_t k : c.topics_without_rows) {
        const DataEntry& e = data_entries_[k];
        if (e.rows > 0) newest = std::max(newest, e.last_timestamp_us);
      }
    }
    log_->param_changes.insert(log_->param_changes.end(), ahead_log.param_changes.begin(),
                               ahead_log.param_changes.end());
  }

  /// The messages other than D of `ahead_log` (made by a parser made by Ahead) added after this
  /// part's: texts, default parameters, info (a later value replaces an earlier one; lists
  /// continue), sync and dropout counts.
  void AbsorbMessages(ULog& ahead_log) {
    log_->texts.insert(log_->texts.end(), std::make_move_iterator(ahead_log.texts.begin()),
                       std::make_move_iterator(ahead_log.texts.end()));
    log_->default_params.insert(log_->default_params.end(), ahead_log.default_params.begin(),
                                ahead_log.default_params.end());
    for (auto& [key, value] : ahead_log.info) log_->info[key] = std::move(value);
    for (auto& [key, list] : ahead_log.info_multiple) {
      std::vector<std::string>& to = log_->info_multiple[key];
      to.insert(to.end(), std::make_move_iterator(list.begin()),
                std::make_move_iterator(list.end()));
    }
    log_->sync_messages += ahead_log.sync_messages;
    log_->dropouts += ahead_log.dropouts;
    log_->dropout_total_ms += ahead_log.dropout_total_ms;
  }

  /// For a parser made by Ahead, at a whole message that DataMessage did not take: true when it
  /// is one this parser decides as its maker would here (AheadOther, AheadDefinition), and
  /// read; false (a stop, nothing changed) otherwise.
  bool AheadMessage() {
    const std::uint8_t* p = At(pos_);
    const std::size_t at = pos_;
    if (const std::size_t size = AheadOther(p, end_ - pos_); size > 0) {
      pos_ += kMsgHeaderSize + size;
      Other(at, p[2], p + kMsgHeaderSize, size, &end_);
      return true;
    }
    if (end_ - pos_ < kMsgHeaderSize) return false;
    const std::size_t size = LoadLittleEndian<std::uint16_t>(p);
    if (size > end_ - pos_ - kMsgHeaderSize || Corrupt(pos_, end_, size, p[2]) ||
        !AheadDefinition(p[2], p + kMsgHeaderSize, size)) {
      return false;
    }
    pos_ += kMsgHeaderSize + size;
    return true;
  }

  /// For a parser made by Ahead: reads a P, Q, I, M or A message (body `body`, `size` bytes,
  /// sizes checked by Corrupt) and returns true when it decides it as its maker would here: a
  /// P once past the definitions (a change, PendingChange), a P, Q, I or M that parses, an M
  /// continuing a key only when this parser has that key's first part, an A whose msg_id is
  /// free and whose format it resolves (AddLoggedAhead). False (nothing read) otherwise.
  bool AheadDefinition(std::uint8_t type, const std::uint8_t* body, std::size_t size) {
    const auto parses = [](const std::uint8_t* b, std::size_t n, bool param) {
      const auto kv = ParseKeyValue(b, n);
      return kv && (!param || ParamValue(*kv));
    };
    switch (type) {
      case 'P':
        if (in_definitions_ || !parses(body, size, true)) return false;
        Param(body, size);
        pending_changes_.push_back(PendingChange::Of(log_->param_changes.size() - 1,
                                                     data_entries_, maker_topics_));
        return true;
      case 'Q':
        if (size < 1 || !parses(body + 1, size - 1, true)) return false;
        DefaultParam(body, size);
        return true;
      case 'I':
        if (!parses(body, size, false)) return false;
        Info(body, size);
        return true;
      case 'M': {
        const auto kv = size >= 1 ? ParseKeyValue(body + 1, size - 1) : std::nullopt;
        if (!kv || (body[0] != 0 && log_->info_multiple.count(kv->name) == 0)) return false;
        InfoMultiple(body, size);
        return true;
      }
      case 'A': return AddLoggedAhead(body, size);
      default: return false;
    }
  }

  /// The size of the message at `p` (n bytes held) when it is whole in them and one besides D
  /// that a parser made by Ahead decides as its maker would (its effect does not depend on
  /// what came before): an S with the sync magic, an O or R of 2 bytes, an L of 9 bytes or
  /// more, a C of 11 or more; 0 otherwise.
  static std::size_t AheadOther(const std::uint8_t* p, std::size_t n) {
    if (n < kMsgHeaderSize || std::memchr("SORLC", p[2], 5) == nullptr) return 0;
    const std::size_t size = LoadLittleEndian<std::uint16_t>(p);
    if (size > n - kMsgHeaderSize || FixedRuleBroken(p[2], size, p + kMsgHeaderSize)) return 0;
    return size;
  }

  /// True when a message of type S, O, R, L or C of `size` bytes breaks its type's rule (an S
  /// of 8 bytes with the sync magic, checked when its body `body` is whole: else nullptr; an O
  /// or R of 2 bytes; an L of 9 bytes or more, a C of 11 or more). False for other types.
  static bool FixedRuleBroken(std::uint8_t type, std::size_t size, const std::uint8_t* body) {
    switch (type) {
      case 'S':
        return size != sizeof(kSyncMagic) ||
               (body != nullptr && std::memcmp(body, kSyncMagic, sizeof(kSyncMagic)) != 0);
      case 'O': case 'R': return size != 2;
      case 'L': return size < 9;
      case 'C': return size < 11;
      default: return false;
    }
  }

  /// The topic index of the D message at `p` (n bytes held) when it is whole in them, of a
  /// subscribed topic and of a fitting size (`size` its size); -1 otherwise.
  [[gnu::always_inline]] int FittingData(const std::uint8_t* p, std::size_t n,
                                         std::size_t* size) const {
    if (n < kMsgHeaderSize + 2 || p[2] != 'D') return -1;
    *size = LoadLittleEndian<std::uint16_t>(p);
    if (*size < 2 || *size > n - kMsgHeaderSize) return -1;
    const int idx = Index(LoadLittleEndian<std::uint16_t>(p + kMsgHeaderSize));
    if (idx < 0) return -1;
    const DataEntry& e = data_entries_[static_cast<std::size_t>(idx)];
    return *size - 2 < e.body_size || *size - 2 > e.full_size ? -1 : idx;
  }

  /// The 16-byte file header: magic, version, start time.
  void ReadFileHeader(bool at_end) {
    if (avail_ < kFileHeaderSize) {
      (void)at_end;  // a first chunk holds the header unless the input is shorter
      throw InputError(log_->source, "byte 0",
                       "expected a 16-byte ULog header, the input has " + std::to_string(avail_) +
                           " bytes");
    }
    if (std::memcmp(data_, kULogMagic, sizeof(kULogMagic)) != 0) {
      throw InputError(log_->source, "byte 0",
                       "expected the ULog magic 'ULog' 01 12 35: not a PX4 ULog file");
    }
    log_->version = data_[7];
    log_->warnings.unknown_version = log_->version > 1;
    log_->start_timestamp_us = LoadLittleEndian<std::uint64_t>(data_ + 8);
  }

  bool Corrupt(std::size_t pos, std::size_t end, std::size_t size, std::uint8_t type) const {
    if (size == 0 || !IsLetter(type)) return true;
    const bool body_fits = size <= end - pos - kMsgHeaderSize;
    switch (type) {
      case 'D': {
        if (size < 2) return true;
        if (end - pos < kMsgHeaderSize + 2) return false;  // truncated: the caller decides
        const int idx = Index(LoadLittleEndian<std::uint16_t>(At(pos) + kMsgHeaderSize));
        if (idx < 0) return false;
        const DataEntry& e = data_entries_[static_cast<std::size_t>(idx)];
        return size - 2 < e.body_size || size - 2 > e.full_size;
      }
      case 'A': return size < 4;
      default: return FixedRuleBroken(type, size, body_fits ? At(pos) + kMsgHeaderSize : nullptr);
    }
  }

  /// True when reading may resume at `pos`: a complete D message of a subscribed msg_id with a
  /// fitting size, a complete S message with its magic, or a chain of kResyncChain complete,
  /// non-corrupt messages of known types (fewer when the segment ends right after them).
  bool ResyncPoint(std::size_t pos, std::size_t end) const {
    if (end - pos < kMsgHeaderSize) return false;
    const std::size_t size = LoadLittleEndian<std::uint16_t>(At(pos));
    const std::uint8_t type = At(pos)[2];
    if (size > end - pos - kMsgHeaderSize) return false;
    const std::uint8_t* body = At(pos) + kMsgHeaderSize;
    if (type == 'D' && size >= 2 && Index(LoadLittleEndian<std::uint16_t>(body)) >= 0) {
      const auto topic = static_cast<std::size_t>(Index(LoadLittleEndian<std::uint16_t>(body)));
      const ULogTopic& t = log_->topics[topic];
      return size - 2 >= t.body_size && size - 2 <= t.full_size;
    }
    if (type == 'S') {
      return size == sizeof(kSyncMagic) && std::memcmp(body, kSyncMagic, size) == 0;
    }
    std::size_t at = pos;
    for (int k = 0; k < kResyncChain; ++k) {
      if (at == end) return true;
      if (end - at < kMsgHeaderSize) return false;
      const std::size_t n = LoadLittleEndian<std::uint16_t>(At(at));
      const std::uint8_t ty = At(at)[2];
      if (!IsKnownType(ty) || Corrupt(at, end, n, ty) || n > end - at - kMsgHeaderSize) {
        return false;
      }
      at += kMsgHeaderSize + n;
    }
    return true;
  }

  /// What the loop reads and counts of each topic for its D messages, by topic index: a
  /// small entry instead of the topic and its column list (Finish copies the counts over).
  struct DataEntry {
    /// What the loop does with a message besides counting it.
    enum class Action : std::uint8_t { kCount, kKeep, kDecode };
    std::size_t body_size = 0;  ///< ULogTopic::body_size
    std::size_t full_size = 0;  ///< ULogTopic::full_size
    bool has_timestamp = false;  ///< the topic has a top-level "timestamp" column
    ULogType timestamp_type = ULogType::kUInt64;  ///< its type
    Action action = Action::kCount;
    std::size_t timestamp_offset = 0;  ///< its offset in the body
    std::size_t rows = 0;              ///< messages so far (ULogTopic::rows)
    std::uint64_t last_timestamp_us = 0;  ///< the last one's (ULogTopic::last_timestamp_us)

    static DataEntry Of(const ULogTopic& t) {
      DataEntry e;
      e.body_size = t.body_size;
      e.full_size = t.full_size;
      if (t.timestamp_col >= 0) {
        const ULogColumn& c = t.columns[static_cast<std::size_t>(t.timestamp_col)];
        e.has_timestamp = true;
        e.timestamp_type = c.type;
        e.timestamp_offset = c.offset;
      }
      e.action = t.bodies_kept ? Action::kKeep : t.imu_decoded ? Action::kDecode : Action::kCount;
      return e;
    }
    /// TimestampOf(the topic, body).
    std::uint64_t Timestamp(const std::uint8_t* body) const {
      return has_timestamp ? TimestampAt(body + timestamp_offset, timestamp_type) : 0;
    }
  };

  /// The common case, taken before the general checks of Run: a D message of a subscribed
  /// topic with a fitting size, whole in the bytes held and in the segment (what Run would
  /// find it to be after Held, Corrupt and the size check). True when it was one, and read.
  bool DataMessage() {
    const std::size_t held = std::min(avail_, end_);
    if (pos_ >= held) return false;
    const std::uint8_t* p = At(pos_);
    std::size_t size = 0;
    const int idx = FittingData(p, held - pos_, &size);
    if (idx < 0) return false;
    pos_ += kMsgHeaderSize + size;
    Data(static_cast<std::size_t>(idx), p + kMsgHeaderSize + 2);
    return true;
  }

  void Data(const std::uint8_t* body, std::size_t size) {
    const std::uint16_t msg_id = LoadLittleEndian<std::uint16_t>(body);
    const int idx = Index(msg_id);
    if (idx < 0) {
      ++log_->warnings.unknown_msg_id_messages;
      return;
    }
    (void)size;  // checked by Corrupt(): body_size <= size - 2 <= full_size
    Data(static_cast<std::size_t>(idx), body + 2);
  }

  /// A D message of topic `idx` whose fields start at `fields`: counted and its timestamp
  /// noted in the topic's entry; kept or decoded when the filter says so.
  void Data(std::size_t idx, const std::uint8_t* fields) {
    DataEntry& e = data_entries_[idx];
    e.last_timestamp_us = e.Timestamp(fields);
    if (e.action != DataEntry::Action::kCount) Store(idx, e, fields);
    ++e.rows;
  }

  /// Keeps the fields of a D message of topic `idx` (entry `e`), or decodes its samples. Out of
  /// line, so that Data, which every message goes through, stays small enough to inline.
  [[gnu::noinline]] void Store(std::size_t idx, const DataEntry& e, const std::uint8_t* fields) {
    ULogTopic& t = log_->topics[idx];
    if (e.action == DataEntry::Action::kKeep) {
      t.bodies.Append(fields);
      return;
    }
    if (e.rows == 0 && t.body_size > 0) {  // at most one sample per remaining message
      const std::size_t rest = ahead_ ? reserve_bytes_ : size_ > pos_ ? size_ - pos_ : 0;
      CombinedDecoder::Reserve(t.imu, std::min(rest / (t.body_size + 5) + 1, kMaxReserve));
    }
    decoders_[idx].Add(t.imu, fields);
  }

  /// The newest timestamp among the last message of every topic, us (for parameter changes).
  std::uint64_t NewestTimestampUs() const {
    std::uint64_t newest = 0;
    for (const DataEntry& e : data_entries_) {
      if (e.rows > 0) newest = std::max(newest, e.last_timestamp_us);
    }
    return newest;
  }

  void Other(std::size_t at, std::uint8_t type, const std::uint8_t* body, std::size_t size,
             std::size_t* end) {
    switch (type) {
      case 'B': FlagBits(at, body, size, end); break;
      case 'F': Format(body, size); break;
      case 'I': Info(body, size); break;
      case 'M': InfoMultiple(body, size); break;
      case 'P': Param(body, size); break;
      case 'Q': DefaultParam(body, size); break;
      case 'A': AddLogged(body, size); break;
      case 'R': break;
      case 'L': Text(body, size, false); break;
      case 'C': Text(body, size, true); break;
      case 'S': ++log_->sync_messages; break;
      case 'O':
        ++log_->dropouts;
        log_->dropout_total_ms += LoadLittleEndian<std::uint16_t>(body);
        break;
      default: ++log_->warnings.unknown_type_messages; break;
    }
  }

  void Malformed() { ++log_->warnings.malformed_messages; }

  /// Decides whether `t` (topic index `index`) keeps its bodies or has its samples decoded.
  void Keep(ULogTopic* t, std::size_t index) {
    t->bodies_kept = filter_.Keeps(t->name);
    if (decoders_.size() <= index) decoders_.resize(index + 1);
    if (filter_.Decodes(t->name)) {
      if (const std::optional<CombinedDecoder> d = CombinedDecoder::For(*t)) {
        t->imu_decoded = true;
        t->bodies_kept = false;
        decoders_[index] = *d;
      }
    }
    if (t->bodies_kept) t->bodies = RecordStore(t->body_size);
  }

  /// Index into log_->topics of a msg_id, -1 when it is not subscribed.
  int Index(std::uint16_t msg_id) const {
    return msg_id < index_.size() ? index_[msg_id] : -1;
  }

  void FlagBits(std::size_t at, const std::uint8_t* body, std::size_t size, std::size_t* end) {
    if (at != kFileHeaderSize || size < kFlagBitsSize) return Malformed();
    std::memcpy(log_->compat_flags.data(), body, 8);
    std::memcpy(log_->incompat_flags.data(), body + 8, 8);
    bool unknown = (log_->incompat_flags[0] & ~1u) != 0;
    for (int k = 1; k < 8; ++k) unknown = unknown || log_->incompat_flags[k] != 0;
    if (unknown) {
      throw InputError(log_->source, "byte " + std::to_string(at + kMsgHeaderSize + 8),
                       "unknown incompatible ULog flag bits set: this log needs a newer reader");
    }
    if ((log_->incompat_flags[0] & 1u) == 0) return;
    std::size_t last = at + kMsgHeaderSize + size;
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t off = LoadLittleEndian<std::uint64_t>(body + 16 + 8 * k);
      if (off == 0) continue;
      if (off < last || off > size_) {
        ++log_->warnings.bad_appended_offsets;
        continue;
      }
      log_->appended_offsets.push_back(off);
      last = static_cast<std::size_t>(off);
    }
    if (!log_->appended_offsets.empty()) {
      log_->data_appended = true;
      *end = static_cast<std::size_t>(log_->appended_offsets.front());
    }
  }

  void Format(const std::uint8_t* body, std::size_t size) {
    ++formats_seen_;
    std::string name;
    std::vector<ULogFormatField> fields;
    if (!detail::ParseULogFormat(std::string_view(reinterpret_cast<const char*>(body), size), &name,
                     &fields)) {
      return Malformed();
    }
    if (log_->formats.count(name) != 0) resolver_.Invalidate();
    log_->formats[name] = std::move(fields);
  }

  void Info(const std::uint8_t* body, std::size_t size) {
    const auto kv = ParseKeyValue(body, size);
    if (!kv) return Malformed();
    log_->info[kv->name] = InfoText(*kv);
  }

  void InfoMultiple(const std::uint8_t* body, std::size_t size) {
    const auto kv = size >= 1 ? ParseKeyValue(body + 1, size - 1) : std::nullopt;
    if (!kv) return Malformed();
    auto& list = log_->info_multiple[kv->name];
    const std::string text = InfoText(*kv);
    if (body[0] != 0 && !list.empty()) {
      list.back() += text;
    } else {
      list.push_back(text);
    }
  }

  void Param(const std::uint8_t* body, std::size_t size) {
    const auto kv = ParseKeyValue(body, size);
    const auto value = kv ? ParamValue(*kv) : std::nullopt;
    if (!value) return Malformed();
    if (in_definitions_) {
      log_->params[kv->name] = *value;
    } else {
      log_->param_changes.push_back({NewestTimestampUs(), kv->name, *value});
    }
  }

  void DefaultParam(const std::uint8_t* body, std::size_t size) {
    const auto kv = size >= 1 ? ParseKeyValue(body + 1, size - 1) : std::nullopt;
    const auto value = kv ? ParamValue(*kv) : std::nullopt;
    if (!value) return Malformed();
    log_->default_params.push_back({kv->name, *value, body[0]});
  }

  /// The topic an A message subscribes (multi_id, msg_id, name; not resolved).
  static ULogTopic Subscription(const std::uint8_t* body, std::size_t size) {
    ULogTopic t;
    t.multi_id = body[0];
    t.msg_id = LoadLittleEndian<std::uint16_t>(body + 1);
    t.name.assign(reinterpret_cast<const char*>(body + 3), size - 3);
    return t;
  }

  void AddLogged(const std::uint8_t* body, std::size_t size) {
    in_definitions_ = false;
    ULogTopic t = Subscription(body, size);
    if (Index(t.msg_id) >= 0) return Malformed();  // an id must not be reused
    if (!resolver_.Resolve(&t)) {
      ++log_->warnings.unresolved_subscriptions;
      return;
    }
    Subscribe(std::move(t));
  }

  /// AddLogged for a parser made by Ahead: false, with nothing changed, where AddLogged would
  /// count a warning (the ahead parser stops there instead).
  bool AddLoggedAhead(const std::uint8_t* body, std::size_t size) {
    ULogTopic t = Subscription(body, size);
    if (Index(t.msg_id) >= 0 || !resolver_.Resolve(&t)) return false;  // no budget taken then
    in_definitions_ = false;
    Subscribe(std::move(t));
    return true;
  }

  /// Adds the resolved topic `t` as the next one: kept or decoded as the filter says.
  void Subscribe(ULogTopic t) {
    const std::size_t k = log_->topics.size();
    Keep(&t, k);
    const DataEntry entry = DataEntry::Of(t);
    const CombinedDecoder decoder = decoders_[k];
    Subscribe(std::move(t), decoder, entry);
  }

  /// Adds the topic `t` as the next one, with its decoder and entry (those of the parser that
  /// read its subscription and messages: the two-part read's join).
  void Subscribe(ULogTopic t, const CombinedDecoder& decoder, const DataEntry& entry) {
    const std::size_t k = log_->topics.size();
    if (decoders_.size() <= k) decoders_.resize(k + 1);
    decoders_[k] = decoder;
    data_entries_.push_back(entry);
    if (index_.size() <= t.msg_id) index_.resize(std::size_t{t.msg_id} + 1, -1);
    index_[t.msg_id] = static_cast<int>(k);
    log_->topics.push_back(std::move(t));
  }

  void Text(const std::uint8_t* body, std::size_t size, bool tagged) {
    in_definitions_ = false;
    ULogText t;
    t.level = body[0];
    std::size_t off = 1;
    if (tagged) {
      t.tag = LoadLittleEndian<std::uint16_t>(body + 1);
      off = 3;
    }
    t.timestamp_us = LoadLittleEndian<std::uint64_t>(body + off);
    off += 8;
    t.text.assign(reinterpret_cast<const char*>(body + off), size - off);
    log_->texts.push_back(std::move(t));
  }

  void Skip(std::size_t pos) { CountSkipped(log_->warnings, pos, pos + 1, skip_end_); }

  void Truncated(std::size_t bytes) {
    ++log_->warnings.truncated_records;
    log_->warnings.truncated_bytes += bytes;
  }

  /// Reserved samples of a decoded topic at most (beyond, they grow by doubling).
  static constexpr std::size_t kMaxReserve = std::size_t{1} << 24;

  std::vector<CombinedDecoder> decoders_;  ///< by topic index, for the topics decoded
  const std::uint8_t* data_ = nullptr;  ///< the bytes held: file offsets [base_, avail_)
  std::size_t base_ = 0;
  std::size_t avail_ = 0;
  std::size_t size_;           ///< input size, bytes
  std::size_t pos_ = 0;        ///< next message's offset (0: the file header is next)
  std::size_t end_;            ///< end of the current segment
  std::size_t next_segment_ = 0;  ///< index into log_->appended_offsets
  bool resync_ = false;        ///< skipping bytes after a corrupt header
  ULog* log_;
  const RecordFilter& filter_;
  std::vector<int> index_;  // msg_id -> topics index, -1 when not subscribed; grows with A
  std::vector<DataEntry> data_entries_;
  detail::ULogFormatResolver resolver_;
  bool in_definitions_ = true;
  std::size_t skip_end_ = 0;  ///< end of the last skipped range (CountSkipped)
  bool ahead_ = false;        ///< made by Ahead: Run stops where AheadMessage says
  std::size_t reserve_bytes_ = 0;  ///< made by Ahead: the bytes of its part, about
  bool stopped_ = false;      ///< FeedAhead stopped
  std::size_t formats_seen_ = 0;  ///< F messages read (well formed or not)
  /// Made by Ahead: its maker's topic count and formats_seen_ then.
  std::size_t maker_topics_ = 0;
  std::size_t maker_formats_seen_ = 0;

  /// A parameter change read by a parser made by Ahead, whose timestamp (the newest among
  /// every topic's last message) is completed by the join: the topics it had no message of
  /// then, whose last message is the first part's.
  struct PendingChange {
    std::size_t change = 0;  ///< index into its log's param_changes
    std::vector<std::uint32_t> topics_without_rows;  ///< of its maker's topics

    static PendingChange Of(std::size_t change, const std::vector<DataEntry>& entries,
                            std::size_t maker_topics) {
      PendingChange c;
      c.change = change;
      for (std::size_t k = 0; k < maker_topics; ++k) {
        if (entries[k].rows == 0) c.topics_without_rows.push_back(static_cast<std::uint32_t>(k));
      }
      return c;
    }
  };
  std::vector<PendingChange> pending_changes_;  ///< made by Ahead: its parameter changes
};

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
  std::optional<Parser> parser;  // made at the first call when the size is not known before
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
  return Decode(FileBytes(path, "ULog file", Parser::kLookahead), RegularFileSize(path), path,
                filter, options);
}

}  // namespace plumb::io

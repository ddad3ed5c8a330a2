// plumb/io/px4/ulog_parser.h — INTERNAL to plumb::io_px4: the ULog reader's one-pass decoder
// (ReadULog and ParseULog in ulog.cc are its users): its state, the common case both of its
// loops take inline (a D message of a subscribed topic with a fitting size), and its two roles,
// each in its own file: the reader of every message in one pass (ulog_parser.cc: the file
// header, the messages, the resynchronisation after a corrupt header), and the pieces of the
// read in parts (ulog_two_part.cc: a parser started further on in the same file, run beside the
// first, ULogParser::Ahead, and the join of what it decoded to what the first one did,
// ULogParser::Absorb, exactly as one parser going through both parts would have decoded them).
// Not part of the public interface.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "plumb/core/jobs.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/px4/ulog.h"
#include "plumb/io/px4/ulog_combined.h"
#include "plumb/io/px4/ulog_format.h"

namespace plumb::io::detail {

/// The one-pass decoder state: fed the file's bytes in order, in one piece (ParseULog) or in
/// chunks (ReadULog, through ReadForward); the position, the segment and the resync state
/// carry over from one call to the next.
class ULogParser {
 public:
  /// Consecutive valid headers that end a resync without D or S.
  static constexpr int kResyncChain = 4;
  /// Bytes a decision at a position may look at: a resync's chain of kResyncChain messages of
  /// at most 65535 bytes each, and the next header.
  static constexpr std::size_t kLookahead =
      kResyncChain * (kULogMsgHeaderSize + 65535) + kULogMsgHeaderSize;
  /// Bytes past a position Feed must be given to decode no message starting at or after it
  /// (and every one ending by it): none, Feed decodes only whole messages (split_read.h).
  static constexpr std::size_t kUntilSlack = 0;

  /// `size`: the input's size in bytes (corrected by the call with at_end); `filter`: the
  /// topics whose bodies are kept.
  ULogParser(std::size_t size, ULog* log, const RecordFilter& filter)
      : size_(size), end_(size), log_(log), filter_(filter),
        resolver_(log->formats, size + kMinColumnBudget) {}

  /// After the last Feed: the topics get their message counts and last timestamps.
  void Finish();

  /// Decodes the messages starting in the bytes [offset, offset + n) of the input held at
  /// `data` and returns the offset to go on from: unless `at_end`, the first message not
  /// whole in the bytes (or, resynchronising, the first position less than kLookahead bytes
  /// before offset + n), or the start of the next appended segment (a jump forward). `at_end`:
  /// the bytes end the input. The first call starts at offset 0 (the file header).
  std::size_t Feed(const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end);

  /// A parser for the messages from a later byte of the same input on, to run beside this one
  /// (the read in parts, split_read.h): it knows the formats, subscriptions and column
  /// budget this one knows now, decodes into `out` (which gets their formats and topics,
  /// without messages), reserves samples for the messages of about `bytes` bytes, and is fed
  /// with FeedAhead.
  ULogParser Ahead(ULog* out, std::size_t bytes) const;

  /// Feed for a parser made by Ahead: decodes the messages from `offset` (at the first call) on
  /// that it can decide as its maker would there: D messages of a subscribed topic with a
  /// fitting size; S, O, L, C and R messages; P (once past the definitions), Q, I and M
  /// messages that parse (an M continuing a key only when it has that key's first part); an A
  /// whose msg_id is free and whose format it resolves. It stops (stopped()) at the first whole
  /// message it cannot: an F or B, any other A, a message that does not parse, a D of an id not
  /// subscribed, an unknown type, a corrupt header. It never decodes a message cut by the
  /// input's end. Returns the offset it reached.
  std::size_t FeedAhead(const std::uint8_t* data, std::size_t n, std::size_t offset);
  /// True once FeedAhead stopped.
  bool stopped() const { return stopped_; }

  /// The first position in [0, n) of `data` from which `records` messages that a parser made
  /// by Ahead decodes (D messages of subscribed topics with fitting sizes, AheadOther) follow
  /// one another inside the n bytes; n when there is none, and always in a log with appended
  /// data (its segments are read by one parser). A guess at a message boundary in the middle
  /// of a log.
  std::size_t FindRecordChain(const std::uint8_t* data, std::size_t n, int records) const;

  /// Adds what `ahead` (made by this parser's Ahead, decoding into `ahead_log`) decoded to
  /// this parser's log, as if this parser had gone on through the same messages from where it
  /// is now (the byte `ahead` started at), and goes on from where `ahead` stopped: messages
  /// counted, bodies kept, texts, sync and dropout counts added; a decoded topic's samples
  /// joined under its rule (a sample is kept when its time is above the last kept one: of
  /// `ahead`'s kept samples, those above this part's last). False, with nothing changed, when
  /// this parser is resynchronising (not at a message boundary) or the log has data appended.
  /// The samples' copies are jobs run through `run_jobs`.
  bool Absorb(const ULogParser& ahead, ULog& ahead_log, const JobRunner& run_jobs);

 private:
  /// Columns allowed beyond one per input byte (the resolver's budget).
  static constexpr std::size_t kMinColumnBudget = 65536;
  /// pos_ of a parser made by Ahead before its first FeedAhead.
  static constexpr std::size_t kNotStarted = static_cast<std::size_t>(-1);
  /// Reserved samples of a decoded topic at most (beyond, they grow by doubling).
  static constexpr std::size_t kMaxReserve = std::size_t{1} << 24;

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

    static DataEntry Of(const ULogTopic& t);
    /// TimestampOf(the topic, body) (ulog.cc).
    std::uint64_t Timestamp(const std::uint8_t* body) const {
      return has_timestamp ? ULogTimestampAt(body + timestamp_offset, timestamp_type) : 0;
    }
  };

  /// A parameter change read by a parser made by Ahead, whose timestamp (the newest among
  /// every topic's last message) is completed by the join: the topics it had no message of
  /// then, whose last message is the first part's.
  struct PendingChange {
    std::size_t change = 0;  ///< index into its log's param_changes
    std::vector<std::uint32_t> topics_without_rows;  ///< of its maker's topics

    static PendingChange Of(std::size_t change, const std::vector<DataEntry>& entries,
                            std::size_t maker_topics);
  };

  // The common case of both loops (Run, RunAhead), inline.

  /// True when the bytes held decide the message at `pos`: while resynchronising, kLookahead
  /// bytes (a chain of messages); else its header and body.
  bool Held(std::size_t pos) const {
    if (resync_) return pos + kLookahead <= avail_;
    return pos + kULogMsgHeaderSize <= avail_ &&
           pos + kULogMsgHeaderSize + LoadLittleEndian<std::uint16_t>(At(pos)) <= avail_;
  }

  /// The byte of the input at file offset `pos` (in the bytes held).
  const std::uint8_t* At(std::size_t pos) const { return data_ + (pos - base_); }

  /// Index into log_->topics of a msg_id, -1 when it is not subscribed.
  int Index(std::uint16_t msg_id) const {
    return msg_id < index_.size() ? index_[msg_id] : -1;
  }

  /// The topic index of the D message at `p` (n bytes held) when it is whole in them, of a
  /// subscribed topic and of a fitting size (`size` its size, ULogDataSizeFits); -1 otherwise.
  [[gnu::always_inline]] int FittingData(const std::uint8_t* p, std::size_t n,
                                         std::size_t* size) const {
    if (n < kULogMsgHeaderSize + 2 || p[2] != 'D') return -1;
    *size = LoadLittleEndian<std::uint16_t>(p);
    if (*size < 2 || *size > n - kULogMsgHeaderSize) return -1;
    const int idx = Index(LoadLittleEndian<std::uint16_t>(p + kULogMsgHeaderSize));
    if (idx < 0) return -1;
    const DataEntry& e = data_entries_[static_cast<std::size_t>(idx)];
    return ULogDataSizeFits(*size, e.body_size, e.full_size) ? idx : -1;
  }

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
    pos_ += kULogMsgHeaderSize + size;
    Data(static_cast<std::size_t>(idx), p + kULogMsgHeaderSize + 2);
    return true;
  }

  /// A D message of topic `idx` whose fields start at `fields`: counted and its timestamp
  /// noted in the topic's entry; kept or decoded when the filter says so.
  void Data(std::size_t idx, const std::uint8_t* fields) {
    DataEntry& e = data_entries_[idx];
    e.last_timestamp_us = e.Timestamp(fields);
    if (e.action != DataEntry::Action::kCount) Store(idx, e, fields);
    ++e.rows;
  }

  // The reader of every message in one pass (ulog_parser.cc).

  /// The messages from pos_ on, while the look-ahead is in the bytes held (or `at_end`).
  void Run(bool at_end);
  /// The 16-byte file header: magic, version, start time. Called once the bytes held hold it,
  /// or hold the whole input (Feed waits for them otherwise).
  void ReadFileHeader();
  /// True when the header at `pos` (message size `size`, type `type`; the segment ending at
  /// `end`) is corrupt: see the contract in ulog.h.
  bool Corrupt(std::size_t pos, std::size_t end, std::size_t size, std::uint8_t type) const;
  /// True when reading may resume at `pos`: a complete D message of a subscribed msg_id with a
  /// fitting size, a complete S message with its magic, or a chain of kResyncChain complete,
  /// non-corrupt messages of known types (fewer when the segment ends right after them).
  bool ResyncPoint(std::size_t pos, std::size_t end) const;
  /// A D message that the general checks of Run let through, `body` its msg_id and fields:
  /// its topic's when the msg_id is subscribed (Corrupt then checked its size,
  /// ULogDataSizeFits), else counted (unknown_msg_id_messages).
  void Data(const std::uint8_t* body);
  /// Keeps the fields of a D message of topic `idx` (entry `e`), or decodes its samples. Out of
  /// line, so that Data, which every message goes through, stays small enough to inline.
  [[gnu::noinline]] void Store(std::size_t idx, const DataEntry& e, const std::uint8_t* fields);
  /// The newest timestamp among the last message of every topic, us (for parameter changes).
  std::uint64_t NewestTimestampUs() const;
  /// Reads a message other than D (type `type`, found at `at`; the segment ending at `*end`).
  void Other(std::size_t at, std::uint8_t type, const std::uint8_t* body, std::size_t size,
             std::size_t* end);
  void Malformed() { ++log_->warnings.malformed_messages; }
  /// Decides whether `t` (topic index `index`) keeps its bodies or has its samples decoded.
  void Keep(ULogTopic* t, std::size_t index);
  void FlagBits(std::size_t at, const std::uint8_t* body, std::size_t size, std::size_t* end);
  void Format(const std::uint8_t* body, std::size_t size);
  void Info(const std::uint8_t* body, std::size_t size);
  void InfoMultiple(const std::uint8_t* body, std::size_t size);
  void Param(const std::uint8_t* body, std::size_t size);
  void DefaultParam(const std::uint8_t* body, std::size_t size);
  /// The topic an A message subscribes (multi_id, msg_id, name; not resolved).
  static ULogTopic Subscription(const std::uint8_t* body, std::size_t size);
  void AddLogged(const std::uint8_t* body, std::size_t size);
  /// Adds the resolved topic `t` as the next one: kept or decoded as the filter says.
  void Subscribe(ULogTopic t);
  /// Adds the topic `t` as the next one, with its decoder and entry (those of the parser that
  /// read its subscription and messages: the two-part read's join).
  void Subscribe(ULogTopic t, const ULogCombinedDecoder& decoder, const DataEntry& entry);
  void Text(const std::uint8_t* body, std::size_t size, bool tagged);
  void Skip(std::size_t pos) { CountSkipped(log_->warnings, pos, pos + 1, skip_end_); }
  void Truncated(std::size_t bytes) {
    ++log_->warnings.truncated_records;
    log_->warnings.truncated_bytes += bytes;
  }

  // The read in parts (ulog_two_part.cc).

  /// Run for a parser made by Ahead: the messages from pos_ on while they are whole in the
  /// bytes held, until the first one AheadMessage does not take (stopped_).
  void RunAhead();
  /// For a parser made by Ahead, at a whole message that DataMessage did not take: true when it
  /// is one this parser decides as its maker would here (AheadOther, AheadDefinition), and
  /// read; false (a stop, nothing changed) otherwise.
  bool AheadMessage();
  /// For a parser made by Ahead: reads a P, Q, I, M or A message (body `body`, `size` bytes,
  /// sizes checked by Corrupt) and returns true when it decides it as its maker would here: a
  /// P once past the definitions (a change, PendingChange), a P, Q, I or M that parses, an M
  /// continuing a key only when this parser has that key's first part, an A whose msg_id is
  /// free and whose format it resolves (AddLoggedAhead). False (nothing read) otherwise.
  bool AheadDefinition(std::uint8_t type, const std::uint8_t* body, std::size_t size);
  /// AddLogged for a parser made by Ahead: false, with nothing changed, where AddLogged would
  /// count a warning (the ahead parser stops there instead).
  bool AddLoggedAhead(const std::uint8_t* body, std::size_t size);
  /// The parameter changes `ahead` logged, added after this part's with their timestamps as
  /// one parser would have them: the newest among every topic's last message, taken from this
  /// part for the topics `ahead` had no message of yet (PendingChange).
  void AbsorbParamChanges(const ULogParser& ahead, ULog& ahead_log);
  /// The messages other than D of `ahead_log` (made by a parser made by Ahead) added after this
  /// part's: texts, default parameters, info (a later value replaces an earlier one; lists
  /// continue), sync and dropout counts.
  void AbsorbMessages(ULog& ahead_log);

  std::vector<ULogCombinedDecoder> decoders_;  ///< by topic index, for the topics decoded
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
  ULogFormatResolver resolver_;
  bool in_definitions_ = true;
  std::size_t skip_end_ = 0;  ///< end of the last skipped range (CountSkipped)
  /// Made by Ahead: the bytes of its part, about (what a decoded topic's samples are reserved
  /// for); nullopt: the rest of the input from the topic's first message on.
  std::optional<std::size_t> part_bytes_;
  bool stopped_ = false;      ///< FeedAhead stopped
  std::size_t formats_seen_ = 0;  ///< F messages read (well formed or not)
  /// Made by Ahead: its maker's topic count and formats_seen_ then.
  std::size_t maker_topics_ = 0;
  std::size_t maker_formats_seen_ = 0;
  std::vector<PendingChange> pending_changes_;  ///< made by Ahead: its parameter changes
};

}  // namespace plumb::io::detail

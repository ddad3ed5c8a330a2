// plumb/io/px4/ulog_two_part.cc — the ULog parser's part in the read in parts (split_read.h): a
// parser made from the first one to start further on in the same file (ULogParser::Ahead), its
// loop, which decodes only what it can decide as the first one would there and stops at
// anything else, the guess of a message boundary to start it at (FindRecordChain), and the join
// of what it decoded to what the first one did (ULogParser::Absorb). See ulog_parser.h.
#include <algorithm>
#include <cstring>
#include <iterator>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "plumb/io/common/split_read.h"
#include "plumb/io/px4/ulog_parser.h"

namespace plumb::io::detail {
namespace {

/// `t` without its messages: its definition, and empty bodies or samples (field by field:
/// a copy would copy the blocks of its bodies).
ULogTopic WithoutMessages(const ULogTopic& t) {
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
void JoinSamples(ImuSeries& s, ImuSeries& more, const JobRunner& run_jobs) {
  if (s.empty()) {
    s = std::move(more);
    return;
  }
  AppendSamples(s, more, 0, run_jobs);
}

/// The size of the message at `p` (n bytes held) when it is whole in them and one besides D
/// that a parser made by Ahead decides as its maker would (its effect does not depend on
/// what came before): an S with the sync magic, an O or R of 2 bytes, an L of 9 bytes or
/// more, a C of 11 or more; 0 otherwise.
std::size_t AheadOther(const std::uint8_t* p, std::size_t n) {
  if (n < kULogMsgHeaderSize || std::memchr("SORLC", p[2], 5) == nullptr) return 0;
  const std::size_t size = LoadLittleEndian<std::uint16_t>(p);
  if (size > n - kULogMsgHeaderSize || ULogFixedRuleBroken(p[2], size, p + kULogMsgHeaderSize)) {
    return 0;
  }
  return size;
}

}  // namespace

ULogParser ULogParser::Ahead(ULog* out, std::size_t bytes) const {
  ULogParser ahead(size_, out, filter_);
  ahead.part_bytes_ = bytes;
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

std::size_t ULogParser::FeedAhead(const std::uint8_t* data, std::size_t n, std::size_t offset) {
  if (pos_ == kNotStarted) pos_ = offset;
  data_ = data;
  base_ = offset;
  avail_ = offset + n;
  RunAhead();
  return std::max(pos_, offset);
}

// Run's loop without what a parser made by Ahead never meets: it never resynchronises (it stops
// at a corrupt header), its bytes are never the input's end (at_end), and its log has no
// appended segments (it stops at the B message that would give them).
void ULogParser::RunAhead() {
  while (pos_ < end_) {
    if (DataMessage()) continue;
    if (!Held(pos_)) return;
    if (!AheadMessage()) {
      stopped_ = true;
      return;
    }
  }
  pos_ = std::max(pos_, size_);
}

std::size_t ULogParser::FindRecordChain(const std::uint8_t* data, std::size_t n,
                                        int records) const {
  if (log_->incompat_flags[0] != 0) return n;  // data appended (or its bit set): one part
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t at = i;
    int k = 0;
    for (; k < records; ++k) {
      std::size_t size = 0;
      if (FittingData(data + at, n - at, &size) < 0) size = AheadOther(data + at, n - at);
      if (size == 0) break;
      at += kULogMsgHeaderSize + size;
    }
    if (k == records) return i;
  }
  return n;
}

bool ULogParser::Absorb(const ULogParser& ahead, ULog& ahead_log, const JobRunner& run_jobs) {
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

void ULogParser::AbsorbParamChanges(const ULogParser& ahead, ULog& ahead_log) {
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

void ULogParser::AbsorbMessages(ULog& ahead_log) {
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

bool ULogParser::AheadMessage() {
  const std::uint8_t* p = At(pos_);
  const std::size_t at = pos_;
  if (const std::size_t size = AheadOther(p, end_ - pos_); size > 0) {
    pos_ += kULogMsgHeaderSize + size;
    Other(at, p[2], p + kULogMsgHeaderSize, size, &end_);
    return true;
  }
  if (end_ - pos_ < kULogMsgHeaderSize) return false;
  const std::size_t size = LoadLittleEndian<std::uint16_t>(p);
  if (size > end_ - pos_ - kULogMsgHeaderSize || Corrupt(pos_, end_, size, p[2]) ||
      !AheadDefinition(p[2], p + kULogMsgHeaderSize, size)) {
    return false;
  }
  pos_ += kULogMsgHeaderSize + size;
  return true;
}

bool ULogParser::AheadDefinition(std::uint8_t type, const std::uint8_t* body, std::size_t size) {
  const auto parses = [](const std::uint8_t* b, std::size_t n, bool param) {
    const auto kv = ParseULogKeyValue(b, n);
    return kv && (!param || ULogParamValue(*kv));
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
      const auto kv = size >= 1 ? ParseULogKeyValue(body + 1, size - 1) : std::nullopt;
      if (!kv || (body[0] != 0 && log_->info_multiple.count(kv->name) == 0)) return false;
      InfoMultiple(body, size);
      return true;
    }
    case 'A': return AddLoggedAhead(body, size);
    default: return false;
  }
}

bool ULogParser::AddLoggedAhead(const std::uint8_t* body, std::size_t size) {
  ULogTopic t = Subscription(body, size);
  if (Index(t.msg_id) >= 0 || !resolver_.Resolve(&t)) return false;  // no budget taken then
  in_definitions_ = false;
  Subscribe(std::move(t));
  return true;
}

ULogParser::PendingChange ULogParser::PendingChange::Of(std::size_t change,
                                                        const std::vector<DataEntry>& entries,
                                                        std::size_t maker_topics) {
  PendingChange c;
  c.change = change;
  for (std::size_t k = 0; k < maker_topics; ++k) {
    if (entries[k].rows == 0) c.topics_without_rows.push_back(static_cast<std::uint32_t>(k));
  }
  return c;
}

}  // namespace plumb::io::detail

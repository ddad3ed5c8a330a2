// plumb/io/px4/ulog_parser.cc — the ULog parser's reader of every message in one pass: the file
// header, the loop with its general checks (truncated messages, corrupt headers and the
// resynchronisation after them, appended segments), and each message type read into the log.
// See ulog_parser.h; the read in parts is in ulog_two_part.cc.
#include "plumb/io/px4/ulog_parser.h"

#include <algorithm>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plumb/core/error.h"

namespace plumb::io::detail {
namespace {

bool IsLetter(std::uint8_t c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }

}  // namespace

void ULogParser::Finish() {
  for (std::size_t k = 0; k < data_entries_.size(); ++k) {
    log_->topics[k].rows = data_entries_[k].rows;
    log_->topics[k].last_timestamp_us = data_entries_[k].last_timestamp_us;
  }
}

std::size_t ULogParser::Feed(const std::uint8_t* data, std::size_t n, std::size_t offset,
                             bool at_end) {
  data_ = data;
  base_ = offset;
  avail_ = offset + n;
  if (at_end && avail_ < size_) {  // a shorter input than announced: it ends here
    size_ = avail_;
    end_ = std::min(end_, size_);
  }
  if (pos_ == 0) {
    if (avail_ < kULogFileHeaderSize && !at_end) return offset;  // a part ending before it
    ReadFileHeader();
    pos_ = kULogFileHeaderSize;
  }
  Run(at_end);
  return std::max(pos_, offset);
}

void ULogParser::Run(bool at_end) {
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
    if (resync_) {
      if (!ResyncPoint(pos_, end_)) {
        Skip(pos_);
        ++pos_;
        continue;
      }
      resync_ = false;
    }
    if (end_ - pos_ < kULogMsgHeaderSize) {
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
    if (size > end_ - pos_ - kULogMsgHeaderSize) {
      Truncated(end_ - pos_);
      pos_ = end_;
      continue;
    }
    const std::uint8_t* body = At(pos_) + kULogMsgHeaderSize;
    const std::size_t at = pos_;
    pos_ += kULogMsgHeaderSize + size;
    if (type == 'D') {
      Data(body);
    } else {
      Other(at, type, body, size, &end_);
    }
  }
}

void ULogParser::ReadFileHeader() {
  if (avail_ < kULogFileHeaderSize) {  // the bytes held are the whole input
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

bool ULogParser::Corrupt(std::size_t pos, std::size_t end, std::size_t size,
                         std::uint8_t type) const {
  if (size == 0 || !IsLetter(type)) return true;
  const bool body_fits = size <= end - pos - kULogMsgHeaderSize;
  switch (type) {
    case 'D': {
      if (size < 2) return true;
      if (end - pos < kULogMsgHeaderSize + 2) return false;  // truncated: the caller decides
      const int idx = Index(LoadLittleEndian<std::uint16_t>(At(pos) + kULogMsgHeaderSize));
      if (idx < 0) return false;
      const DataEntry& e = data_entries_[static_cast<std::size_t>(idx)];
      return !ULogDataSizeFits(size, e.body_size, e.full_size);
    }
    case 'A': return size < 4;
    default:
      return ULogFixedRuleBroken(type, size,
                                 body_fits ? At(pos) + kULogMsgHeaderSize : nullptr);
  }
}

bool ULogParser::ResyncPoint(std::size_t pos, std::size_t end) const {
  if (end - pos < kULogMsgHeaderSize) return false;
  const std::size_t size = LoadLittleEndian<std::uint16_t>(At(pos));
  const std::uint8_t type = At(pos)[2];
  if (size > end - pos - kULogMsgHeaderSize) return false;
  const std::uint8_t* body = At(pos) + kULogMsgHeaderSize;
  if (type == 'D' && size >= 2 && Index(LoadLittleEndian<std::uint16_t>(body)) >= 0) {
    const auto topic = static_cast<std::size_t>(Index(LoadLittleEndian<std::uint16_t>(body)));
    const ULogTopic& t = log_->topics[topic];
    return ULogDataSizeFits(size, t.body_size, t.full_size);
  }
  if (type == 'S') {
    return size == sizeof(kULogSyncMagic) && std::memcmp(body, kULogSyncMagic, size) == 0;
  }
  std::size_t at = pos;
  for (int k = 0; k < kResyncChain; ++k) {
    if (at == end) return true;
    if (end - at < kULogMsgHeaderSize) return false;
    const std::size_t n = LoadLittleEndian<std::uint16_t>(At(at));
    const std::uint8_t ty = At(at)[2];
    if (!ULogIsKnownType(ty) || Corrupt(at, end, n, ty) || n > end - at - kULogMsgHeaderSize) {
      return false;
    }
    at += kULogMsgHeaderSize + n;
  }
  return true;
}

ULogParser::DataEntry ULogParser::DataEntry::Of(const ULogTopic& t) {
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

void ULogParser::Data(const std::uint8_t* body) {
  const std::uint16_t msg_id = LoadLittleEndian<std::uint16_t>(body);
  const int idx = Index(msg_id);
  if (idx < 0) {
    ++log_->warnings.unknown_msg_id_messages;
    return;
  }
  Data(static_cast<std::size_t>(idx), body + 2);
}

void ULogParser::Store(std::size_t idx, const DataEntry& e, const std::uint8_t* fields) {
  ULogTopic& t = log_->topics[idx];
  if (e.action == DataEntry::Action::kKeep) {
    t.bodies.Append(fields);
    return;
  }
  if (e.rows == 0 && t.body_size > 0) {  // at most one sample per remaining message
    const std::size_t rest = part_bytes_ ? *part_bytes_ : size_ > pos_ ? size_ - pos_ : 0;
    ULogCombinedDecoder::Reserve(t.imu, std::min(rest / (t.body_size + 5) + 1, kMaxReserve));
  }
  decoders_[idx].Add(t.imu, fields);
}

std::uint64_t ULogParser::NewestTimestampUs() const {
  std::uint64_t newest = 0;
  for (const DataEntry& e : data_entries_) {
    if (e.rows > 0) newest = std::max(newest, e.last_timestamp_us);
  }
  return newest;
}

void ULogParser::Other(std::size_t at, std::uint8_t type, const std::uint8_t* body,
                       std::size_t size, std::size_t* end) {
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

void ULogParser::Keep(ULogTopic* t, std::size_t index) {
  t->bodies_kept = filter_.Keeps(t->name);
  if (decoders_.size() <= index) decoders_.resize(index + 1);
  if (filter_.Decodes(t->name)) {
    if (const std::optional<ULogCombinedDecoder> d = ULogCombinedDecoder::For(*t)) {
      t->imu_decoded = true;
      t->bodies_kept = false;
      decoders_[index] = *d;
    }
  }
  if (t->bodies_kept) t->bodies = RecordStore(t->body_size);
}

void ULogParser::FlagBits(std::size_t at, const std::uint8_t* body, std::size_t size,
                          std::size_t* end) {
  if (at != kULogFileHeaderSize || size < kULogFlagBitsSize) return Malformed();
  std::memcpy(log_->compat_flags.data(), body, 8);
  std::memcpy(log_->incompat_flags.data(), body + 8, 8);
  bool unknown = (log_->incompat_flags[0] & ~1u) != 0;
  for (int k = 1; k < 8; ++k) unknown = unknown || log_->incompat_flags[k] != 0;
  if (unknown) {
    throw InputError(log_->source, "byte " + std::to_string(at + kULogMsgHeaderSize + 8),
                     "unknown incompatible ULog flag bits set: this log needs a newer reader");
  }
  if ((log_->incompat_flags[0] & 1u) == 0) return;
  std::size_t last = at + kULogMsgHeaderSize + size;
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

void ULogParser::Format(const std::uint8_t* body, std::size_t size) {
  ++formats_seen_;
  std::string name;
  std::vector<ULogFormatField> fields;
  if (!ParseULogFormat(std::string_view(reinterpret_cast<const char*>(body), size), &name,
                       &fields)) {
    return Malformed();
  }
  if (log_->formats.count(name) != 0) resolver_.Invalidate();
  log_->formats[name] = std::move(fields);
}

void ULogParser::Info(const std::uint8_t* body, std::size_t size) {
  const auto kv = ParseULogKeyValue(body, size);
  if (!kv) return Malformed();
  log_->info[kv->name] = ULogInfoText(*kv);
}

void ULogParser::InfoMultiple(const std::uint8_t* body, std::size_t size) {
  const auto kv = size >= 1 ? ParseULogKeyValue(body + 1, size - 1) : std::nullopt;
  if (!kv) return Malformed();
  auto& list = log_->info_multiple[kv->name];
  const std::string text = ULogInfoText(*kv);
  if (body[0] != 0 && !list.empty()) {
    list.back() += text;
  } else {
    list.push_back(text);
  }
}

void ULogParser::Param(const std::uint8_t* body, std::size_t size) {
  const auto kv = ParseULogKeyValue(body, size);
  const auto value = kv ? ULogParamValue(*kv) : std::nullopt;
  if (!value) return Malformed();
  if (in_definitions_) {
    log_->params[kv->name] = *value;
  } else {
    log_->param_changes.push_back({NewestTimestampUs(), kv->name, *value});
  }
}

void ULogParser::DefaultParam(const std::uint8_t* body, std::size_t size) {
  const auto kv = size >= 1 ? ParseULogKeyValue(body + 1, size - 1) : std::nullopt;
  const auto value = kv ? ULogParamValue(*kv) : std::nullopt;
  if (!value) return Malformed();
  log_->default_params.push_back({kv->name, *value, body[0]});
}

ULogTopic ULogParser::Subscription(const std::uint8_t* body, std::size_t size) {
  ULogTopic t;
  t.multi_id = body[0];
  t.msg_id = LoadLittleEndian<std::uint16_t>(body + 1);
  t.name.assign(reinterpret_cast<const char*>(body + 3), size - 3);
  return t;
}

void ULogParser::AddLogged(const std::uint8_t* body, std::size_t size) {
  in_definitions_ = false;
  ULogTopic t = Subscription(body, size);
  if (Index(t.msg_id) >= 0) return Malformed();  // an id must not be reused
  if (!resolver_.Resolve(&t)) {
    ++log_->warnings.unresolved_subscriptions;
    return;
  }
  Subscribe(std::move(t));
}

void ULogParser::Subscribe(ULogTopic t) {
  const std::size_t k = log_->topics.size();
  Keep(&t, k);
  const DataEntry entry = DataEntry::Of(t);
  const ULogCombinedDecoder decoder = decoders_[k];
  Subscribe(std::move(t), decoder, entry);
}

void ULogParser::Subscribe(ULogTopic t, const ULogCombinedDecoder& decoder,
                           const DataEntry& entry) {
  const std::size_t k = log_->topics.size();
  if (decoders_.size() <= k) decoders_.resize(k + 1);
  decoders_[k] = decoder;
  data_entries_.push_back(entry);
  if (index_.size() <= t.msg_id) index_.resize(std::size_t{t.msg_id} + 1, -1);
  index_[t.msg_id] = static_cast<int>(k);
  log_->topics.push_back(std::move(t));
}

void ULogParser::Text(const std::uint8_t* body, std::size_t size, bool tagged) {
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

}  // namespace plumb::io::detail

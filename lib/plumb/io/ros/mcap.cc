// plumb/io/ros/mcap.cc — see mcap.h for the format and the decoding contract: the one pass
// over an MCAP file's records and chunks, and the reader's entry points.
#include "plumb/io/ros/mcap.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <fstream>
#include <memory>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/core/jobs.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/stream_spool.h"
#include "plumb/io/ros/mcap_fields.h"
#include "plumb/io/ros/read_ahead.h"
#include "plumb/io/ros/ros_imu.h"
#include "plumb/io/ros/rosbag_format.h"

namespace plumb::io {
namespace {

using Fields = detail::McapFields;
using namespace detail::mcap_op;

constexpr std::uint8_t kMagic[] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::size_t kMagicSize = sizeof(kMagic);
constexpr std::size_t kPrefixSize = 5;  // 0x89 "MCAP", whatever the version
constexpr const char* kImuSchema = "sensor_msgs/msg/Imu";

const std::uint8_t* Bytes(std::string_view v) {
  return reinterpret_cast<const std::uint8_t*>(v.data());
}

class Parser {
 public:
  /// `min_chunks`: the chunks the file has at least when they are read ahead through
  /// `run_jobs` (RunAhead); an empty `run_jobs`: never.
  Parser(const std::uint8_t* data, std::size_t size, RosBag* bag, const LogFile* file,
         std::size_t min_chunks, const JobRunner& run_jobs)
      : data_(data),
        size_(size),
        bag_(bag),
        file_(file),
        min_chunks_(min_chunks),
        run_jobs_(run_jobs) {}

  void Run();

 private:
  struct Record {
    std::uint8_t op = 0;
    const std::uint8_t* body = nullptr;
    std::size_t len = 0;  ///< the content there is (all of it unless cut)
    std::size_t end = 0;  ///< offset past the record in its range
  };
  /// The record at `pos` of [base, base + n). False when it runs past n (`r->len` then holds
  /// what is there of it; `r->body` nullptr when not even its opcode and length are).
  static bool Frame(const std::uint8_t* base, std::size_t n, std::size_t pos, Record* r);
  /// A chunk made ready to parse: its fields read, its records decompressed (into the
  /// ChunkBuffers given) and their CRC-32 computed where it is checked. Made by Open, which
  /// touches nothing else, so that it may run on another thread ahead of the parse.
  struct OpenedChunk {
    bool fields_ok = false;  ///< every field is there (the records as far as a cut file goes)
    std::uint64_t size = 0;  ///< uncompressed, as stated
    std::uint32_t crc = 0;   ///< uncompressed_crc, 0: not given
    std::string compression;
    detail::ChunkBody body;
    std::uint32_t computed_crc = 0;  ///< of body; set when the check applies (Checked)
    std::exception_ptr error;        ///< thrown while opening: rethrown where the parse is
  };
  using Stretch = detail::Stretch<Record, OpenedChunk>;
  /// Whether the CRC-32 of an opened chunk is checked: a whole chunk that states one.
  static bool Checked(const OpenedChunk& c, bool cut) {
    return !cut && c.body.whole && c.crc != 0;
  }
  static void Open(const Record& r, bool cut, detail::ChunkBuffers* buffers, OpenedChunk* out);
  static void OpenCatching(const Record& r, bool cut, detail::ChunkBuffers* buffers,
                           OpenedChunk* out);
  /// The records from `pos` (the first after the Header) to the end, on this thread alone.
  void RunInOrder(std::size_t pos);
  /// The same, the chunks opened up to detail::kStretchesInFlight - 1 stretches ahead of the
  /// parse through run_jobs_ (detail::ReadAhead).
  void RunAhead(std::size_t pos);
  /// Whether the records from `pos` hold at least `n` chunks (looked for up to the n-th).
  bool ChunksAtLeast(std::size_t pos, std::size_t n) const;
  /// The top-level record `r` at `at`, whole; `opened`: its chunk opened ahead, or nullptr.
  void Whole(const Record& r, std::size_t at, const OpenedChunk* opened);
  /// The top-level record at `at`, cut by the file's end: said, and the reading ends.
  void CutAt(const Record& r, std::size_t at, const OpenedChunk* opened);
  void TopRecord(const Record& r, std::size_t at, const OpenedChunk* opened);
  void Chunk(const Record& r, std::size_t at, bool cut);
  /// The chunk `c` opened from the Chunk record at `at`: counted, checked, its records read.
  void UseChunk(const OpenedChunk& c, std::size_t at, bool cut);
  /// Throws InputError naming the chunk at `at` when its records' CRC-32 is not the one stated.
  void CheckCrc(const OpenedChunk& c, std::size_t at) const;
  /// The records of a chunk's data [p, p + n); `at`: the chunk's file offset. Returns the
  /// messages read; `past_end` says what ran past the data's end ("" when none).
  std::size_t ChunkRecords(const std::uint8_t* p, std::size_t n, std::size_t at,
                           std::string* past_end);
  void Schema(const Record& r, std::size_t at);
  void Channel(const Record& r, std::size_t at);
  /// A Message record: counted, and decoded (ImuMessage) when of an IMU channel. Inline: most
  /// records are messages, many of other topics.
  void Message(const Record& r, std::size_t at) {
    if (r.len < 22) {
      BadRecord(at);
      return;
    }
    const auto channel = LoadLittleEndian<std::uint16_t>(r.body);
    ++bag_->messages;
    if (channel >= slots_.size() || slots_[channel].conn == nullptr) {
      Orphan(at);
      return;
    }
    Slot& slot = slots_[channel];
    ++slot.messages;
    if (slot.topic >= 0) ImuMessage(static_cast<std::size_t>(slot.topic), r, at);
  }
  /// A Message record (whole: at least its 22 bytes of fields) of IMU topic `topic`.
  void ImuMessage(std::size_t topic, const Record& r, std::size_t at);
  void Orphan(std::size_t at) {
    RosBagWarnings& w = bag_->warnings;
    if (w.orphan_messages++ == 0) w.first_orphan = at;
  }
  /// Adds the messages counted in the slots to their connections.
  void CountMessages();
  /// A message of IMU topic `t` that AppendCdrImuFast does not take: decoded by DecodeCdrImu,
  /// false when it does not decode (counted as malformed, the first with where and why).
  bool Decode(RosImuTopic* t, const std::uint8_t* p, std::size_t n, std::size_t at,
              detail::RosImuMessage* m);
  /// Room in `t` for its next sample (detail::ReserveImuAhead); returns the samples it has room
  /// for.
  std::size_t Room(RosImuTopic* t) const;
  void BadRecord(std::size_t at) {
    if (bag_->warnings.bad_records++ == 0) bag_->warnings.first_bad_record = at;
  }
  void Damaged(std::size_t at, const std::string& why) {
    RosBagWarnings& w = bag_->warnings;
    if (w.damaged_chunks++ == 0) {
      w.first_damaged_chunk = at;
      w.first_damage = why;
    }
  }

  const std::uint8_t* data_;
  std::size_t size_;
  RosBag* bag_;
  const LogFile* file_;
  std::size_t min_chunks_;
  const JobRunner& run_jobs_;
  std::size_t released_ = 0;
  std::size_t read_to_ = 0;  ///< the file offset past the top-level record being read
  bool footer_ = false;
  bool cut_ = false;  ///< a record ran past the file's end: the reading ended there
  struct SchemaInfo {
    std::string name;
  };
  std::unordered_map<std::uint16_t, SchemaInfo> schemas_;
  /// A channel as a message finds it (by id: channel ids are 16-bit).
  struct Slot {
    RosConnection* conn = nullptr;  ///< nullptr: not defined (yet)
    int topic = -1;                 ///< index in imu_topics, -1: not decoded
    /// Its messages read, added to conn->messages at the end (CountMessages): a count here,
    /// beside the slot a message looks up anyway, rather than in the connection's map node.
    std::size_t messages = 0;
  };
  std::vector<Slot> slots_;
  /// By index in imu_topics: the samples its four vectors have room for (Room's).
  std::vector<std::size_t> room_;
  detail::ChunkBuffers chunk_;  ///< a decompressed chunk and the decompressors, reused
};

bool Parser::Frame(const std::uint8_t* base, std::size_t n, std::size_t pos, Record* r) {
  r->body = nullptr;
  r->len = 0;
  if (n - pos < 9) return false;
  r->op = base[pos];
  const std::uint64_t len = LoadLittleEndian<std::uint64_t>(base + pos + 1);
  r->body = base + pos + 9;
  r->len = static_cast<std::size_t>(std::min<std::uint64_t>(len, n - pos - 9));
  r->end = pos + 9 + r->len;
  return len <= n - pos - 9;
}

void Parser::Run() {
  std::size_t pos = kMagicSize;
  Record r;
  const bool first_whole = Frame(data_, size_, pos, &r);
  if (r.body == nullptr || r.op != kOpHeader) {
    throw InputError(bag_->source, "byte " + std::to_string(pos),
                     "expected the MCAP Header record (opcode 0x01) after the magic" +
                         std::string(r.body == nullptr ? "; the file ends there" : ""));
  }
  if (!first_whole) {
    throw InputError(bag_->source, "byte " + std::to_string(pos),
                     "the MCAP Header record runs past the end of the file");
  }
  if (run_jobs_ && ChunksAtLeast(pos, min_chunks_)) {
    RunAhead(pos);
  } else {
    RunInOrder(pos);
  }
  if (cut_) return;
  CountMessages();
  if (!footer_) {
    bag_->warnings.notes.push_back(
        "cut short: the file ends at byte " + std::to_string(size_) +
        " without its Footer record (at a record boundary); the " +
        std::to_string(bag_->messages) + " messages before were read");
  }
}

void Parser::RunInOrder(std::size_t pos) {
  Record r;
  while (pos < size_ && !footer_) {
    if (!Frame(data_, size_, pos, &r)) {
      CutAt(r, pos, nullptr);
      return;
    }
    Whole(r, pos, nullptr);
    pos = r.end;
  }
}

// The schedule is detail::ReadAhead's: stretches framed in order, opened on either job, parsed
// in order. The parse touches only what RunInOrder's would (the bag, the counts, the page
// release), in the same order; opening touches only its slot.
void Parser::RunAhead(std::size_t pos) {
  const auto frame = [this](std::size_t at, Record* r) { return Frame(data_, size_, at, r); };
  const auto is_chunk = [](const Record& r, bool) {
    return r.body != nullptr && r.op == kOpChunk;
  };
  const auto footer = [](const Record& r) { return r.op == kOpFooter; };  // nothing read past it
  const auto whole = [this](const Record& r, std::size_t at, const OpenedChunk* opened) {
    Whole(r, at, opened);
  };
  const auto cut_at = [this](const Record& r, std::size_t at, const OpenedChunk* opened) {
    CutAt(r, at, opened);
  };
  detail::ReadAhead<Stretch>(
      run_jobs_, [&](Stretch& s) { return s.Frame(&pos, size_, frame, is_chunk, footer); },
      [](Stretch& s) {
        if (s.has_chunk) OpenCatching(s.records.back().first, s.cut, &s.buffers, &s.chunk);
      },
      [&](const Stretch& s) { s.Parse(whole, cut_at); });
}

bool Parser::ChunksAtLeast(std::size_t pos, std::size_t n) const {
  std::size_t chunks = 0;
  Record r;
  while (chunks < n && pos < size_ && Frame(data_, size_, pos, &r) && r.op != kOpFooter) {
    if (r.op == kOpChunk) ++chunks;
    pos = r.end;
  }
  return chunks >= n;
}

void Parser::Whole(const Record& r, std::size_t at, const OpenedChunk* opened) {
  read_to_ = r.end;
  TopRecord(r, at, opened);
  if (file_ != nullptr && r.end >= released_ + LogFile::kReleaseStep) {
    file_->Release(released_, r.end);
    released_ = r.end;
  }
}

void Parser::CutAt(const Record& r, std::size_t at, const OpenedChunk* opened) {
  bag_->warnings.cut_at = at;
  read_to_ = size_;
  if (r.body != nullptr && r.op == kOpChunk) {
    if (opened != nullptr) {
      UseChunk(*opened, at, true);
    } else {
      Chunk(r, at, true);
    }
  }
  bag_->warnings.messages_read = bag_->messages;
  CountMessages();
  cut_ = true;
}

void Parser::TopRecord(const Record& r, std::size_t at, const OpenedChunk* opened) {
  switch (r.op) {
    case kOpFooter: footer_ = true; break;
    case kOpSchema: Schema(r, at); break;
    case kOpChannel: Channel(r, at); break;
    case kOpMessage: Message(r, at); break;
    case kOpChunk:
      if (opened != nullptr) {
        UseChunk(*opened, at, false);
      } else {
        Chunk(r, at, false);
      }
      break;
    case kOpChunkIndex: ++bag_->chunk_infos; break;
    default: break;  // the index, attachments, metadata, statistics; unknown opcodes
  }
}

void Parser::CheckCrc(const OpenedChunk& c, std::size_t at) const {
  if (c.computed_crc == c.crc) return;
  char what[160];
  std::snprintf(what, sizeof what,
                "the chunk's %zu bytes of records do not match its uncompressed_crc (stated "
                "%08x, computed %08x): the file is damaged there",
                c.body.size, static_cast<unsigned>(c.crc), static_cast<unsigned>(c.computed_crc));
  throw InputError(bag_->source, "byte " + std::to_string(at), what);
}

void Parser::Open(const Record& r, bool cut, detail::ChunkBuffers* buffers, OpenedChunk* out) {
  Fields f(r.body, r.len);
  f.Get<std::uint64_t>();  // message_start_time
  f.Get<std::uint64_t>();  // message_end_time
  out->size = f.Get<std::uint64_t>();
  out->crc = f.Get<std::uint32_t>();
  out->compression = std::string(f.String().substr(0, 32));
  const std::uint64_t records_len = f.Get<std::uint64_t>();
  const std::string_view records = f.Bytes(records_len, cut);
  out->fields_ok = f.ok();
  out->body = detail::ChunkBody{};
  out->computed_crc = 0;
  out->error = nullptr;
  if (!out->fields_ok || out->size > detail::kRosMaxChunkBytes) return;
  out->body = detail::OpenChunk(out->compression, Bytes(records), records.size(),
                                static_cast<std::uint32_t>(out->size), cut, buffers);
  if (Checked(*out, cut)) out->computed_crc = detail::Crc32(out->body.data, out->body.size);
}

// What opening throws (memory running out) is kept for the parse, which rethrows it where the
// one-thread reading would have met it: after every record before the chunk was read.
void Parser::OpenCatching(const Record& r, bool cut, detail::ChunkBuffers* buffers,
                          OpenedChunk* out) {
  try {
    Open(r, cut, buffers, out);
  } catch (...) {
    out->error = std::current_exception();
  }
}

void Parser::Chunk(const Record& r, std::size_t at, bool cut) {
  OpenedChunk c;
  Open(r, cut, &chunk_, &c);
  UseChunk(c, at, cut);
}

void Parser::UseChunk(const OpenedChunk& c, std::size_t at, bool cut) {
  if (!c.fields_ok) {
    if (!cut) BadRecord(at);
    return;
  }
  ++bag_->chunks;
  ++bag_->compression[c.compression.empty() ? "none" : c.compression];
  if (c.size > detail::kRosMaxChunkBytes) {
    Damaged(at, "chunk stating " + std::to_string(c.size) +
                    " bytes uncompressed, more than plumb reads (1 GiB)");
    return;
  }
  if (c.error) std::rethrow_exception(c.error);
  const detail::ChunkBody& body = c.body;
  if (Checked(c, cut)) CheckCrc(c, at);
  std::string past_end;
  const std::size_t kept = ChunkRecords(body.data, body.size, at, &past_end);
  if (cut) {
    bag_->warnings.cut_messages_kept = kept;
  } else if (!body.whole) {
    Damaged(at, body.why);
  } else if (!past_end.empty()) {
    Damaged(at, past_end);
  }
}

std::size_t Parser::ChunkRecords(const std::uint8_t* p, std::size_t n, std::size_t at,
                                 std::string* past_end) {
  std::size_t pos = 0;
  std::size_t messages = 0;
  Record r;
  while (pos < n) {
    if (!Frame(p, n, pos, &r)) {
      *past_end = "a record at offset " + std::to_string(pos) + " of the chunk's " +
                  std::to_string(n) + " bytes runs past its end";
      break;
    }
    switch (r.op) {
      case kOpSchema: Schema(r, at); break;
      case kOpChannel: Channel(r, at); break;
      case kOpMessage:
        Message(r, at);
        ++messages;
        break;
      default: break;
    }
    pos = r.end;
  }
  return messages;
}

void Parser::Schema(const Record& r, std::size_t at) {
  Fields f(r.body, r.len);
  const auto id = f.Get<std::uint16_t>();
  const std::string_view name = f.String();
  f.String();  // encoding
  f.Bytes(f.Get<std::uint32_t>());
  if (!f.ok()) {
    BadRecord(at);
    return;
  }
  if (id == 0) return;  // invalid by the spec: ignored
  schemas_.emplace(id, SchemaInfo{std::string(name.substr(0, 256))});
}

void Parser::Channel(const Record& r, std::size_t at) {
  Fields f(r.body, r.len);
  const auto id = f.Get<std::uint16_t>();
  const auto schema_id = f.Get<std::uint16_t>();
  const std::string_view topic = f.String();
  const std::string_view encoding = f.String();
  if (!f.ok()) {
    BadRecord(at);
    return;
  }
  if (bag_->connections.count(id) != 0) return;  // repeated in the summary
  RosConnection c;
  c.id = id;
  c.topic = std::string(topic.substr(0, 1024));
  const auto schema = schemas_.find(schema_id);
  c.type = schema == schemas_.end() ? std::string() : schema->second.name;
  int imu = -1;
  if (c.type == kImuSchema) {
    if (encoding == "cdr") {
      imu = detail::ImuTopicIndex(bag_, c.topic);
      room_.resize(bag_->imu_topics.size());  // a new topic's: 0, grown at its first sample
    } else {
      bag_->warnings.notes.push_back(
          "channel " + std::to_string(id) + " (" + c.topic + "): sensor_msgs/msg/Imu in '" +
          std::string(encoding.substr(0, 32)) + "', not CDR; its messages are not decoded");
    }
  }
  RosConnection& stored = bag_->connections.emplace(id, std::move(c)).first->second;
  if (id >= slots_.size()) slots_.resize(std::size_t{id} + 1);
  slots_[id] = Slot{&stored, imu};
}

void Parser::CountMessages() {
  for (Slot& slot : slots_) {
    if (slot.conn != nullptr) slot.conn->messages += slot.messages;
    slot.messages = 0;
  }
}

void Parser::ImuMessage(std::size_t topic, const Record& r, std::size_t at) {
  const auto log_time = LoadLittleEndian<std::uint64_t>(r.body + 6);
  RosImuTopic& t = bag_->imu_topics[topic];
  if (t.samples.t_s.size() >= room_[topic]) room_[topic] = Room(&t);
  std::int64_t sec = 0;
  std::uint32_t nsec = 0;
  detail::SplitNanoseconds(static_cast<std::int64_t>(log_time), &sec, &nsec);
  // The usual message appended straight from its bytes; any other decoded in general (out of
  // line: DecodeCdrImu, which says what is wrong with one that does not decode), then appended.
  const std::uint8_t* cdr = r.body + 22;
  if (detail::AppendCdrImuFast(&t, cdr, r.len - 22, sec, nsec)) return;
  detail::RosImuMessage m;
  if (Decode(&t, cdr, r.len - 22, at, &m)) detail::AppendImu(&t, m, sec, nsec);
}

bool Parser::Decode(RosImuTopic* t, const std::uint8_t* p, std::size_t n, std::size_t at,
                    detail::RosImuMessage* m) {
  std::string why;
  if (detail::DecodeCdrImu(p, n, m, &why)) return true;
  RosBagWarnings& w = bag_->warnings;
  ++t->malformed;
  if (w.malformed_imu++ == 0) {
    w.first_malformed_imu = at;
    w.first_malformed_why = "the message " + std::to_string(t->samples.size() + t->malformed - 1) +
                            " of " + t->topic + ", in the record at byte " + std::to_string(at) +
                            ", " + why;
  }
  return false;
}

std::size_t Parser::Room(RosImuTopic* t) const {
  return detail::ReserveImuAhead(t, read_to_, size_);
}

/// ParseMcap, releasing the pages of `file` (or nullptr) behind the parser.
RosBag ParseFrom(const std::uint8_t* data, std::size_t size, const std::string& source,
                 const LogFile* file, const JobRunner& run_jobs = {},
                 std::size_t min_chunks = detail::kMcapChunksReadAhead) {
  RosBag bag;
  bag.kind = RosBagKind::kMcap;
  bag.source = source;
  bag.size_bytes = size;
  if (size < kPrefixSize || !std::equal(data, data + kPrefixSize, kMagic)) {
    throw InputError(source, "byte 0", "not an MCAP file (no 0x89 \"MCAP\" magic)");
  }
  if (size < kMagicSize || !std::equal(data, data + kMagicSize, kMagic)) {
    throw InputError(source, "byte 5",
                     size < kMagicSize ? "MCAP magic cut short"
                                       : "MCAP of another version ('" +
                                             std::string(1, static_cast<char>(data[5])) +
                                             "'); plumb reads version 0");
  }
  Parser(data, size, &bag, file, min_chunks, run_jobs).Run();
  return bag;
}

}  // namespace

RosBag ParseMcap(const std::uint8_t* data, std::size_t size, const std::string& source) {
  return ParseFrom(data, size, source, nullptr);
}

RosBag detail::ParseMcapReadingAhead(const std::uint8_t* data, std::size_t size,
                                     const std::string& source, const JobRunner& run_jobs,
                                     std::size_t min_chunks) {
  return ParseFrom(data, size, source, nullptr, run_jobs, min_chunks);
}

RosBag ReadMcap(const std::string& path, const JobRunner& run_jobs) {
  const LogFile file(path, "MCAP file");
  try {
    RosBag bag = ParseFrom(file.data(), file.size(), path, &file, run_jobs);
    file.ThrowIfCut();
    return bag;
  } catch (const Error&) {
    file.ThrowIfCut();
    throw;
  }
}

bool LooksLikeMcap(const std::string& path) {
  std::ifstream in(OpenPath(path), std::ios::binary);
  char head[kPrefixSize] = {};
  in.read(head, sizeof(head));
  return in.gcount() == static_cast<std::streamsize>(sizeof(head)) &&
         std::equal(head, head + sizeof(head), reinterpret_cast<const char*>(kMagic));
}

}  // namespace plumb::io

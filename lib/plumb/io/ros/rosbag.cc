// plumb/io/ros/rosbag.cc — see rosbag.h for the format and the decoding contract: the one
// pass over the bag's records and chunks, and the reader's entry points.
#include "plumb/io/ros/rosbag.h"

#include <algorithm>
#include <exception>
#include <fstream>
#include <unordered_map>
#include <utility>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/stream_spool.h"
#include "plumb/io/ros/read_ahead.h"
#include "plumb/io/ros/ros_imu.h"
#include "plumb/io/ros/rosbag_format.h"

namespace plumb::io {
namespace {

using detail::RosRecordFields;

constexpr const char* kImuType = "sensor_msgs/Imu";

/// A message whose connection was not defined yet when it was read.
struct Pending {
  std::uint32_t conn = 0;
  std::uint32_t sec = 0;
  std::uint32_t nsec = 0;
  std::size_t offset = 0;  ///< where it was, for the warnings
  std::vector<std::uint8_t> bytes;
};

class Parser {
 public:
  /// `file`: the mapped file the bytes are, whose pages the parser releases behind it as it
  /// goes (LogFile::Release), or nullptr. `min_chunks`: the chunks the bag has at least when
  /// they are read ahead through `run_jobs` (RunAhead); an empty `run_jobs`: never.
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
  /// One record at `pos` of [base, base + n) (the file, or a chunk's records); `at` is the file
  /// offset the warnings name for it. Returns the offset past it, or nullopt when it runs past
  /// the end (`cut_record` then says what).
  struct Record {
    RosRecordFields fields;
    const std::uint8_t* header = nullptr;
    std::size_t header_len = 0;
    const std::uint8_t* data = nullptr;
    std::size_t data_len = 0;
    std::size_t end = 0;  ///< offset past the record in its range
    bool header_ok = true;
    std::string why;      ///< what did not parse in the header
  };
  /// Reads the framing of the record at `pos` of [base, base + n). False when its header or
  /// data run past n (`r->data_len` then holds what is there of the data, the header's fields
  /// parsed when the header is whole).
  static bool Frame(const std::uint8_t* base, std::size_t n, std::size_t pos, Record* r);
  /// A chunk made ready to parse: its records decompressed (into the ChunkBuffers given) when
  /// its size is stated and within kRosMaxChunkBytes (else body is empty, and UseChunk says
  /// why). Made by Open, which touches nothing else, so that it may run on another thread ahead
  /// of the parse.
  struct OpenedChunk {
    detail::ChunkBody body;
    std::exception_ptr error;  ///< thrown while opening: rethrown where the parse is
  };
  using Stretch = detail::Stretch<Record, OpenedChunk>;
  /// Whether `r`, framed at top level, is a chunk record (its header parsed, op 0x05).
  static bool IsChunk(const Record& r) {
    return r.header != nullptr && r.header_ok && r.fields.has_op &&
           r.fields.op == detail::kOpChunk;
  }
  /// Opens the chunk record `r` (cut: its data as far as the file goes) into `out`; an error
  /// thrown is kept in `out` for the parse.
  static void Open(const Record& r, bool cut, detail::ChunkBuffers* buffers, OpenedChunk* out);
  /// The records from `pos` (the first after the bag header) to the end, on this thread alone.
  void RunInOrder(std::size_t pos);
  /// The same, the chunks opened up to detail::kStretchesInFlight - 1 stretches ahead of the
  /// parse through run_jobs_ (detail::ReadAhead).
  void RunAhead(std::size_t pos);
  /// Whether the records from `pos` hold at least `n` chunks (looked for up to the n-th).
  bool ChunksAtLeast(std::size_t pos, std::size_t n) const;
  /// The top-level record `r` at `at`, whole; `opened`: its chunk opened ahead, or nullptr.
  void Whole(const Record& r, std::size_t at, const OpenedChunk* opened);
  /// The top-level record at `at`, cut by the file's end: said (a chunk's whole records
  /// kept), and the reading ends.
  void CutAt(const Record& r, std::size_t at, const OpenedChunk* opened);
  void TopRecord(const Record& r, std::size_t at, const OpenedChunk* opened);
  /// The chunk record `r` at `at`, opened here.
  void Chunk(const Record& r, std::size_t at, bool cut);
  /// The chunk record `r` at `at`, opened (`c`): counted, its records read.
  void UseChunk(const Record& r, const OpenedChunk& c, std::size_t at, bool cut);
  /// The records of a chunk's data [p, p + n); `at`: the chunk's file offset. Returns the
  /// message records read; `past_end` says what ran past the data's end ("" when none).
  std::size_t ChunkRecords(const std::uint8_t* p, std::size_t n, std::size_t at,
                           std::string* past_end);
  void Connection(const Record& r, std::size_t at);
  void Message(const Record& r, std::size_t at);
  /// Decodes a sensor_msgs/Imu message of imu_topics[topic] into its samples.
  void Decode(int topic, std::uint32_t sec, std::uint32_t nsec, const std::uint8_t* p,
              std::size_t n, std::size_t at);
  void Damaged(std::size_t at, const std::string& why);
  void Finish();

  const std::uint8_t* data_;
  std::size_t size_;
  RosBag* bag_;
  const LogFile* file_;
  std::size_t min_chunks_;
  const JobRunner& run_jobs_;
  std::size_t released_ = 0;  ///< the file is released up to here
  std::size_t read_to_ = 0;   ///< the file offset past the top-level record being read
  /// By index in imu_topics: the samples its four vectors have room for
  /// (detail::ReserveImuAhead's).
  std::vector<std::size_t> room_;
  bool cut_ = false;          ///< a record ran past the file's end: the reading ended there
  /// A connection as a message finds it: its record, and its index in imu_topics (-1: not IMU).
  struct Slot {
    RosConnection* conn = nullptr;  ///< nullptr: not defined (yet)
    int topic = -1;
  };
  /// The slot of connection `id`: by index for the small ids every recorder gives (from 0 up),
  /// else in a map (no lookup by hash or tree per message of a normal bag).
  Slot& SlotOf(std::uint32_t id) {
    if (id < kDenseIds) {
      if (id >= slots_.size()) slots_.resize(id + 1);
      return slots_[id];
    }
    return sparse_slots_[id];
  }
  static constexpr std::uint32_t kDenseIds = 1u << 16;
  std::vector<Slot> slots_;
  std::unordered_map<std::uint32_t, Slot> sparse_slots_;
  std::vector<Pending> pending_;
  detail::ChunkBuffers chunk_;  ///< a decompressed chunk and the decompressors, reused
};

bool Parser::Frame(const std::uint8_t* base, std::size_t n, std::size_t pos, Record* r) {
  // Reset field by field: a whole `*r = Record{}` cleared the struct with a slow `rep stos`
  // per record (a fifth of the reading time of an uncompressed bag).
  r->header = nullptr;
  r->header_len = 0;
  r->data = nullptr;
  r->data_len = 0;
  r->end = 0;
  r->header_ok = true;
  r->why.clear();
  if (n - pos < 4) return false;
  const std::size_t header_len = LoadLittleEndian<std::uint32_t>(base + pos);
  if (header_len > n - pos - 4) return false;
  r->header = base + pos + 4;
  r->header_len = header_len;
  r->header_ok = detail::ParseRecordFields(r->header, header_len, &r->fields, &r->why);
  const std::size_t data_at = pos + 4 + header_len;
  if (n - data_at < 4) return false;
  const std::size_t data_len = LoadLittleEndian<std::uint32_t>(base + data_at);
  r->data = base + data_at + 4;
  r->data_len = std::min(data_len, n - data_at - 4);
  r->end = data_at + 4 + data_len;
  return data_len <= n - data_at - 4;
}

void Parser::Damaged(std::size_t at, const std::string& why) {
  RosBagWarnings& w = bag_->warnings;
  if (w.damaged_chunks++ == 0) {
    w.first_damaged_chunk = at;
    w.first_damage = why;
  }
}

void Parser::Run() {
  std::size_t pos = detail::kRosBagMagicSize;
  if (pos == size_) {
    throw InputError(bag_->source, "byte " + std::to_string(pos),
                     "expected the bag header record (op 0x03) after \"#ROSBAG V2.0\"; the file "
                     "ends there");
  }
  Record r;
  const bool whole = Frame(data_, size_, pos, &r);
  if (!whole || !r.header_ok || !r.fields.has_op || r.fields.op != detail::kOpBagHeader) {
    throw InputError(bag_->source, "byte " + std::to_string(pos),
                     "expected the bag header record (op 0x03) after \"#ROSBAG V2.0\"" +
                         std::string(r.why.empty() ? "" : ": " + r.why));
  }
  Whole(r, pos, nullptr);
  pos = r.end;
  if (run_jobs_ && ChunksAtLeast(pos, min_chunks_)) {
    RunAhead(pos);
  } else {
    RunInOrder(pos);
  }
  // Every record whole, but the bag header puts the index at the end or past it: cut at a
  // record boundary.
  if (!cut_ && bag_->index_pos != 0 && bag_->index_pos >= size_) {
    bag_->warnings.cut_at = size_;
    bag_->warnings.index_past_end = bag_->index_pos;
    bag_->warnings.messages_read = bag_->messages;
  }
  Finish();
}

void Parser::RunInOrder(std::size_t pos) {
  Record r;
  while (pos < size_) {
    if (!Frame(data_, size_, pos, &r)) {
      CutAt(r, pos, nullptr);
      return;
    }
    Whole(r, pos, nullptr);
    pos = r.end;
  }
}

// The schedule is detail::ReadAhead's: stretches framed in order, opened on either job, parsed
// in order. The parse touches only what RunInOrder's would (the bag, the connections, the
// pending messages, the page release), in the same order; opening touches only its slot.
void Parser::RunAhead(std::size_t pos) {
  const auto frame = [this](std::size_t at, Record* r) { return Frame(data_, size_, at, r); };
  // A cut record is read only when it is a chunk whose data begins in the file (CutAt).
  const auto is_chunk = [](const Record& r, bool whole) {
    return IsChunk(r) && (whole || r.data != nullptr);
  };
  const auto whole = [this](const Record& r, std::size_t at, const OpenedChunk* opened) {
    Whole(r, at, opened);
  };
  const auto cut_at = [this](const Record& r, std::size_t at, const OpenedChunk* opened) {
    CutAt(r, at, opened);
  };
  detail::ReadAhead<Stretch>(
      run_jobs_,
      [&](Stretch& s) {
        return s.Frame(&pos, size_, frame, is_chunk, [](const Record&) { return false; });
      },
      [](Stretch& s) {
        if (s.has_chunk) Open(s.records.back().first, s.cut, &s.buffers, &s.chunk);
      },
      [&](const Stretch& s) { s.Parse(whole, cut_at); });
}

bool Parser::ChunksAtLeast(std::size_t pos, std::size_t n) const {
  std::size_t chunks = 0;
  Record r;
  while (chunks < n && pos < size_ && Frame(data_, size_, pos, &r)) {
    if (IsChunk(r)) ++chunks;
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
  // A chunk whose header is whole: its data as far as the file goes.
  if (IsChunk(r) && r.data != nullptr) {
    if (opened != nullptr) {
      UseChunk(r, *opened, at, true);
    } else {
      Chunk(r, at, true);
    }
  }
  bag_->warnings.messages_read = bag_->messages;
  cut_ = true;
}

void Parser::TopRecord(const Record& r, std::size_t at, const OpenedChunk* opened) {
  RosBagWarnings& w = bag_->warnings;
  if (!r.header_ok || !r.fields.has_op) {
    if (w.bad_records++ == 0) w.first_bad_record = at;
    return;
  }
  switch (r.fields.op) {
    case detail::kOpBagHeader: bag_->index_pos = r.fields.index_pos; break;
    case detail::kOpChunk:
      if (opened != nullptr) {
        UseChunk(r, *opened, at, false);
      } else {
        Chunk(r, at, false);
      }
      break;
    case detail::kOpConnection: Connection(r, at); break;
    case detail::kOpMessageData: Message(r, at); break;
    case detail::kOpChunkInfo: ++bag_->chunk_infos; break;
    case detail::kOpIndexData: break;
    default: ++w.unknown_ops; break;
  }
}

void Parser::Open(const Record& r, bool cut, detail::ChunkBuffers* buffers, OpenedChunk* out) {
  out->body = detail::ChunkBody{};
  out->error = nullptr;
  if (!r.fields.has_size || r.fields.size > detail::kRosMaxChunkBytes) return;
  try {
    out->body = detail::OpenChunk(r.fields.compression.substr(0, 32), r.data, r.data_len,
                                  r.fields.size, cut, buffers);
  } catch (...) {  // memory running out
    out->error = std::current_exception();
  }
}

void Parser::Chunk(const Record& r, std::size_t at, bool cut) {
  OpenedChunk c;
  Open(r, cut, &chunk_, &c);
  UseChunk(r, c, at, cut);
}

void Parser::UseChunk(const Record& r, const OpenedChunk& c, std::size_t at, bool cut) {
  ++bag_->chunks;
  const std::string compression(r.fields.compression.substr(0, 32));
  ++bag_->compression[compression.empty() ? "none" : compression];
  if (c.error) std::rethrow_exception(c.error);
  if (!r.fields.has_size) {
    Damaged(at, "chunk without its 'size' field");
    return;
  }
  if (r.fields.size > detail::kRosMaxChunkBytes) {
    Damaged(at, "chunk stating " + std::to_string(r.fields.size) +
                    " bytes uncompressed, more than plumb reads (1 GiB)");
    return;
  }
  const detail::ChunkBody& body = c.body;
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
      // A record past the data: the end of a cut chunk, or a length that is wrong.
      *past_end = "a record at offset " + std::to_string(pos) + " of the chunk's " +
                  std::to_string(n) + " bytes runs past its end";
      break;
    }
    if (!r.header_ok || !r.fields.has_op) {
      RosBagWarnings& w = bag_->warnings;
      if (w.bad_records++ == 0) w.first_bad_record = at;
    } else if (r.fields.op == detail::kOpMessageData) {
      Message(r, at);
      ++messages;
    } else if (r.fields.op == detail::kOpConnection) {
      Connection(r, at);
    } else {
      ++bag_->warnings.unknown_ops;
    }
    pos = r.end;
  }
  return messages;
}

void Parser::Connection(const Record& r, std::size_t at) {
  RosBagWarnings& w = bag_->warnings;
  RosConnection c;
  std::string why;
  if (!r.fields.has_conn || !r.fields.has_topic ||
      !detail::ParseConnectionData(r.data, r.data_len, &c, &why)) {
    if (w.bad_records++ == 0) w.first_bad_record = at;
    return;
  }
  if (bag_->connections.count(r.fields.conn) != 0) return;  // repeated in the index section
  c.id = r.fields.conn;
  c.topic = std::string(r.fields.topic);
  int topic = -1;
  if (c.type == kImuType) {
    topic = detail::ImuTopicIndex(bag_, c.topic);
    auto& topics = bag_->imu_topics;
    if (c.md5sum != kRosImuMd5) {
      topics[static_cast<std::size_t>(topic)].md5_differs = true;
      w.md5_notes.push_back("connection " + std::to_string(c.id) + " (" + c.topic +
                            "): sensor_msgs/Imu md5sum '" + c.md5sum.substr(0, 40) +
                            "' is not " + kRosImuMd5 +
                            "; its messages are decoded where their size fits the layout");
    }
  }
  const std::uint32_t id = c.id;
  RosConnection& stored = bag_->connections.emplace(id, std::move(c)).first->second;
  SlotOf(id) = Slot{&stored, topic};
}

void Parser::Message(const Record& r, std::size_t at) {
  RosBagWarnings& w = bag_->warnings;
  if (!r.fields.has_conn || !r.fields.has_time) {
    if (w.bad_records++ == 0) w.first_bad_record = at;
    return;
  }
  ++bag_->messages;
  const Slot& slot = SlotOf(r.fields.conn);
  if (slot.conn == nullptr) {
    Pending p{r.fields.conn, r.fields.sec, r.fields.nsec, at, {r.data, r.data + r.data_len}};
    pending_.push_back(std::move(p));
    return;
  }
  ++slot.conn->messages;
  if (slot.topic >= 0) Decode(slot.topic, r.fields.sec, r.fields.nsec, r.data, r.data_len, at);
}

void Parser::Decode(int topic, std::uint32_t sec, std::uint32_t nsec, const std::uint8_t* p,
                    std::size_t n, std::size_t at) {
  const auto k = static_cast<std::size_t>(topic);
  RosImuTopic& t = bag_->imu_topics[k];
  if (k >= room_.size()) room_.resize(bag_->imu_topics.size());  // a new topic's: 0
  if (t.samples.t_s.size() >= room_[k]) room_[k] = detail::ReserveImuAhead(&t, read_to_, size_);
  detail::RosImuMessage m;
  if (!detail::DecodeRosImu(p, n, &m)) {
    ++t.malformed;
    if (bag_->warnings.malformed_imu++ == 0) bag_->warnings.first_malformed_imu = at;
    return;
  }
  detail::AppendImu(&t, m, sec, nsec);
}

void Parser::Finish() {
  for (const Pending& p : pending_) {
    const auto it = bag_->connections.find(p.conn);
    if (it == bag_->connections.end()) {
      if (bag_->warnings.orphan_messages++ == 0) bag_->warnings.first_orphan = p.offset;
      continue;
    }
    ++it->second.messages;
    const int topic = SlotOf(p.conn).topic;
    if (topic >= 0) Decode(topic, p.sec, p.nsec, p.bytes.data(), p.bytes.size(), p.offset);
  }
  // Kept aside in file order: the samples of a topic may now be out of record order; the
  // session keeps increasing times (KeepIncreasingTimes), so sort each topic by record time
  // only when late messages were added.
  if (!pending_.empty()) {
    for (RosImuTopic& t : bag_->imu_topics) {
      std::vector<std::size_t> order(t.receive_s.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return t.receive_s[a] < t.receive_s[b];
      });
      RosImuTopic sorted = t;
      for (std::size_t i = 0; i < order.size(); ++i) {
        sorted.samples.t_s[i] = t.samples.t_s[order[i]];
        sorted.samples.acc[i] = t.samples.acc[order[i]];
        sorted.samples.gyr[i] = t.samples.gyr[order[i]];
        sorted.receive_s[i] = t.receive_s[order[i]];
      }
      t = std::move(sorted);
    }
  }
}

}  // namespace

bool RosBagWarnings::any() const {
  return cut_at || bad_records || damaged_chunks || unknown_ops || orphan_messages ||
         malformed_imu || !md5_notes.empty() || !notes.empty();
}

std::vector<std::string> RosBagWarnings::Describe() const {
  std::vector<std::string> out;
  const auto n = [](std::size_t v) { return std::to_string(v); };
  if (cut_at && index_past_end) {
    out.push_back("cut short: the bag header puts the index at byte " + n(index_past_end) +
                  ", not before the end of the file (" + n(*cut_at) + " bytes); its " +
                  n(messages_read) + " messages were read");
  } else if (cut_at) {
    out.push_back("cut short: the record at byte " + n(*cut_at) +
                  " runs past the end of the file; the " + n(messages_read) +
                  " messages before the cut were read" +
                  (cut_messages_kept ? " (" + n(cut_messages_kept) +
                                           " of them whole in that cut chunk)"
                                     : std::string()));
  }
  if (damaged_chunks) {
    out.push_back(n(damaged_chunks) + " chunk(s) not read to their end (first at byte " +
                  n(first_damaged_chunk) + ": " + first_damage +
                  "); their records before the fault were read");
  }
  if (bad_records) {
    out.push_back(n(bad_records) + " record(s) whose header does not parse, skipped (first at byte " +
                  n(first_bad_record) + ")");
  }
  if (unknown_ops) out.push_back(n(unknown_ops) + " record(s) of an unknown op, skipped");
  if (orphan_messages) {
    out.push_back(n(orphan_messages) + " message(s) of a connection the bag never defines, " +
                  "skipped (first in the record at byte " + n(first_orphan) + ")");
  }
  if (malformed_imu && !first_malformed_why.empty()) {
    out.push_back(n(malformed_imu) + " sensor_msgs/Imu message(s) that do not decode, skipped " +
                  "(first: " + first_malformed_why + ")");
  } else if (malformed_imu) {
    out.push_back(n(malformed_imu) + " sensor_msgs/Imu message(s) whose size is not 16 + " +
                  "frame_id + 296 bytes, skipped (first in the record at byte " +
                  n(first_malformed_imu) + ")");
  }
  for (const std::string& m : md5_notes) out.push_back(m);
  for (const std::string& m : notes) out.push_back(m);
  return out;
}

const RosImuTopic* RosBag::Find(const std::string& topic) const {
  for (const RosImuTopic& t : imu_topics) {
    if (t.topic == topic) return &t;
  }
  return nullptr;
}

std::vector<std::pair<std::string, std::size_t>> RosBag::MessageCounts() const {
  std::vector<std::pair<std::string, std::size_t>> out;
  for (const auto& [id, c] : connections) {
    const std::string key = c.topic + " (" + c.type + ")";
    const auto it = std::find_if(out.begin(), out.end(),
                                 [&](const auto& e) { return e.first == key; });
    if (it == out.end()) {
      out.emplace_back(key, c.messages);
    } else {
      it->second += c.messages;
    }
  }
  return out;
}

namespace {

/// ParseRosBag, releasing the pages of `file` (or nullptr) behind the parser, the chunks read
/// ahead through `run_jobs` from `min_chunks` of them.
RosBag ParseRosBagFrom(const std::uint8_t* data, std::size_t size, const std::string& source,
                       const LogFile* file, const JobRunner& run_jobs = {},
                       std::size_t min_chunks = detail::kRosChunksReadAhead) {
  RosBag bag;
  bag.source = source;
  bag.size_bytes = size;
  const std::size_t head = std::min(size, detail::kRosBagMagicSize);
  if (size < detail::kRosBagPrefixSize ||
      !std::equal(data, data + detail::kRosBagPrefixSize, detail::kRosBagPrefix)) {
    throw InputError(source, "byte 0", "not a ROS bag (no \"#ROSBAG V\" line)");
  }
  if (head < detail::kRosBagMagicSize ||
      !std::equal(data, data + detail::kRosBagMagicSize, detail::kRosBagMagic)) {
    const auto* text = reinterpret_cast<const char*>(data);
    const std::size_t line = std::find(text, text + head, '\n') - text;
    throw InputError(source, "byte 0",
                     "ROS bag of another version (\"" + std::string(text, line) +
                         "\"); plumb reads ROS 1 bags of version 2.0");
  }
  Parser(data, size, &bag, file, min_chunks, run_jobs).Run();
  return bag;
}

}  // namespace

RosBag ParseRosBag(const std::uint8_t* data, std::size_t size, const std::string& source) {
  return ParseRosBagFrom(data, size, source, nullptr);
}

RosBag detail::ParseRosBagReadingAhead(const std::uint8_t* data, std::size_t size,
                                       const std::string& source, const JobRunner& run_jobs,
                                       std::size_t min_chunks) {
  return ParseRosBagFrom(data, size, source, nullptr, run_jobs, min_chunks);
}

RosBag ReadRosBag(const std::string& path, const JobRunner& run_jobs) {
  const LogFile file(path, "ROS bag");
  try {
    RosBag bag = ParseRosBagFrom(file.data(), file.size(), path, &file, run_jobs);
    file.ThrowIfCut();
    return bag;
  } catch (const Error&) {
    file.ThrowIfCut();  // the zeros of a cut may have caused it
    throw;
  }
}

bool LooksLikeRosBag(const std::string& path) {
  std::ifstream in(OpenPath(path), std::ios::binary);
  char head[detail::kRosBagPrefixSize] = {};
  in.read(head, sizeof(head));
  return in.gcount() == static_cast<std::streamsize>(sizeof(head)) &&
         std::equal(head, head + sizeof(head), detail::kRosBagPrefix);
}

}  // namespace plumb::io

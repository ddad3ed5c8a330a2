// plumb/io/ros/rosbag.cc — see rosbag.h for the format and the decoding contract: the one
// pass over the bag's records and chunks, and the reader's entry points.
#include "plumb/io/ros/rosbag.h"

#include <algorithm>
#include <fstream>
#include <unordered_map>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/stream_spool.h"
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
  /// goes (LogFile::Release), or nullptr.
  Parser(const std::uint8_t* data, std::size_t size, RosBag* bag, const LogFile* file)
      : data_(data), size_(size), bag_(bag), file_(file) {}

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

  void TopRecord(const Record& r, std::size_t at);
  void Chunk(const Record& r, std::size_t at, bool cut);
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
  std::size_t released_ = 0;  ///< the file is released up to here
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
  bool first = true;
  Record r;
  while (pos < size_) {
    const bool whole = Frame(data_, size_, pos, &r);
    if (first) {
      if (!whole || !r.header_ok || !r.fields.has_op || r.fields.op != detail::kOpBagHeader) {
        throw InputError(bag_->source, "byte " + std::to_string(pos),
                         "expected the bag header record (op 0x03) after \"#ROSBAG V2.0\"" +
                             std::string(r.why.empty() ? "" : ": " + r.why));
      }
      first = false;
    }
    if (!whole) {
      bag_->warnings.cut_at = pos;
      // A chunk whose header is whole: its data as far as the file goes.
      if (r.header != nullptr && r.header_ok && r.fields.has_op &&
          r.fields.op == detail::kOpChunk && r.data != nullptr) {
        Chunk(r, pos, true);
      }
      bag_->warnings.messages_read = bag_->messages;
      break;
    }
    TopRecord(r, pos);
    pos = r.end;
    if (file_ != nullptr && pos >= released_ + LogFile::kReleaseStep) {
      file_->Release(released_, pos);
      released_ = pos;
    }
  }
  // Every record whole, but the bag header puts the index at the end or past it: cut at a
  // record boundary.
  if (!bag_->warnings.cut_at && bag_->index_pos != 0 && bag_->index_pos >= size_) {
    bag_->warnings.cut_at = size_;
    bag_->warnings.index_past_end = bag_->index_pos;
    bag_->warnings.messages_read = bag_->messages;
  }
  Finish();
}

void Parser::TopRecord(const Record& r, std::size_t at) {
  RosBagWarnings& w = bag_->warnings;
  if (!r.header_ok || !r.fields.has_op) {
    if (w.bad_records++ == 0) w.first_bad_record = at;
    return;
  }
  switch (r.fields.op) {
    case detail::kOpBagHeader: bag_->index_pos = r.fields.index_pos; break;
    case detail::kOpChunk: Chunk(r, at, false); break;
    case detail::kOpConnection: Connection(r, at); break;
    case detail::kOpMessageData: Message(r, at); break;
    case detail::kOpChunkInfo: ++bag_->chunk_infos; break;
    case detail::kOpIndexData: break;
    default: ++w.unknown_ops; break;
  }
}

void Parser::Chunk(const Record& r, std::size_t at, bool cut) {
  ++bag_->chunks;
  const std::string compression(r.fields.compression.substr(0, 32));
  ++bag_->compression[compression.empty() ? "none" : compression];
  if (!r.fields.has_size) {
    Damaged(at, "chunk without its 'size' field");
    return;
  }
  if (r.fields.size > detail::kRosMaxChunkBytes) {
    Damaged(at, "chunk stating " + std::to_string(r.fields.size) +
                    " bytes uncompressed, more than plumb reads (1 GiB)");
    return;
  }
  const detail::ChunkBody body =
      detail::OpenChunk(compression, r.data, r.data_len, r.fields.size, cut, &chunk_);
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
  RosImuTopic& t = bag_->imu_topics[static_cast<std::size_t>(topic)];
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

/// ParseRosBag, releasing the pages of `file` (or nullptr) behind the parser.
RosBag ParseRosBagFrom(const std::uint8_t* data, std::size_t size, const std::string& source,
                       const LogFile* file) {
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
  Parser(data, size, &bag, file).Run();
  return bag;
}

}  // namespace

RosBag ParseRosBag(const std::uint8_t* data, std::size_t size, const std::string& source) {
  return ParseRosBagFrom(data, size, source, nullptr);
}

RosBag ReadRosBag(const std::string& path) {
  const LogFile file(path, "ROS bag");
  try {
    RosBag bag = ParseRosBagFrom(file.data(), file.size(), path, &file);
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

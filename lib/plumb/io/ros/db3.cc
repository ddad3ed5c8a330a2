// plumb/io/ros/db3.cc — see db3.h.
#include "plumb/io/ros/db3.h"

#include <sqlite3.h>

#include <stdlib.h>  // mkdtemp

#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>
#include <unordered_map>

#include "plumb/core/error.h"
#include "plumb/io/common/stream_spool.h"
#include "plumb/io/ros/ros_imu.h"

namespace plumb::io {
namespace {

constexpr char kSqliteHeader[] = "SQLite format 3";  // and its NUL: 16 bytes
constexpr std::size_t kSqliteHeaderSize = sizeof(kSqliteHeader);
constexpr const char* kImuType = "sensor_msgs/msg/Imu";

struct CloseDb {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
using Db = std::unique_ptr<sqlite3, CloseDb>;
struct FinalizeStatement {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Statement = std::unique_ptr<sqlite3_stmt, FinalizeStatement>;

/// `path` as an SQLite URI (every byte outside the unreserved set and '/' percent-encoded) with
/// `query` ("mode=ro&immutable=1").
std::string Uri(const std::string& path, const char* query) {
  std::string uri = "file:";
  for (const unsigned char c : path) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '.' || c == '_' || c == '~') {
      uri += static_cast<char>(c);
    } else {
      static constexpr char kHex[] = "0123456789ABCDEF";
      uri += '%';
      uri += kHex[c >> 4];
      uri += kHex[c & 15];
    }
  }
  return uri + "?" + query;
}

/// The size of the -wal file beside `file` when it holds frames (more than its 32-byte header),
/// else 0.
std::uintmax_t WalBytes(const std::string& file) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(file + "-wal", ec);
  return !ec && size > 32 ? size : 0;
}

/// A folder plumb makes in the temporary directory holding a copy of a bag and of its -wal
/// file, where sqlite3 reads them as a live database (the -wal's frames replayed, its -shm
/// made there); the copies, what sqlite3 made beside them and the folder are removed with it,
/// nothing else.
class WalCopy {
 public:
  WalCopy(const std::string& file, const std::string& source) {
    std::string pattern = (std::filesystem::temp_directory_path() / "plumb-db3-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw InputError(source, "", "cannot make a temporary folder to read its -wal file in: " +
                                       std::string(std::strerror(errno)));
    }
    dir_ = pattern;
    db_ = dir_ + "/bag.db3";
    std::error_code ec;
    std::filesystem::copy_file(file, db_, ec);
    if (!ec) std::filesystem::copy_file(file + "-wal", db_ + "-wal", ec);
    if (ec) {
      Remove();
      throw InputError(source, "", "cannot copy it and its -wal file to a temporary folder: " +
                                       ec.message());
    }
  }
  ~WalCopy() { Remove(); }
  WalCopy(const WalCopy&) = delete;
  WalCopy& operator=(const WalCopy&) = delete;
  const std::string& db() const { return db_; }

 private:
  void Remove() const {
    std::error_code ec;
    for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
      std::filesystem::remove(db_ + suffix, ec);
    }
    std::filesystem::remove(dir_, ec);  // only when empty
  }
  std::string dir_, db_;
};

/// Opens `path` read-only: immutable (no lock, nothing written beside it) unless `live`, for a
/// WalCopy's database (its -wal read, its -shm made in plumb's own folder).
Db OpenFile(const std::string& path, std::string* why, bool live = false) {
  sqlite3* db = nullptr;
  const std::string uri = Uri(path, live ? "mode=ro" : "mode=ro&immutable=1");
  const int rc =
      sqlite3_open_v2(uri.c_str(), &db, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr);
  Db out(db);
  if (rc != SQLITE_OK) {
    *why = std::string("sqlite3 cannot open it: ") + (db ? sqlite3_errmsg(db) : sqlite3_errstr(rc));
    return nullptr;
  }
  return out;
}

/// A read-only in-memory database over a copy of [data, data + size).
Db OpenMemory(const std::uint8_t* data, std::size_t size, std::string* why) {
  sqlite3* db = nullptr;
  const int rc = sqlite3_open_v2(":memory:", &db, SQLITE_OPEN_READWRITE, nullptr);
  Db out(db);
  if (rc != SQLITE_OK) {
    *why = "sqlite3 could not start";
    return nullptr;
  }
  auto* copy = static_cast<unsigned char*>(sqlite3_malloc64(size == 0 ? 1 : size));
  if (copy == nullptr) {
    *why = "no memory for the database";
    return nullptr;
  }
  if (size > 0) std::memcpy(copy, data, size);
  if (sqlite3_deserialize(db, "main", copy, static_cast<sqlite3_int64>(size),
                          static_cast<sqlite3_int64>(size),
                          SQLITE_DESERIALIZE_FREEONCLOSE | SQLITE_DESERIALIZE_READONLY) !=
      SQLITE_OK) {
    *why = std::string("sqlite3 cannot read it: ") + sqlite3_errmsg(db);
    return nullptr;
  }
  return out;
}

Statement Prepare(sqlite3* db, const char* sql, const std::string& source) {
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &s, nullptr) != SQLITE_OK) {
    throw InputError(source, "",
                     std::string("not a ROS 2 sqlite3 bag: ") + sqlite3_errmsg(db) + " (in \"" +
                         sql + "\")");
  }
  return Statement(s);
}

std::string Text(sqlite3_stmt* s, int column) {
  const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(s, column));
  return p == nullptr ? std::string() : std::string(p, sqlite3_column_bytes(s, column));
}

/// The topics table into bag->connections; the IMU topics' index in imu_topics by topic id.
std::unordered_map<std::int64_t, int> ReadTopics(sqlite3* db, RosBag* bag) {
  std::unordered_map<std::int64_t, int> imu;
  const Statement s =
      Prepare(db, "SELECT id, name, type, serialization_format FROM topics ORDER BY id",
              bag->source);
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
    RosConnection c;
    const std::int64_t id = sqlite3_column_int64(s.get(), 0);
    c.id = static_cast<std::uint32_t>(id);
    c.topic = Text(s.get(), 1).substr(0, 1024);
    c.type = Text(s.get(), 2).substr(0, 256);
    const std::string format = Text(s.get(), 3);
    if (c.type == kImuType) {
      if (format == "cdr") {
        imu[id] = detail::ImuTopicIndex(bag, c.topic);
      } else {
        bag->warnings.notes.push_back("topic " + c.topic + ": sensor_msgs/msg/Imu in '" +
                                      format.substr(0, 32) +
                                      "', not CDR; its messages are not decoded");
      }
    }
    bag->connections.emplace(c.id, std::move(c));
  }
  if (rc != SQLITE_DONE) {
    throw InputError(bag->source, "table topics",
                     std::string("the topics do not read: ") + sqlite3_errmsg(db));
  }
  return imu;
}

void ReadMessages(sqlite3* db, const std::unordered_map<std::int64_t, int>& imu, RosBag* bag) {
  const Statement s =
      Prepare(db, "SELECT id, topic_id, timestamp, data FROM messages ORDER BY id", bag->source);
  RosBagWarnings& w = bag->warnings;
  std::int64_t last_id = -1;
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
    last_id = sqlite3_column_int64(s.get(), 0);
    const std::int64_t topic_id = sqlite3_column_int64(s.get(), 1);
    ++bag->messages;
    const auto conn = bag->connections.find(static_cast<std::uint32_t>(topic_id));
    if (conn == bag->connections.end() || conn->first != topic_id) {
      if (w.orphan_messages++ == 0) w.first_orphan = static_cast<std::size_t>(last_id);
      continue;
    }
    ++conn->second.messages;
    const auto topic = imu.find(topic_id);
    if (topic == imu.end()) continue;
    RosImuTopic& t = bag->imu_topics[static_cast<std::size_t>(topic->second)];
    const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(s.get(), 3));
    const auto n = static_cast<std::size_t>(sqlite3_column_bytes(s.get(), 3));
    detail::RosImuMessage m;
    std::string why;
    if (!detail::DecodeCdrImu(data, data == nullptr ? 0 : n, &m, &why)) {
      ++t.malformed;
      if (w.malformed_imu++ == 0) {
        w.first_malformed_imu = static_cast<std::size_t>(last_id);
        w.first_malformed_why = "the message of id " + std::to_string(last_id) + " (" + t.topic +
                                "), " + why;
      }
      continue;
    }
    std::int64_t sec = 0;
    std::uint32_t nsec = 0;
    detail::SplitNanoseconds(sqlite3_column_int64(s.get(), 2), &sec, &nsec);
    detail::AppendImu(&t, m, sec, nsec);
  }
  if (rc != SQLITE_DONE) {
    if (bag->messages == 0) {
      throw InputError(bag->source, "table messages",
                       std::string("the messages do not read: ") + sqlite3_errmsg(db));
    }
    w.notes.push_back("the messages stopped reading after the message of id " +
                      std::to_string(last_id) + " (sqlite3: " + sqlite3_errmsg(db) + "); the " +
                      std::to_string(bag->messages) + " messages before were read");
  }
}

RosBag ReadFrom(sqlite3* db, const std::string& source, std::size_t size) {
  RosBag bag;
  bag.kind = RosBagKind::kSqlite3;
  bag.source = source;
  bag.size_bytes = size;
  const auto imu = ReadTopics(db, &bag);
  ReadMessages(db, imu, &bag);
  return bag;
}

/// A bag with a -wal file of `wal` bytes beside it (a recorder that did not close it): read
/// from a WalCopy, so that the messages not yet checkpointed into the bag are read too.
RosBag ReadWithWal(const std::string& file, const std::string& path, std::size_t size,
                   std::uintmax_t wal) {
  const WalCopy copy(file, path);
  std::string why;
  Db db = OpenFile(copy.db(), &why, true);
  if (!db) throw InputError(path, "", why + " (a copy of it with its -wal file)");
  RosBag bag = ReadFrom(db.get(), path, size);
  db.reset();  // closed before the copy is removed
  bag.warnings.notes.push_back(
      "its -wal file (" + path + "-wal, " + std::to_string(wal) +
      " bytes) was not checkpointed into it (the recording was not closed): read with it, "
      "from a copy of both in a temporary folder; the " +
      std::to_string(bag.messages) + " messages are the bag's and the -wal file's");
  return bag;
}

bool HasSqliteHeader(const std::uint8_t* data, std::size_t size) {
  return size >= kSqliteHeaderSize &&
         std::memcmp(data, kSqliteHeader, kSqliteHeaderSize) == 0;
}

}  // namespace

RosBag ParseDb3(const std::uint8_t* data, std::size_t size, const std::string& source) {
  if (!HasSqliteHeader(data, size)) {
    throw InputError(source, "byte 0", "not an SQLite 3 database (no \"SQLite format 3\" header)");
  }
  std::string why;
  const Db db = OpenMemory(data, size, &why);
  if (!db) throw InputError(source, "", why);
  return ReadFrom(db.get(), source, size);
}

RosBag ReadDb3(const std::string& path) {
  const std::string file = OpenPath(path);
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path, "", "cannot open the file");
  const auto size = static_cast<std::size_t>(in.tellg());
  in.seekg(0);
  std::uint8_t head[kSqliteHeaderSize] = {};
  in.read(reinterpret_cast<char*>(head), sizeof(head));
  if (!HasSqliteHeader(head, static_cast<std::size_t>(in.gcount()))) {
    throw InputError(path, "byte 0", "not an SQLite 3 database (no \"SQLite format 3\" header)");
  }
  const std::uintmax_t wal = WalBytes(file);
  if (wal == 0) {
    std::string why;
    const Db db = OpenFile(file, &why);
    if (!db) throw InputError(path, "", why);
    return ReadFrom(db.get(), path, size);
  }
  return ReadWithWal(file, path, size, wal);
}

bool LooksLikeDb3(const std::string& path) {
  const std::string file = OpenPath(path);
  {
    std::ifstream in(file, std::ios::binary);
    std::uint8_t head[kSqliteHeaderSize] = {};
    in.read(reinterpret_cast<char*>(head), sizeof(head));
    if (!HasSqliteHeader(head, static_cast<std::size_t>(in.gcount()))) return false;
  }
  if (WalBytes(file) != 0) return true;  // its tables may be in the -wal file only
  std::string why;
  const Db db = OpenFile(file, &why);
  if (!db) return false;
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db.get(),
                         "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name IN "
                         "('topics', 'messages')",
                         -1, &raw, nullptr) != SQLITE_OK) {
    return false;
  }
  const Statement s(raw);
  return sqlite3_step(s.get()) == SQLITE_ROW && sqlite3_column_int(s.get(), 0) == 2;
}

}  // namespace plumb::io

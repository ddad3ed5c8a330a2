// A tiny writer of ROS 2 bags for the readers' tests (tests/io/ros2_test.cc): CDR
// sensor_msgs/msg/Imu messages (either byte order), MCAP records and chunks (none, zstd, lz4
// frame; compressed by libzstd and liblz4), and .db3 files (sqlite3), as mcap.h and db3.h
// describe the formats.
#pragma once

#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <boost/crc.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace plumb::test {

/// One sensor_msgs/msg/Imu message's fields.
struct Ros2Imu {
  std::int32_t sec = 1700000000;
  std::uint32_t nsec = 0;
  std::string frame_id = "imu_link";
  std::array<double, 4> orientation = {0.0, 0.0, 0.0, 1.0};
  double orientation_cov0 = 0.0;
  std::array<double, 3> gyr = {0.01, -0.02, 0.03};
  double gyr_cov0 = 0.0;
  std::array<double, 3> acc = {0.1, -0.2, 9.8};
  double acc_cov0 = 0.0;
};

/// `m` serialized as CDR (encapsulation 0 1 little endian, 0 0 big endian), every primitive
/// aligned to its size from the byte after the 4-byte encapsulation header.
inline std::string CdrImu(const Ros2Imu& m, bool little = true) {
  std::string body;
  const auto put = [&](const void* v, std::size_t size) {
    while (body.size() % size != 0) body += '\0';
    std::string b(static_cast<const char*>(v), size);
    if (!little) std::reverse(b.begin(), b.end());
    body += b;
  };
  put(&m.sec, 4);
  put(&m.nsec, 4);
  const auto len = static_cast<std::uint32_t>(m.frame_id.size() + 1);
  put(&len, 4);
  body += m.frame_id;
  body += '\0';
  const auto doubles = [&](const double* v, int n) {
    for (int i = 0; i < n; ++i) put(&v[i], 8);
  };
  const auto covariance = [&](double c0) {
    std::array<double, 9> c{};
    c[0] = c0;
    doubles(c.data(), 9);
  };
  doubles(m.orientation.data(), 4);
  covariance(m.orientation_cov0);
  doubles(m.gyr.data(), 3);
  covariance(m.gyr_cov0);
  doubles(m.acc.data(), 3);
  covariance(m.acc_cov0);
  return std::string("\x00", 1) + (little ? '\x01' : '\x00') + std::string(2, '\0') + body;
}

template <typename T>
std::string Le(T v) {
  std::string out(sizeof v, '\0');
  std::memcpy(out.data(), &v, sizeof v);
  return out;
}
inline std::string McapString(const std::string& s) {
  return Le(static_cast<std::uint32_t>(s.size())) + s;
}
inline std::string McapRecord(std::uint8_t op, const std::string& content) {
  return std::string(1, static_cast<char>(op)) + Le(static_cast<std::uint64_t>(content.size())) +
         content;
}
inline const std::string kMcapMagic("\x89MCAP0\r\n", 8);

inline std::string McapHeader() { return McapRecord(0x01, McapString("ros2") + McapString("plumb test")); }
inline std::string McapFooter() {
  return McapRecord(0x02, Le(std::uint64_t{0}) + Le(std::uint64_t{0}) + Le(std::uint32_t{0}));
}
inline std::string McapSchema(std::uint16_t id, const std::string& name = "sensor_msgs/msg/Imu") {
  return McapRecord(0x03, Le(id) + McapString(name) + McapString("ros2msg") +
                              McapString("std_msgs/Header header\n..."));
}
inline std::string McapChannel(std::uint16_t id, std::uint16_t schema, const std::string& topic,
                               const std::string& encoding = "cdr") {
  return McapRecord(0x04, Le(id) + Le(schema) + McapString(topic) + McapString(encoding) +
                              Le(std::uint32_t{0}));
}
inline std::string McapMessage(std::uint16_t channel, std::uint64_t log_time_ns,
                               const std::string& data) {
  return McapRecord(0x05, Le(channel) + Le(std::uint32_t{0}) + Le(log_time_ns) +
                              Le(log_time_ns) + data);
}

/// The CRC-32 of `bytes` (Boost.CRC's: another implementation than the reader's libdeflate).
inline std::uint32_t Crc32(const std::string& bytes) {
  boost::crc_32_type crc;
  crc.process_bytes(bytes.data(), bytes.size());
  return static_cast<std::uint32_t>(crc.checksum());
}

/// A Chunk record of `records`, compressed with `compression` ("", "zstd", "lz4"), stating the
/// records' CRC-32 when `with_crc` (else 0, "not given").
inline std::string McapChunk(const std::string& records, const std::string& compression,
                             bool with_crc = false) {
  std::string data = records;
  if (compression == "zstd") {
    data.resize(ZSTD_compressBound(records.size()));
    data.resize(ZSTD_compress(data.data(), data.size(), records.data(), records.size(), 3));
  } else if (compression == "lz4") {
    data.resize(LZ4F_compressFrameBound(records.size(), nullptr));
    data.resize(LZ4F_compressFrame(data.data(), data.size(), records.data(), records.size(), nullptr));
  } else if (!compression.empty() && compression != "bogus") {
    throw std::runtime_error("McapChunk: " + compression);
  }
  return McapRecord(0x06, Le(std::uint64_t{0}) + Le(std::uint64_t{0}) +
                              Le(static_cast<std::uint64_t>(records.size())) +
                              Le(with_crc ? Crc32(records) : std::uint32_t{0}) +
                              McapString(compression) +
                              Le(static_cast<std::uint64_t>(data.size())) + data);
}

/// A .db3 bag at `path`: `topics` (id, name, type, serialization_format) and `messages`
/// (topic_id, timestamp ns, data), in rosbag2's schema.
struct Db3Topic {
  int id;
  std::string name;
  std::string type;
  std::string format = "cdr";
};
struct Db3Message {
  int topic_id;
  std::int64_t timestamp;
  std::string data;
};
inline void Db3Exec(sqlite3* db, const std::string& sql) {
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) {
    throw std::runtime_error("WriteDb3: " + std::string(sqlite3_errmsg(db)));
  }
}

/// rosbag2's two tables and `topics`.
inline void Db3Tables(sqlite3* db, const std::vector<Db3Topic>& topics) {
  Db3Exec(db, "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT "
              "NULL, serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)");
  Db3Exec(db, "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
              "timestamp INTEGER NOT NULL, data BLOB NOT NULL)");
  for (const Db3Topic& t : topics) {
    Db3Exec(db, "INSERT INTO topics VALUES (" + std::to_string(t.id) + ", '" + t.name + "', '" +
                    t.type + "', '" + t.format + "', '')");
  }
}

/// `messages` [begin, end) inserted, one transaction each (as a recorder writes them).
inline void Db3Insert(sqlite3* db, const std::vector<Db3Message>& messages, std::size_t begin,
                      std::size_t end) {
  sqlite3_stmt* s = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", -1,
                     &s, nullptr);
  for (std::size_t i = begin; i < end && i < messages.size(); ++i) {
    const Db3Message& m = messages[i];
    sqlite3_bind_int(s, 1, m.topic_id);
    sqlite3_bind_int64(s, 2, m.timestamp);
    sqlite3_bind_blob(s, 3, m.data.data(), static_cast<int>(m.data.size()), SQLITE_TRANSIENT);
    sqlite3_step(s);
    sqlite3_reset(s);
  }
  sqlite3_finalize(s);
}

inline void WriteDb3(const std::string& path, const std::vector<Db3Topic>& topics,
                     const std::vector<Db3Message>& messages, bool with_tables = true) {
  std::remove(path.c_str());
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) throw std::runtime_error("WriteDb3: open");
  if (!with_tables) {
    Db3Exec(db, "CREATE TABLE other(x INTEGER)");
    sqlite3_close(db);
    return;
  }
  Db3Tables(db, topics);
  Db3Insert(db, messages, 0, messages.size());
  sqlite3_close(db);
}

/// The bag `path` and its `path`-wal as a recorder in WAL mode leaves them when it dies: the
/// tables and the first `checkpointed` messages checkpointed into the bag (none, with the
/// tables too, when 0), the others only in the -wal file. Written in `scratch` (a file name
/// in another folder) and copied while its connection is open (closing it would checkpoint).
inline void WriteUnclosedDb3(const std::string& path, const std::string& scratch,
                             const std::vector<Db3Topic>& topics,
                             const std::vector<Db3Message>& messages, std::size_t checkpointed) {
  std::remove(scratch.c_str());
  sqlite3* db = nullptr;
  if (sqlite3_open(scratch.c_str(), &db) != SQLITE_OK) throw std::runtime_error("open");
  Db3Exec(db, "PRAGMA journal_mode=WAL");
  Db3Exec(db, "PRAGMA wal_autocheckpoint=0");
  Db3Tables(db, topics);
  if (checkpointed > 0) {
    Db3Insert(db, messages, 0, checkpointed);
    Db3Exec(db, "PRAGMA wal_checkpoint(TRUNCATE)");
  }
  Db3Insert(db, messages, checkpointed, messages.size());
  std::filesystem::copy_file(scratch, path, std::filesystem::copy_options::overwrite_existing);
  std::filesystem::copy_file(scratch + "-wal", path + "-wal",
                             std::filesystem::copy_options::overwrite_existing);
  sqlite3_close(db);
  std::remove(scratch.c_str());
}

}  // namespace plumb::test

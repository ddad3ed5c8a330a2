// plumb/io/ros/rosbag.h — ROS 1 bags (format 2.0) holding sensor_msgs/Imu messages.
//
// Decision: plumb reads bags with its own reader rather than Debian's librosbag-storage-dev.
// That library pulls roscpp_serialization, console_bridge and Boost into every user of plumb,
// throws generic exceptions that name neither the file nor the byte offset (SPEC 8 asks for
// both), and its speed is not under our control (SPEC 7: 1 GB/s uncompressed). What plumb
// needs of a bag is small and fixed: the record framing, bz2 and lz4 chunks, connections, and
// the serialization of one message type, sensor_msgs/Imu, whose layout has not changed since
// ROS 1 began (md5sum 6a62c6daae103f4ff57a132d6f95cec2).
//
// Format (ROS "Bag Format 2.0", little endian): the line "#ROSBAG V2.0\n", then records, each
//   uint32 header_len, header (fields: uint32 field_len, "name=value", value binary),
//   uint32 data_len, data.
// The header's "op" field (1 byte) gives the record's kind:
//   0x03 bag header: index_pos (uint64; 0 when the bag was never indexed), conn_count,
//        chunk_count (uint32); data is padding.
//   0x05 chunk: compression ("none", "bz2", "lz4": the LZ4 *frame* format), size (uint32, the
//        uncompressed size); data: the (compressed) records 0x02 and 0x07.
//   0x07 connection: conn (uint32), topic; data: more header-style fields: type, md5sum,
//        message_definition, optional callerid and latching.
//   0x02 message data: conn (uint32), time (uint32 sec, uint32 nsec: the time the recorder
//        received the message); data: the message's ROS serialization.
//   0x04 index data, 0x06 chunk info: the index; read past.
// sensor_msgs/Imu's serialization: Header {uint32 seq, uint32 sec, uint32 nsec, string
// frame_id (uint32 length + bytes)}, orientation (4 float64 x y z w), its covariance (9
// float64), angular_velocity (3 float64, rad/s), its covariance (9), linear_acceleration (3
// float64, m/s^2), its covariance (9): 16 + frame_id length + 296 bytes.
//
// Decoding contract (one pass over the file held in memory):
//  * The bag is read linearly, record by record, chunk by chunk; the index is not needed (a
//    bag cut short or never reindexed has none) and not trusted. Connections are collected
//    wherever they are, inside chunks and in the index section; a message whose connection
//    is defined only later is kept aside and decoded once the whole bag is read.
//  * A connection is an IMU connection when its type is "sensor_msgs/Imu". A different md5sum
//    is said in a warning and its messages are decoded when their size fits the layout above;
//    a message whose size does not fit is skipped (counted).
//  * Every length is checked against what holds it. A record cut by the end of the file ends
//    the reading: the whole records before it are kept, and a cut chunk's whole records too
//    (its compressed bytes decoded as far as they go); the warnings give the byte offset and
//    the counts. A record whose header does not parse but whose lengths fit is skipped
//    (counted); inside a chunk, a record whose length runs past the chunk's end ends that
//    chunk (counted), and reading goes on with the next record of the file. A chunk that does
//    not decompress, of an unknown compression, or whose data exceeds its stated size keeps
//    the records decoded before the fault (counted); one stating more than 1 GiB uncompressed
//    is skipped (counted). The output buffer grows as data comes out, never ahead of it.
//  * A file without the magic, of another bag version (1.2), or whose first record is not a
//    bag header is refused: plumb::InputError naming the file and the byte.
//  * Values are kept as logged: SI (m/s^2, rad/s) in the message's frame (REP-103: x forward,
//    y left, z up, FLU). orientation and the covariances are not used for calibration; a
//    covariance whose element 0 is -1 ("not given" by REP convention) is counted, and a topic
//    whose every angular_velocity_covariance[0] is -1 has no gyroscope.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/jobs.h"

namespace plumb::io {

/// sensor_msgs/Imu's md5sum, as every ROS 1 distribution defines it.
inline constexpr const char* kRosImuMd5 = "6a62c6daae103f4ff57a132d6f95cec2";

/// One connection (a topic as one publisher's recording of it).
struct RosConnection {
  std::uint32_t id = 0;       ///< conn
  std::string topic;          ///< e.g. "/imu/data_raw"
  std::string type;           ///< e.g. "sensor_msgs/Imu"
  std::string md5sum;         ///< of the type
  std::string callerid;       ///< publisher node, when given
  bool latching = false;
  std::size_t messages = 0;   ///< message data records read
};

/// The samples of one sensor_msgs/Imu topic (all its connections), in record order.
struct RosImuTopic {
  std::string topic;
  std::string frame_id;          ///< the first message's header.frame_id (a leading '/' kept)
  /// t_s: header.stamp (sec + nsec * 1e-9, s since the unix epoch); acc: linear_acceleration,
  /// gyr: angular_velocity, both as logged (float). Every decoded message, in record order.
  ImuSeries samples;
  std::vector<double> receive_s;  ///< the records' times (the recorder's), s, one per sample
  std::size_t malformed = 0;      ///< messages whose size does not fit the layout, skipped
  std::size_t acc_not_given = 0;  ///< linear_acceleration_covariance[0] == -1
  std::size_t gyr_not_given = 0;  ///< angular_velocity_covariance[0] == -1
  std::size_t orientation_not_given = 0;  ///< orientation_covariance[0] == -1
  std::size_t orientation_zero = 0;       ///< orientation all zeros (not a quaternion)
  bool md5_differs = false;       ///< a connection's md5sum is not kRosImuMd5
};

/// What the reader skipped or repaired, with counts and the first byte offset of each kind.
struct RosBagWarnings {
  /// Set when a record runs past the end of the file: its offset.
  std::optional<std::size_t> cut_at;
  std::size_t cut_messages_kept = 0;     ///< messages of a cut chunk kept (whole records)
  std::size_t messages_read = 0;         ///< with cut_at: the messages read (all topics)
  /// Set when every record is whole but the bag header's index_pos lies past the end (the
  /// file cut at a record boundary; cut_at is then the file size): that index_pos.
  std::uint64_t index_past_end = 0;
  std::size_t bad_records = 0;           ///< records whose header does not parse, skipped
  std::size_t first_bad_record = 0;
  std::size_t damaged_chunks = 0;        ///< chunks not decoded to their end
  std::size_t first_damaged_chunk = 0;   ///< file offset of the first
  std::string first_damage;              ///< what was wrong with it
  std::size_t unknown_ops = 0;           ///< records of an unknown op, skipped
  std::size_t orphan_messages = 0;       ///< messages of a connection never defined
  std::size_t first_orphan = 0;          ///< file offset of the first (its chunk's)
  std::size_t malformed_imu = 0;         ///< sensor_msgs/Imu messages whose size does not fit
  std::size_t first_malformed_imu = 0;   ///< file offset of the first (its chunk's)
  /// ROS 2 (CDR): where the first did not decode ("message at byte N: byte K: ..."); empty
  /// for ROS 1, whose messages are judged by size.
  std::string first_malformed_why;
  std::vector<std::string> md5_notes;    ///< IMU connections with another md5sum
  /// Other lines, one per finding (ROS 2 readers: an IMU topic of another serialization, a
  /// file that ends without its footer, a table that stopped reading).
  std::vector<std::string> notes;

  bool any() const;
  /// One readable line per non-zero count.
  std::vector<std::string> Describe() const;
};

/// The file formats a RosBag is read from.
enum class RosBagKind {
  kRos1,     ///< ROS 1 .bag (this file), format "ros1-bag"
  kMcap,     ///< ROS 2 MCAP .mcap (mcap.h), format "ros2-mcap"
  kSqlite3,  ///< ROS 2 sqlite3 .db3 (db3.h), format "ros2-db3"
};

/// A decoded ROS bag: ROS 1 (this file's reader), or ROS 2 (mcap.h, db3.h: the same
/// intermediate, so that one session builder, ros_session.h, serves them all).
struct RosBag {
  RosBagKind kind = RosBagKind::kRos1;
  std::string source;               ///< file name (or the name given to ParseRosBag)
  std::size_t size_bytes = 0;
  std::uint64_t index_pos = 0;      ///< the bag header's; 0: never indexed
  /// Chunk records read (MCAP: Chunk records; .db3: 0).
  std::size_t chunks = 0;
  std::map<std::string, std::size_t> compression;  ///< chunks by compression
  std::size_t chunk_infos = 0;      ///< chunk info records (the index) seen (MCAP: ChunkIndex)
  /// By conn id (MCAP: the channels by channel id, type its schema's name; .db3: the topics
  /// table by id).
  std::map<std::uint32_t, RosConnection> connections;
  std::vector<RosImuTopic> imu_topics;  ///< sensor_msgs/Imu topics, in order of first connection
  std::size_t messages = 0;         ///< message data records read (all topics)
  RosBagWarnings warnings;

  /// The IMU topic called `topic`, or nullptr.
  const RosImuTopic* Find(const std::string& topic) const;
  /// ("topic (type)", message count) per topic, in order of first connection.
  std::vector<std::pair<std::string, std::size_t>> MessageCounts() const;
};

/// Reads and decodes a .bag file (see the file comment). Throws plumb::InputError(path,
/// "byte N", what) when the file cannot be read or is not a ROS 1 bag 2.0. `run_jobs`: a bag's
/// chunks are decompressed ahead of their parse through it (the same bag either way); empty:
/// on the calling thread alone.
RosBag ReadRosBag(const std::string& path, const JobRunner& run_jobs = {});

/// Decodes a bag held in memory; `source` names it in errors. Same contract as ReadRosBag.
RosBag ParseRosBag(const std::uint8_t* data, std::size_t size, const std::string& source);

/// True when the file starts with "#ROSBAG V" (any version: another one is then refused by
/// name rather than taken for a text table).
bool LooksLikeRosBag(const std::string& path);

}  // namespace plumb::io

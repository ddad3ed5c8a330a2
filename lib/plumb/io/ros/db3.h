// plumb/io/ros/db3.h — ROS 2 bags in sqlite3 (.db3, rosbag2's storage before Iron) holding
// sensor_msgs/msg/Imu messages, read into the same RosBag as a ROS 1 bag (rosbag.h).
//
// Format (rosbag2_storage_sqlite3): an SQLite 3 database (its first 16 bytes "SQLite format
// 3\0") with the tables topics(id, name, type, serialization_format, ...) and messages(id,
// topic_id, timestamp, data): timestamp is when the recorder received the message (ns since
// the unix epoch), data the message's serialization (CDR for serialization_format "cdr").
//
// Decoding contract:
//  * The database is opened read-only and immutable (SQLITE_OPEN_READONLY, the URI parameter
//    immutable=1): sqlite3 then never writes a -journal, -wal or -shm file beside it nor takes
//    a lock, and the input is never modified.
//  * A bag whose recorder did not close it (killed, crashed, power lost) may have messages in
//    its -wal file (name.db3-wal beside it) not yet checkpointed into it; immutable reading
//    would not see them. When that file holds frames (more than its 32-byte header), the bag
//    and its -wal file are copied into a folder plumb makes in the temporary directory and
//    read there as a live database (read-only; sqlite3 makes its -shm file there), the copies
//    and the folder removed after: every message is read, nothing is written beside the
//    input, and a warning names the -wal file. LooksLikeDb3 takes such a bag for one without
//    looking for its tables (they may be in the -wal file only).
//  * The topics are read from `topics` (RosBag::connections by id, type as given); a topic is
//    an IMU topic when its type is "sensor_msgs/msg/Imu" and its serialization_format "cdr".
//    The messages are read in the order of their id (the order recorded), each IMU message
//    decoded by ros_imu.h's DecodeCdrImu; one that does not decode is skipped (counted, named
//    by its id). A message of a topic id not in `topics` is counted as an orphan.
//  * A file that is not SQLite, lacks the two tables or their columns, or whose topics do not
//    read is refused: plumb::InputError naming the file and what sqlite3 said. When the
//    messages stop reading part way (a damaged or cut database), the messages read before are
//    kept with a warning naming the last message id read.
//  * Values as logged (FLU, SI); times: header.stamp, and the timestamp as the receive time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "plumb/io/ros/rosbag.h"

namespace plumb::io {

/// Reads a .db3 bag (see the file comment): RosBag with kind kSqlite3. Throws
/// plumb::InputError naming the file when it cannot be read or is not a ROS 2 sqlite3 bag.
RosBag ReadDb3(const std::string& path);

/// Decodes a .db3 bag held in memory (sqlite3_deserialize, read-only); `source` names it in
/// errors. Same contract as ReadDb3.
RosBag ParseDb3(const std::uint8_t* data, std::size_t size, const std::string& source);

/// True when the file starts with "SQLite format 3\0" and has the tables topics and messages.
bool LooksLikeDb3(const std::string& path);

}  // namespace plumb::io

// plumb/io/ros/mcap.h — ROS 2 bags in MCAP (.mcap, rosbag2's default storage since Iron)
// holding sensor_msgs/msg/Imu messages, read into the same RosBag as a ROS 1 bag (rosbag.h),
// so that the session builder (ros_session.h) serves both.
//
// Format (https://mcap.dev/spec, version "0", little endian): the magic 0x89 "MCAP" "0" "\r\n",
// then records, each uint8 opcode, uint64 length, content; strings are uint32 length + bytes,
// byte arrays uint32 (Schema) or uint64 (Chunk) length + bytes. The records plumb uses:
//   0x01 Header: profile, library (the first record).
//   0x02 Footer: the end of the records (the magic follows).
//   0x03 Schema: uint16 id, name ("sensor_msgs/msg/Imu"), encoding ("ros2msg"), data.
//   0x04 Channel: uint16 id, uint16 schema_id, topic, message_encoding ("cdr"), metadata.
//   0x05 Message: uint16 channel_id, uint32 sequence, uint64 log_time (ns, when the recorder
//        received it), uint64 publish_time, data (the rest: the CDR serialization).
//   0x06 Chunk: uint64 message_start_time, message_end_time, uncompressed_size, uint32
//        uncompressed_crc, compression ("" none, "zstd", "lz4": the LZ4 frame format), records
//        (Schema, Channel and Message records, compressed).
//   0x08 ChunkIndex: counted (the summary's index). Every other record (MessageIndex,
//        Attachment, Statistics, Metadata, SummaryOffset, DataEnd, ...; unknown opcodes too)
//        is read past.
//
// Decoding contract (one pass over the file held in memory, as the ROS 1 reader's):
//  * Given a JobRunner (core/jobs.h; the library starts no thread), a file of 64 chunks or more
//    has its chunks decompressed and CRC-checked up to three ahead of their parse (io/ros/
//    read_ahead.h): two jobs run through the runner once, each taking the next task, the parse
//    of the next chunk's records in file order or the opening of a chunk ahead; all else as
//    below: the same samples, warnings and errors (the first in file order) as read on one
//    thread, which smaller files and an empty runner are.
//  * The records are read linearly, chunk by chunk, up to the Footer; the summary section is
//    read like the data (its Schema and Channel records repeat those already known) and never
//    needed, so a file cut short gives the messages before the cut: the record at the cut and
//    a cut chunk's whole records are kept as far as the bytes go, with a warning naming the
//    byte offset and the counts (RosBagWarnings::cut_at). A file that ends at a record
//    boundary without its Footer says so in a warning.
//  * A channel is an IMU channel when its schema's name is "sensor_msgs/msg/Imu" and its
//    message_encoding "cdr"; the messages are decoded by ros_imu.h's DecodeCdrImu, and one
//    that does not decode is skipped (counted, with its byte offset and what was wrong). A
//    sensor_msgs/msg/Imu channel of another encoding is said in a warning, its messages
//    counted but not decoded.
//  * Lengths are checked against what holds them: a record whose fields run past its content
//    is skipped (counted); inside a chunk, a record running past the chunk's records ends that
//    chunk (counted). A chunk that does not decompress, of an unknown compression, of another
//    size than stated, or stating more than 1 GiB, keeps the records decoded before the fault
//    (counted). A message of a channel not defined before it is counted as an orphan.
//  * A chunk stating its uncompressed_crc (not 0) whose records, whole and decompressed, have
//    another CRC-32 is refused: plumb::InputError naming the file and the chunk's byte offset
//    (a damaged byte there could be a wrong value in a message that still decodes). A chunk cut
//    by the end of the file or not decompressed to its size is not checked (the damage is
//    said as above).
//  * A file without the magic, of another MCAP version, or whose first record is not a Header
//    is refused: plumb::InputError naming the file and the byte.
//  * Values as logged (FLU, SI), times as the ROS 1 reader's: header.stamp, and log_time as the
//    receive time (RosImuTopic::receive_s).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "plumb/core/jobs.h"
#include "plumb/io/ros/rosbag.h"

namespace plumb::io {

/// Reads and decodes a .mcap file (see the file comment): RosBag with kind kMcap. Throws
/// plumb::InputError(path, "byte N", what) when the file cannot be read or is not an MCAP
/// file of version 0. `run_jobs`: a large file's chunks are decompressed ahead of their parse
/// through it (the same bag either way); empty: on the calling thread alone.
RosBag ReadMcap(const std::string& path, const JobRunner& run_jobs = {});

/// Decodes an MCAP file held in memory; `source` names it in errors. Same contract.
RosBag ParseMcap(const std::uint8_t* data, std::size_t size, const std::string& source);

/// True when the file starts with 0x89 "MCAP" (any version: another one is then refused by
/// name).
bool LooksLikeMcap(const std::string& path);

}  // namespace plumb::io

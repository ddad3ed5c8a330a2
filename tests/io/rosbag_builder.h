// A tiny ROS 1 bag 2.0 writer for the reader's tests (tests/io/rosbag_test.cc): records, chunks
// (none, bz2, lz4 frame), connections, sensor_msgs/Imu messages and an index section, byte for
// byte as rosbag writes them (io/ros/rosbag.h has the format).
#pragma once

#include <bzlib.h>
#include <lz4frame.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace plumb::test {

/// `v` as its little-endian bytes.
template <typename T>
std::string Bytes(T v) {
  std::string out(sizeof v, '\0');
  std::memcpy(out.data(), &v, sizeof v);
  return out;
}

/// One header field: uint32 length, "name=value".
inline std::string RosField(const std::string& name, const std::string& value) {
  return Bytes(static_cast<std::uint32_t>(name.size() + 1 + value.size())) + name + "=" + value;
}

/// A record: uint32 header length, header, uint32 data length, data.
inline std::string RosRecord(const std::string& header, const std::string& data) {
  return Bytes(static_cast<std::uint32_t>(header.size())) + header +
         Bytes(static_cast<std::uint32_t>(data.size())) + data;
}

inline std::string RosOpField(std::uint8_t op) { return RosField("op", std::string(1, char(op))); }

/// The time field: uint32 sec, uint32 nsec.
inline std::string RosTime(std::uint32_t sec, std::uint32_t nsec) {
  return Bytes(sec) + Bytes(nsec);
}

inline const char* kImuMd5 = "6a62c6daae103f4ff57a132d6f95cec2";

/// A connection record of `topic` with `type` and `md5`.
inline std::string RosConnectionRecord(std::uint32_t conn, const std::string& topic,
                                       const std::string& type = "sensor_msgs/Imu",
                                       const std::string& md5 = kImuMd5) {
  const std::string header = RosOpField(0x07) + RosField("conn", Bytes(conn)) + RosField("topic", topic);
  const std::string data = RosField("topic", topic) + RosField("type", type) +
                           RosField("md5sum", md5) +
                           RosField("message_definition", "# see sensor_msgs/Imu") +
                           RosField("callerid", "/test_node");
  return RosRecord(header, data);
}

/// A message data record of connection `conn` received at sec.nsec.
inline std::string RosMessageRecord(std::uint32_t conn, std::uint32_t sec, std::uint32_t nsec,
                                    const std::string& data) {
  const std::string header = RosOpField(0x02) + RosField("conn", Bytes(conn)) +
                             RosField("time", RosTime(sec, nsec));
  return RosRecord(header, data);
}

/// sensor_msgs/Imu serialized. cov0 values: the first element of each covariance (-1 = not
/// given); orientation all zeros when `zero_orientation`.
inline std::string RosImuMessage(std::uint32_t seq, std::uint32_t sec, std::uint32_t nsec,
                                 const std::string& frame_id, const std::array<double, 3>& acc,
                                 const std::array<double, 3>& gyr, double gyr_cov0 = 0.0,
                                 double acc_cov0 = 0.0, bool zero_orientation = false) {
  std::string out = Bytes(seq) + Bytes(sec) + Bytes(nsec) +
                    Bytes(static_cast<std::uint32_t>(frame_id.size())) + frame_id;
  const double q[4] = {0.0, 0.0, 0.0, zero_orientation ? 0.0 : 1.0};
  for (double v : q) out += Bytes(v);
  for (int i = 0; i < 9; ++i) out += Bytes(i == 0 ? -1.0 : 0.0);
  for (double v : gyr) out += Bytes(v);
  for (int i = 0; i < 9; ++i) out += Bytes(i == 0 ? gyr_cov0 : 0.0);
  for (double v : acc) out += Bytes(v);
  for (int i = 0; i < 9; ++i) out += Bytes(i == 0 ? acc_cov0 : 0.0);
  return out;
}

inline std::string Bz2Compress(const std::string& in) {
  std::vector<char> out(in.size() + in.size() / 100 + 700);
  unsigned n = static_cast<unsigned>(out.size());
  if (BZ2_bzBuffToBuffCompress(out.data(), &n, const_cast<char*>(in.data()),
                               static_cast<unsigned>(in.size()), 9, 0, 30) != BZ_OK) {
    throw std::runtime_error("bz2 compression failed");
  }
  return std::string(out.data(), n);
}

inline std::string Lz4FrameCompress(const std::string& in) {
  std::vector<char> out(LZ4F_compressFrameBound(in.size(), nullptr));
  const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr);
  if (LZ4F_isError(n)) throw std::runtime_error("lz4 compression failed");
  return std::string(out.data(), n);
}

/// A chunk record holding `records`, compressed with `compression` ("none", "bz2", "lz4").
inline std::string RosChunkRecord(const std::string& compression, const std::string& records) {
  const std::string data = compression == "bz2"   ? Bz2Compress(records)
                           : compression == "lz4" ? Lz4FrameCompress(records)
                                                  : records;
  const std::string header = RosOpField(0x05) + RosField("compression", compression) +
                             RosField("size", Bytes(static_cast<std::uint32_t>(records.size())));
  return RosRecord(header, data);
}

/// The magic and a bag header record (index_pos 0 unless given), padded as rosbag pads it.
inline std::string RosBagStart(std::uint64_t index_pos = 0, std::uint32_t conns = 0,
                               std::uint32_t chunks = 0) {
  const std::string header = RosOpField(0x03) + RosField("index_pos", Bytes(index_pos)) +
                             RosField("conn_count", Bytes(conns)) +
                             RosField("chunk_count", Bytes(chunks));
  return "#ROSBAG V2.0\n" + RosRecord(header, std::string(64, ' '));
}

/// An index data record and a chunk info record (the reader reads past them).
inline std::string RosIndexRecords(std::uint32_t conn, std::uint64_t chunk_pos) {
  const std::string index = RosRecord(RosOpField(0x04) + RosField("ver", Bytes(std::uint32_t{1})) +
                                          RosField("conn", Bytes(conn)) +
                                          RosField("count", Bytes(std::uint32_t{0})),
                                      "");
  const std::string info_header = RosOpField(0x06) + RosField("ver", Bytes(std::uint32_t{1})) +
                                  RosField("chunk_pos", Bytes(chunk_pos)) +
                                  RosField("start_time", RosTime(0, 0)) +
                                  RosField("end_time", RosTime(0, 0)) +
                                  RosField("count", Bytes(std::uint32_t{1}));
  return index + RosRecord(info_header, Bytes(conn) + Bytes(std::uint32_t{1}));
}

}  // namespace plumb::test

// plumb/io/ros/rosbag_format.h — the pieces of a ROS 1 bag 2.0 (rosbag.h has the format): a
// record header's fields, a connection's data, a chunk's decompression and the
// sensor_msgs/Imu serialization (ROS 1's; the MCAP reader shares the chunks' decompression).
// Internal to the reader; every length is checked against the bytes that hold it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "plumb/core/types.h"
#include "plumb/io/ros/ros_imu.h"
#include "plumb/io/ros/rosbag.h"

struct ZSTD_DCtx_s;  // zstd.h's ZSTD_DCtx
struct LZ4F_dctx_s;  // lz4frame.h's LZ4F_dctx

namespace plumb::io::detail {

/// The bag's first line.
inline constexpr char kRosBagMagic[] = "#ROSBAG V2.0\n";
inline constexpr std::size_t kRosBagMagicSize = sizeof(kRosBagMagic) - 1;
/// What every bag's first line starts with, whatever its version.
inline constexpr char kRosBagPrefix[] = "#ROSBAG V";
inline constexpr std::size_t kRosBagPrefixSize = sizeof(kRosBagPrefix) - 1;

/// The largest uncompressed chunk read, bytes (1 GiB): rosbag closes a chunk past 768 KiB
/// (its default chunk threshold) or after one large message, so a larger stated size is a
/// damaged field or a decompression bomb, not a bag; such a chunk is skipped (counted).
inline constexpr std::uint32_t kRosMaxChunkBytes = std::uint32_t{1} << 30;

/// The record ops.
enum RosOp : std::uint8_t {
  kOpMessageData = 0x02,
  kOpBagHeader = 0x03,
  kOpIndexData = 0x04,
  kOpChunk = 0x05,
  kOpChunkInfo = 0x06,
  kOpConnection = 0x07,
};

/// The fields of a record header the reader uses (others are read past).
struct RosRecordFields {
  bool has_op = false;
  std::uint8_t op = 0;
  bool has_conn = false;
  std::uint32_t conn = 0;
  bool has_time = false;
  std::uint32_t sec = 0;
  std::uint32_t nsec = 0;
  std::string_view topic;
  bool has_topic = false;
  std::string_view compression;
  bool has_size = false;
  std::uint32_t size = 0;   ///< a chunk's uncompressed size
  std::uint64_t index_pos = 0;
};

/// Parses the header [p, p + n) into `out`. False when a field's length runs past the header,
/// a field has no '=', or a known field has the wrong size; `why` then says which.
bool ParseRecordFields(const std::uint8_t* p, std::size_t n, RosRecordFields* out,
                       std::string* why);

/// Parses a connection record's data (type, md5sum, callerid, latching) into `c`. False, with
/// `why`, when a field's length runs past the data or has no '='.
bool ParseConnectionData(const std::uint8_t* p, std::size_t n, RosConnection* c,
                         std::string* why);

/// What a reader keeps from chunk to chunk: the buffer the chunks decompress into (grown as
/// data comes out, never shrunk) and libzstd's and liblz4's decompression contexts (made at
/// their first chunk, reused: a context's making and its tables' setting up cost as much as a
/// small chunk's decompression).
class ChunkBuffers {
 public:
  ChunkBuffers() = default;
  ~ChunkBuffers();
  ChunkBuffers(const ChunkBuffers&) = delete;
  ChunkBuffers& operator=(const ChunkBuffers&) = delete;

  std::vector<std::uint8_t> out;
  ZSTD_DCtx_s* zstd = nullptr;
  LZ4F_dctx_s* lz4 = nullptr;
};

/// Decompresses a chunk's data [in, in + n) of `compression` ("none", "bz2", "lz4" (the LZ4
/// frame format), "zstd" (MCAP's; a zstd frame), as liblz4 and libzstd decode them) into the
/// first `*out_size` bytes of `buffers->out`, reused from chunk to chunk: grown as data comes
/// out (never ahead of it, never past `declared` + 1 bytes; an LZ4 frame whose blocks are
/// larger than that is given room for one block, 4 MiB at most, so that liblz4 decodes it
/// without a copy), never shrunk. True when the data decompressed to its end and to exactly
/// `declared` bytes; false with `why` otherwise, the buffer then holding what came out before
/// the fault (the records there are still whole: a caller reads them). `cut`: the data was cut
/// by the end of the file (the fault expected; `why` says where it ended).
bool DecompressChunk(std::string_view compression, const std::uint8_t* in, std::size_t n,
                     std::uint32_t declared, bool cut, ChunkBuffers* buffers,
                     std::size_t* out_size, std::string* why);

/// A chunk's records as a reader walks them.
struct ChunkBody {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  bool whole = true;  ///< all `declared` bytes are there; else `why` says what is not
  std::string why;
};

/// The records of a chunk whose data is [in, in + n): as stored for `compression` "none" or
/// empty (cut to `declared` bytes), else decompressed into `buffers` (DecompressChunk). The
/// ROS 1 and MCAP readers' chunks alike.
ChunkBody OpenChunk(std::string_view compression, const std::uint8_t* in, std::size_t n,
                    std::uint32_t declared, bool cut, ChunkBuffers* buffers);

/// The CRC-32 (ISO-HDLC: zlib's, gzip's, MCAP's) of [p, p + n), by libdeflate.
std::uint32_t Crc32(const std::uint8_t* p, std::size_t n);

/// Bytes of a sensor_msgs/Imu message past its frame_id.
inline constexpr std::size_t kRosImuFixedBytes = 37 * 8;

/// Decodes a sensor_msgs/Imu message [p, p + n). False when its size is not 16 + frame_id
/// length + kRosImuFixedBytes. Inline: the reader calls it once per message.
inline bool DecodeRosImu(const std::uint8_t* p, std::size_t n, RosImuMessage* out) {
  if (n < 16) return false;
  out->sec = LoadLittleEndian<std::uint32_t>(p + 4);
  out->nsec = LoadLittleEndian<std::uint32_t>(p + 8);
  const std::uint32_t len = LoadLittleEndian<std::uint32_t>(p + 12);
  if (len > n - 16 || n - 16 - len != kRosImuFixedBytes) return false;
  out->frame_id = std::string_view(reinterpret_cast<const char*>(p + 16), len);
  const std::uint8_t* d = p + 16 + len;
  const auto f = [d](int i) { return LoadLittleEndian<double>(d + 8 * i); };
  for (int i = 0; i < 4; ++i) out->orientation[i] = f(i);
  out->orientation_cov0 = f(4);
  out->gyr = Vec3(f(13), f(14), f(15));
  out->gyr_cov0 = f(16);
  out->acc = Vec3(f(25), f(26), f(27));
  out->acc_cov0 = f(28);
  return true;
}

}  // namespace plumb::io::detail

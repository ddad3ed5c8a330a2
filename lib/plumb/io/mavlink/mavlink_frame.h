// plumb/io/mavlink/mavlink_frame.h — INTERNAL to plumb::io_mavlink: the tlog record and the
// MAVLink frame in it (see mavlink_tlog.h for the format): the layout constants, the X.25 CRC,
// and whether a record starts at a position (ExamineTlogRecord), inline for the scan of
// mavlink_tlog.cc, which examines every position it meets. Not part of the public interface.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "plumb/io/common/log_common.h"
#include "plumb/io/mavlink/mavlink_dialect.h"

namespace plumb::io::detail {

inline constexpr std::uint8_t kMavlinkStxV1 = 0xFE;
inline constexpr std::uint8_t kMavlinkStxV2 = 0xFD;
inline constexpr std::size_t kTlogTimeBytes = 8;  // big-endian uint64 µs before every frame
// Frame headers: v1 STX len seq sys comp msgid; v2 STX len incompat compat seq sys comp
// msgid[3].
inline constexpr std::size_t kMavlinkHeaderV1 = 6;
inline constexpr std::size_t kMavlinkHeaderV2 = 10;
inline constexpr std::size_t kMavlinkCrcBytes = 2;
inline constexpr std::size_t kMavlinkSignatureBytes = 13;
inline constexpr std::uint8_t kMavlinkIncompatSigned = 0x01;
// Plausible tlog times: 2000-01-01 and 2100-01-01 in µs since the unix epoch.
inline constexpr std::uint64_t kTlogMinTimeUs = 946684800ull * 1000000ull;
inline constexpr std::uint64_t kTlogMaxTimeUs = 4102444800ull * 1000000ull;
inline constexpr std::size_t kMavlinkMaxPayload = 255;

/// CRC-16/MCRF4XX tables (reflected polynomial 0x8408) for slicing by 8, built once.
/// t[0] is the classic byte table: crc' = (crc >> 8) ^ t[0][(crc ^ byte) & 0xFF]. t[k][v] is
/// the contribution of byte value v followed by k zero bytes, t[k][v] = (t[k-1][v] >> 8) ^
/// t[0][t[k-1][v] & 0xFF], so that 8 bytes b0..b7 advance the 16-bit state c as
///   c' = t[7][(c ^ b0) & 0xFF] ^ t[6][((c >> 8) ^ b1) & 0xFF] ^ t[5][b2] ^ ... ^ t[0][b7]
/// (the CRC is linear over GF(2); the state holds only two bytes).
struct MavlinkCrcTable {
  std::array<std::array<std::uint16_t, 256>, 8> t{};
  MavlinkCrcTable();
};
extern const MavlinkCrcTable kMavlinkCrcTable;  // mavlink_frame.cc

/// One byte into the CRC state.
inline std::uint16_t MavlinkCrcByte(std::uint16_t crc, std::uint8_t byte) {
  return static_cast<std::uint16_t>((crc >> 8) ^ kMavlinkCrcTable.t[0][(crc ^ byte) & 0xFFu]);
}

/// X.25 CRC of `size` bytes from state `crc`, sliced by 8 (see MavlinkCrcTable). Each step is
/// one link of a chain of dependent lookups, so the last 0-7 bytes go in at most three (slices
/// of 4, 2 and 1 bytes) instead of one per byte: frames are short (a RAW_IMU's CRC covers 31).
inline std::uint16_t MavlinkX25Crc(const std::uint8_t* data, std::size_t size, std::uint16_t crc) {
  const auto& t = kMavlinkCrcTable.t;
  std::size_t k = 0;
  for (; k + 8 <= size; k += 8) {
    const std::uint8_t* b = data + k;
    crc = static_cast<std::uint16_t>(
        t[7][(crc ^ b[0]) & 0xFFu] ^ t[6][((crc >> 8) ^ b[1]) & 0xFFu] ^ t[5][b[2]] ^
        t[4][b[3]] ^ t[3][b[4]] ^ t[2][b[5]] ^ t[1][b[6]] ^ t[0][b[7]]);
  }
  if (size - k >= 4) {
    const std::uint8_t* b = data + k;
    crc = static_cast<std::uint16_t>(t[3][(crc ^ b[0]) & 0xFFu] ^
                                     t[2][((crc >> 8) ^ b[1]) & 0xFFu] ^ t[1][b[2]] ^ t[0][b[3]]);
    k += 4;
  }
  if (size - k >= 2) {
    const std::uint8_t* b = data + k;
    crc = static_cast<std::uint16_t>(t[1][(crc ^ b[0]) & 0xFFu] ^
                                     t[0][((crc >> 8) ^ b[1]) & 0xFFu]);
    k += 2;
  }
  if (k < size) crc = MavlinkCrcByte(crc, data[k]);
  return crc;
}

inline std::uint64_t LoadBigEndian64(const std::uint8_t* p) {
  return __builtin_bswap64(LoadLittleEndian<std::uint64_t>(p));  // little-endian host
}

inline bool PlausibleTlogTime(std::uint64_t t_us) {
  return t_us >= kTlogMinTimeUs && t_us < kTlogMaxTimeUs;
}

/// LooksLikeTlogRecord (mavlink_tlog.h), inline.
inline bool StartsLikeTlogRecord(const std::uint8_t* data, std::size_t size) {
  if (size < kTlogTimeBytes + 1) return false;
  const std::uint8_t stx = data[kTlogTimeBytes];
  return PlausibleTlogTime(LoadBigEndian64(data)) && (stx == kMavlinkStxV1 || stx == kMavlinkStxV2);
}

/// A frame located in the input.
struct MavlinkFrame {
  std::size_t record_bytes = 0;  // 8-byte time + the whole frame (signature included)
  std::uint64_t time_us = 0;
  std::uint32_t msgid = 0;
  const std::uint8_t* payload = nullptr;
  std::size_t len = 0;
  std::uint8_t system_id = 0;
  std::uint8_t component_id = 0;
  bool v2 = false;
  bool is_signed = false;
};

enum class TlogVerdict { kNotStart, kIncomplete, kCrcFailed, kChecked, kUnchecked };

/// Whether a record can start at `pos` (pure: no side effects).
inline TlogVerdict ExamineTlogRecord(const std::uint8_t* data, std::size_t size, std::size_t pos,
                                     MavlinkFrame* f) {
  const std::size_t left = size - pos;
  if (left < kTlogTimeBytes + 1) return TlogVerdict::kIncomplete;
  const std::uint8_t* p = data + pos;
  f->time_us = LoadBigEndian64(p);
  if (!PlausibleTlogTime(f->time_us)) return TlogVerdict::kNotStart;
  const std::uint8_t* frame = p + kTlogTimeBytes;
  const std::size_t frame_left = left - kTlogTimeBytes;
  std::size_t header = 0;
  std::size_t extra = 0;
  if (frame[0] == kMavlinkStxV1) {
    header = kMavlinkHeaderV1;
    if (frame_left < header) return TlogVerdict::kIncomplete;
    f->v2 = false;
    f->is_signed = false;
    f->len = frame[1];
    f->system_id = frame[3];
    f->component_id = frame[4];
    f->msgid = frame[5];
  } else if (frame[0] == kMavlinkStxV2) {
    header = kMavlinkHeaderV2;
    if (frame_left < 3) return TlogVerdict::kIncomplete;
    const std::uint8_t incompat = frame[2];
    if ((incompat & ~kMavlinkIncompatSigned) != 0) return TlogVerdict::kNotStart;
    if (frame_left < header) return TlogVerdict::kIncomplete;
    f->v2 = true;
    f->is_signed = (incompat & kMavlinkIncompatSigned) != 0;
    extra = f->is_signed ? kMavlinkSignatureBytes : 0;
    f->len = frame[1];
    f->system_id = frame[5];
    f->component_id = frame[6];
    f->msgid = static_cast<std::uint32_t>(frame[7]) | (static_cast<std::uint32_t>(frame[8]) << 8) |
               (static_cast<std::uint32_t>(frame[9]) << 16);
  } else {
    return TlogVerdict::kNotStart;
  }
  const std::size_t frame_bytes = header + f->len + kMavlinkCrcBytes + extra;
  if (frame_left < frame_bytes) return TlogVerdict::kIncomplete;
  f->record_bytes = kTlogTimeBytes + frame_bytes;
  f->payload = frame + header;
  const int crc_extra = MavlinkCrcExtraOf(f->msgid);
  if (crc_extra < 0) return TlogVerdict::kUnchecked;
  const std::uint16_t crc = MavlinkCrcByte(MavlinkX25Crc(frame + 1, header - 1 + f->len, 0xFFFF),
                                           static_cast<std::uint8_t>(crc_extra));
  const std::uint16_t sent = LoadLittleEndian<std::uint16_t>(f->payload + f->len);
  return crc == sent ? TlogVerdict::kChecked : TlogVerdict::kCrcFailed;
}

/// A record of any id could start at `pos`: the end of the data, a tail too short for a
/// record header, or a plausible time followed by a start byte.
inline bool NextLooksLikeTlogRecord(const std::uint8_t* data, std::size_t size, std::size_t pos) {
  return size - pos < kTlogTimeBytes + 1 || StartsLikeTlogRecord(data + pos, size - pos);
}

}  // namespace plumb::io::detail

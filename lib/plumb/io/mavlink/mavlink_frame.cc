// plumb/io/mavlink/mavlink_frame.cc — the CRC tables, built once, and the framing functions
// mavlink_tlog.h offers (MavlinkCrc, LooksLikeTlogRecord); see mavlink_frame.h.
#include "plumb/io/mavlink/mavlink_frame.h"

namespace plumb::io {
namespace detail {

MavlinkCrcTable::MavlinkCrcTable() {
  for (unsigned b = 0; b < 256; ++b) {
    std::uint16_t crc = static_cast<std::uint16_t>(b);
    for (int k = 0; k < 8; ++k) {
      crc = static_cast<std::uint16_t>((crc & 1u) ? (crc >> 1) ^ 0x8408u : crc >> 1);
    }
    t[0][b] = crc;
  }
  for (std::size_t k = 1; k < 8; ++k) {
    for (unsigned b = 0; b < 256; ++b) {
      const std::uint16_t prev = t[k - 1][b];
      t[k][b] = static_cast<std::uint16_t>((prev >> 8) ^ t[0][prev & 0xFFu]);
    }
  }
}

const MavlinkCrcTable kMavlinkCrcTable;

}  // namespace detail

std::uint16_t MavlinkCrc(const std::uint8_t* data, std::size_t size, std::uint16_t crc) {
  return detail::MavlinkX25Crc(data, size, crc);
}

bool LooksLikeTlogRecord(const std::uint8_t* data, std::size_t size) {
  return detail::StartsLikeTlogRecord(data, size);
}

}  // namespace plumb::io

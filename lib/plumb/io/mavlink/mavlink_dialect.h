// plumb/io/mavlink/mavlink_dialect.h — INTERNAL to plumb::io_mavlink: the known dialects'
// message table as the tlog reader's scan asks it, for every frame it examines: the CRC_EXTRA
// of an id (MavlinkCrcExtraOf) and the full payload length of the messages it decodes, by low
// id from a table built once. The generated table itself (mavlink_messages.inc) is in
// mavlink_dialect.cc alone, which also answers the look-ups of mavlink_tlog.h (MavlinkMessages,
// FindMavlinkMessage, MavlinkMessageName, MavlinkCrcExtra, MavlinkDefinitionsSource). Not part
// of the public interface.
#pragma once

#include <array>
#include <cstdint>

#include "plumb/io/mavlink/mavlink_tlog.h"

namespace plumb::io::detail {

/// Per low id (< 256), for the byte-by-byte scan: CRC_EXTRA (-1 unknown) and full decoded
/// length (0 not decoded). Higher ids are looked up in the table (MavlinkCrcExtra).
struct MavlinkIdTable {
  std::array<std::int16_t, 256> crc_extra{};
  std::array<std::uint8_t, 256> full_len{};
  MavlinkIdTable();
};
extern const MavlinkIdTable kMavlinkIds;  // mavlink_dialect.cc

/// CRC_EXTRA of any id, -1 when unknown (MavlinkCrcExtra, inline for low ids).
inline int MavlinkCrcExtraOf(std::uint32_t msgid) {
  if (msgid < 256) return kMavlinkIds.crc_extra[msgid];
  return MavlinkCrcExtra(msgid);
}

}  // namespace plumb::io::detail

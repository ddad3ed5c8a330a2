// plumb/io/mavlink/mavlink_dialect.cc — the known dialects' message table (generated at build
// time, mavlink_messages.inc): its look-ups (mavlink_tlog.h), the scan's table by low id
// (mavlink_dialect.h), and the compile-time checks of the table and of the payload lengths the
// decoders assume (mavlink_decode.h).
#include "plumb/io/mavlink/mavlink_dialect.h"

#include <cstddef>
#include <string>
#include <vector>

#include "plumb/io/mavlink/mavlink_decode.h"

namespace plumb::io {
namespace detail {
namespace {

/// One row of the generated table (mavlink_messages.inc, see MavlinkMessageInfo).
struct MavlinkMessageInfoRow {
  std::uint32_t id;
  const char* name;
  std::uint8_t crc_extra;
  std::uint8_t min_length;
  std::uint8_t max_length;
  std::uint8_t dialect;  // index into kMavlinkDialects
};

// kMavlinkDefinitions, kMavlinkDialects, kMavlinkMessages (sorted by id): generated at build
// time by scripts/gen-mavlink-dialect (lib/plumb/io/mavlink/CMakeLists.txt).
#include "mavlink_messages.inc"

constexpr std::size_t kMessageCount = sizeof(kMavlinkMessages) / sizeof(kMavlinkMessages[0]);

/// The row of `msgid`, or nullptr (binary search: the table is sorted by id).
constexpr const MavlinkMessageInfoRow* FindRow(std::uint32_t msgid) {
  std::size_t lo = 0, hi = kMessageCount;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (kMavlinkMessages[mid].id < msgid) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo < kMessageCount && kMavlinkMessages[lo].id == msgid ? &kMavlinkMessages[lo] : nullptr;
}

constexpr bool SortedById() {
  for (std::size_t k = 1; k < kMessageCount; ++k) {
    if (kMavlinkMessages[k - 1].id >= kMavlinkMessages[k].id) return false;
  }
  return true;
}
static_assert(SortedById(), "the generated MAVLink table must be sorted by id");

constexpr bool DecodedLengthsMatchTheDialect() {
  for (const MavlinkDecodedMessage& d : kMavlinkDecoded) {
    const MavlinkMessageInfoRow* row = FindRow(d.id);
    if (row == nullptr || row->max_length != d.full_len) return false;
  }
  return true;
}
static_assert(DecodedLengthsMatchTheDialect(),
              "a decoded message's payload length differs from the generated MAVLink table");

}  // namespace

MavlinkIdTable::MavlinkIdTable() {
  crc_extra.fill(-1);
  for (const MavlinkMessageInfoRow& m : kMavlinkMessages) {
    if (m.id < 256) crc_extra[m.id] = m.crc_extra;
  }
  for (const MavlinkDecodedMessage& d : kMavlinkDecoded) {
    full_len[d.id] = static_cast<std::uint8_t>(d.full_len);
  }
}

const MavlinkIdTable kMavlinkIds;

}  // namespace detail

using detail::FindRow;
using detail::kMavlinkDefinitions;
using detail::kMavlinkDialects;
using detail::kMavlinkMessages;
using detail::kMessageCount;
using detail::MavlinkMessageInfoRow;

const std::vector<MavlinkMessageInfo>& MavlinkMessages() {
  static const std::vector<MavlinkMessageInfo> all = [] {
    std::vector<MavlinkMessageInfo> out;
    out.reserve(kMessageCount);
    for (const MavlinkMessageInfoRow& m : kMavlinkMessages) {
      out.push_back({m.id, m.name, m.crc_extra, m.min_length, m.max_length,
                     kMavlinkDialects[m.dialect]});
    }
    return out;
  }();
  return all;
}

const MavlinkMessageInfo* FindMavlinkMessage(std::uint32_t msgid) {
  const MavlinkMessageInfoRow* row = FindRow(msgid);
  return row ? &MavlinkMessages()[static_cast<std::size_t>(row - kMavlinkMessages)] : nullptr;
}

std::string MavlinkDefinitionsSource() {
  std::string dialects;
  for (const char* d : kMavlinkDialects) {
    dialects += (dialects.empty() ? "" : ", ") + std::string(d);
  }
  return dialects + " (" + kMavlinkDefinitions + ")";
}

std::string MavlinkMessageName(std::uint32_t msgid) {
  const MavlinkMessageInfoRow* row = FindRow(msgid);
  return row ? std::string(row->name) : "MSG" + std::to_string(msgid);
}

int MavlinkCrcExtra(std::uint32_t msgid) {
  if (msgid < 256) return detail::kMavlinkIds.crc_extra[msgid];
  const MavlinkMessageInfoRow* row = FindRow(msgid);
  return row ? row->crc_extra : -1;
}

}  // namespace plumb::io

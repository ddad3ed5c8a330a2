// tests/io/tlog_builder.h — building MAVLink tlogs byte by byte in tests: records (8-byte
// big-endian time + a v1 or v2 frame with its CRC) and the payloads of the messages the reader
// decodes.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "plumb/io/mavlink/mavlink_tlog.h"

namespace plumb::io::testing {

using Bytes = std::vector<std::uint8_t>;

inline constexpr std::uint64_t kT0_us = 1532076292000000ull;  // 2018-07-20, a plausible tlog time
/// An 8-bit id in none of the known dialects (the tests assert it before relying on it).
inline constexpr std::uint32_t kUnknownId = 199;

/// Little-endian payload writer.
struct Payload {
  Bytes b;
  template <typename T>
  Payload& Put(T v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    b.insert(b.end(), p, p + sizeof(T));
    return *this;
  }
};

struct FrameSpec {
  std::uint32_t msgid = 0;
  Bytes payload;
  std::uint8_t system_id = 1;
  std::uint8_t component_id = 1;
  bool v2 = false;
  bool sign = false;          // v2 only: incompat flag 1 and a 13-byte signature
  bool truncate_zeros = true;  // v2 only: drop trailing zero bytes of the payload
  std::uint64_t time_us = kT0_us;
};

/// One tlog record: 8-byte big-endian time + the frame, CRC from MavlinkCrc and the
/// message's CRC_EXTRA (MavlinkCrc itself is checked against known values below).
inline Bytes Record(const FrameSpec& s) {
  Bytes r;
  for (int k = 7; k >= 0; --k) r.push_back(static_cast<std::uint8_t>(s.time_us >> (8 * k)));
  Bytes payload = s.payload;
  if (s.v2 && s.truncate_zeros) {
    while (payload.size() > 1 && payload.back() == 0) payload.pop_back();
  }
  const std::size_t start = r.size();
  const std::uint8_t len = static_cast<std::uint8_t>(payload.size());
  if (s.v2) {
    r.insert(r.end(), {0xFD, len, static_cast<std::uint8_t>(s.sign ? 1 : 0), 0, 7, s.system_id,
                       s.component_id, static_cast<std::uint8_t>(s.msgid & 0xFF),
                       static_cast<std::uint8_t>((s.msgid >> 8) & 0xFF),
                       static_cast<std::uint8_t>((s.msgid >> 16) & 0xFF)});
  } else {
    r.insert(r.end(), {0xFE, len, 7, s.system_id, s.component_id,
                       static_cast<std::uint8_t>(s.msgid)});
  }
  r.insert(r.end(), payload.begin(), payload.end());
  std::uint16_t crc = MavlinkCrc(r.data() + start + 1, r.size() - start - 1);
  const int extra = MavlinkCrcExtra(s.msgid);
  const std::uint8_t extra_byte = static_cast<std::uint8_t>(extra < 0 ? 0 : extra);
  crc = MavlinkCrc(&extra_byte, 1, crc);
  r.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  r.push_back(static_cast<std::uint8_t>(crc >> 8));
  if (s.v2 && s.sign) {
    for (int k = 0; k < 13; ++k) r.push_back(static_cast<std::uint8_t>(0xA0 + k));
  }
  return r;
}

inline void Append(Bytes* out, const Bytes& more) {
  out->insert(out->end(), more.begin(), more.end());
}

inline Bytes Heartbeat(std::uint8_t autopilot) {
  return Payload{}.Put<std::uint32_t>(0).Put<std::uint8_t>(1).Put<std::uint8_t>(autopilot)
      .Put<std::uint8_t>(0).Put<std::uint8_t>(3).Put<std::uint8_t>(3).b;
}

/// RAW_IMU payload: time_usec, acc/gyr/mag triads, id, temperature (29 bytes).
inline Bytes RawImu(std::uint64_t time_us, std::array<std::int16_t, 9> v, std::uint8_t id = 0,
             std::int16_t temperature_cdegc = 0) {
  Payload p;
  p.Put(time_us);
  for (std::int16_t x : v) p.Put(x);
  p.Put(id).Put(temperature_cdegc);
  return p.b;
}

/// SCALED_IMU2 payload: time_boot_ms, triads, temperature (24 bytes).
inline Bytes ScaledImu(std::uint32_t time_ms, std::array<std::int16_t, 9> v,
                       std::int16_t temp = 0) {
  Payload p;
  p.Put(time_ms);
  for (std::int16_t x : v) p.Put(x);
  p.Put(temp);
  return p.b;
}

/// HIGHRES_IMU payload: time_usec, 13 floats (acc, gyr, mag, pressures, altitude,
/// temperature), fields_updated, id (63 bytes).
inline Bytes HighresImu(std::uint64_t time_us, const std::array<float, 13>& v,
                        std::uint16_t fields_updated = 0x1FFF, std::uint8_t id = 0) {
  Payload p;
  p.Put(time_us);
  for (float x : v) p.Put(x);
  p.Put(fields_updated).Put(id);
  return p.b;
}

/// GPS_RAW_INT payload: time_usec 1, the position, eph 100, epv 200, `vel_cm_s`, cog 0, the
/// fix, 9 satellites, the extensions zero.
inline Bytes GpsRawInt(std::int32_t lat_e7, std::int32_t lon_e7, std::int32_t alt_mm,
                std::uint8_t fix_type, std::uint16_t vel_cm_s = 0) {
  Payload p;
  p.Put<std::uint64_t>(1).Put(lat_e7).Put(lon_e7).Put(alt_mm);
  p.Put<std::uint16_t>(100).Put<std::uint16_t>(200).Put(vel_cm_s).Put<std::uint16_t>(0);
  p.Put(fix_type).Put<std::uint8_t>(9);
  for (int k = 0; k < 5; ++k) p.Put<std::uint32_t>(0);
  p.Put<std::uint16_t>(0);
  return p.b;
}

inline Bytes ParamValue(const std::string& name, float value, std::uint8_t type) {
  Payload p;
  p.Put(value).Put<std::uint16_t>(10).Put<std::uint16_t>(0);
  char id[16] = {};
  std::memcpy(id, name.data(), std::min<std::size_t>(16, name.size()));
  for (char c : id) p.Put(c);
  p.Put(type);
  return p.b;
}

}  // namespace plumb::io::testing

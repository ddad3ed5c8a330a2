// plumb/io/mavlink/mavlink_decode.h — INTERNAL to plumb::io_mavlink: the messages the tlog
// reader decodes (HEARTBEAT, PARAM_VALUE, GPS_RAW_INT and the IMU messages; see mavlink_tlog.h),
// from the payload of a checked frame, at the offsets of their definitions (fields ordered by
// size, largest first, extensions last), into the log's vectors (MavlinkDecoder). Inline: the
// scan of mavlink_tlog.cc, its user, decodes each such frame inside its loop. Not part of the
// public interface.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "plumb/io/common/log_common.h"
#include "plumb/io/mavlink/mavlink_frame.h"
#include "plumb/io/mavlink/mavlink_tlog.h"

namespace plumb::io::detail {

/// The messages MavlinkDecoder reads, with the full payload length its offsets assume; each
/// must be the dialect's (checked at compile time against the generated table,
/// mavlink_dialect.cc).
struct MavlinkDecodedMessage {
  std::uint32_t id;
  std::size_t full_len;
};
inline constexpr MavlinkDecodedMessage kMavlinkDecoded[] = {
    {kMavHeartbeat, 9},  {kMavParamValue, 25}, {kMavGpsRawInt, 52},  {kMavScaledImu, 24},
    {kMavRawImu, 29},    {kMavHighresImu, 63}, {kMavScaledImu2, 24}, {kMavScaledImu3, 24},
};

/// Decodes the frames of the messages in kMavlinkDecoded into a log's vectors. Its functions
/// are inlined into the scan's loop ([[gnu::always_inline]]), as they were when the scan decoded
/// the payloads itself: called out of line, BM_ReadTlog measured about 2 % slower.
class MavlinkDecoder {
 public:
  /// Appends the message of `f`, a checked frame whose id has the full payload length `full`
  /// (kMavlinkIds.full_len, not 0), to its vector of `log`. A payload shorter than `full` is
  /// zero-extended to it first (MAVLink 2 truncation); bytes beyond it are ignored.
  [[gnu::always_inline]] void Decode(const MavlinkFrame& f, std::size_t full, MavlinkLog* log) {
    // Zero-extend a truncated payload (MAVLink 2) to the full length.
    const std::uint8_t* p = f.payload;
    if (f.len < full) {
      std::memset(buffer_.data(), 0, full);
      std::memcpy(buffer_.data(), f.payload, f.len);
      p = buffer_.data();
    }
    const double log_time_s = static_cast<double>(f.time_us) * 1e-6;
    switch (f.msgid) {
      case kMavHeartbeat: DecodeHeartbeat(f, log_time_s, p, log); break;
      case kMavParamValue: DecodeParamValue(f, log_time_s, p, log); break;
      case kMavGpsRawInt: DecodeGpsRawInt(f, log_time_s, p, log); break;
      case kMavRawImu: DecodeRawImu(f, log_time_s, p, log); break;
      case kMavScaledImu:
      case kMavScaledImu2:
      case kMavScaledImu3: DecodeScaledImu(f, log_time_s, p, log); break;
      case kMavHighresImu: DecodeHighresImu(f, log_time_s, p, log); break;
      default: break;
    }
  }

 private:
  [[gnu::always_inline]] static std::array<std::int16_t, 3> Int16Triad(const std::uint8_t* p) {
    return {LoadLittleEndian<std::int16_t>(p), LoadLittleEndian<std::int16_t>(p + 2),
            LoadLittleEndian<std::int16_t>(p + 4)};
  }

  [[gnu::always_inline]] static std::array<float, 3> FloatTriad(const std::uint8_t* p) {
    return {LoadLittleEndian<float>(p), LoadLittleEndian<float>(p + 4),
            LoadLittleEndian<float>(p + 8)};
  }

  [[gnu::always_inline]] static void FillInt16Imu(const MavlinkFrame& f, double log_time_s,
                                                  std::uint64_t time_us, const std::uint8_t* triads,
                                                  MavlinkInt16Imu* s) {
    s->log_time_s = log_time_s;
    s->time_us = time_us;
    s->system_id = f.system_id;
    s->component_id = f.component_id;
    s->acc = Int16Triad(triads);
    s->gyr = Int16Triad(triads + 6);
    s->mag = Int16Triad(triads + 12);
  }

  [[gnu::always_inline]] static void DecodeHeartbeat(const MavlinkFrame& f, double log_time_s,
                                                     const std::uint8_t* p, MavlinkLog* log) {
    MavlinkHeartbeat& h = log->heartbeat.emplace_back();
    h.log_time_s = log_time_s;
    h.system_id = f.system_id;
    h.component_id = f.component_id;
    h.custom_mode = LoadLittleEndian<std::uint32_t>(p);
    h.type = p[4];
    h.autopilot = p[5];
    h.base_mode = p[6];
    h.system_status = p[7];
    h.mavlink_version = p[8];
  }

  [[gnu::always_inline]] static void DecodeParamValue(const MavlinkFrame& f, double log_time_s,
                                                      const std::uint8_t* p, MavlinkLog* log) {
    MavlinkParamValue& v = log->param_value.emplace_back();
    v.log_time_s = log_time_s;
    v.system_id = f.system_id;
    v.component_id = f.component_id;
    v.value = LoadLittleEndian<float>(p);
    v.count = LoadLittleEndian<std::uint16_t>(p + 4);
    v.index = LoadLittleEndian<std::uint16_t>(p + 6);
    std::memcpy(v.id.data(), p + 8, 16);
    v.type = p[24];
  }

  [[gnu::always_inline]] static void DecodeGpsRawInt(const MavlinkFrame& f, double log_time_s,
                                                     const std::uint8_t* p, MavlinkLog* log) {
    MavlinkGpsRawInt& g = log->gps_raw_int.emplace_back();
    g.log_time_s = log_time_s;
    g.system_id = f.system_id;
    g.component_id = f.component_id;
    g.time_us = LoadLittleEndian<std::uint64_t>(p);
    g.lat_e7 = LoadLittleEndian<std::int32_t>(p + 8);
    g.lon_e7 = LoadLittleEndian<std::int32_t>(p + 12);
    g.alt_mm = LoadLittleEndian<std::int32_t>(p + 16);
    g.eph = LoadLittleEndian<std::uint16_t>(p + 20);
    g.epv = LoadLittleEndian<std::uint16_t>(p + 22);
    g.vel_cm_s = LoadLittleEndian<std::uint16_t>(p + 24);
    g.cog_cdeg = LoadLittleEndian<std::uint16_t>(p + 26);
    g.fix_type = p[28];
    g.satellites_visible = p[29];
    g.alt_ellipsoid_mm = LoadLittleEndian<std::int32_t>(p + 30);
    g.h_acc_mm = LoadLittleEndian<std::uint32_t>(p + 34);
    g.v_acc_mm = LoadLittleEndian<std::uint32_t>(p + 38);
    g.vel_acc_mm_s = LoadLittleEndian<std::uint32_t>(p + 42);
    g.hdg_acc_degE5 = LoadLittleEndian<std::uint32_t>(p + 46);
    g.yaw_cdeg = LoadLittleEndian<std::uint16_t>(p + 50);
  }

  [[gnu::always_inline]] static void DecodeRawImu(const MavlinkFrame& f, double log_time_s,
                                                  const std::uint8_t* p, MavlinkLog* log) {
    // time_usec u64, 9 x int16, extensions id u8 (26), temperature int16 (27).
    MavlinkInt16Imu& s = log->raw_imu.emplace_back();
    FillInt16Imu(f, log_time_s, LoadLittleEndian<std::uint64_t>(p), p + 8, &s);
    s.id = p[26];
    s.temperature_cdegc = LoadLittleEndian<std::int16_t>(p + 27);
  }

  [[gnu::always_inline]] static void DecodeScaledImu(const MavlinkFrame& f, double log_time_s,
                                                     const std::uint8_t* p, MavlinkLog* log) {
    // time_boot_ms u32, 9 x int16, extension temperature int16 (22).
    std::vector<MavlinkInt16Imu>& out = f.msgid == kMavScaledImu    ? log->scaled_imu
                                        : f.msgid == kMavScaledImu2 ? log->scaled_imu2
                                                                    : log->scaled_imu3;
    MavlinkInt16Imu& s = out.emplace_back();
    FillInt16Imu(f, log_time_s, std::uint64_t{LoadLittleEndian<std::uint32_t>(p)} * 1000u, p + 4,
                 &s);
    s.temperature_cdegc = LoadLittleEndian<std::int16_t>(p + 22);
  }

  [[gnu::always_inline]] static void DecodeHighresImu(const MavlinkFrame& f, double log_time_s,
                                                      const std::uint8_t* p, MavlinkLog* log) {
    // time_usec u64, 13 floats, fields_updated u16 (60), extension id u8 (62).
    MavlinkHighresImu& h = log->highres_imu.emplace_back();
    h.log_time_s = log_time_s;
    h.system_id = f.system_id;
    h.component_id = f.component_id;
    h.time_us = LoadLittleEndian<std::uint64_t>(p);
    h.acc = FloatTriad(p + 8);
    h.gyr = FloatTriad(p + 20);
    h.mag = FloatTriad(p + 32);
    h.abs_pressure_hpa = LoadLittleEndian<float>(p + 44);
    h.diff_pressure_hpa = LoadLittleEndian<float>(p + 48);
    h.pressure_alt = LoadLittleEndian<float>(p + 52);
    h.temperature_degc = LoadLittleEndian<float>(p + 56);
    h.fields_updated = LoadLittleEndian<std::uint16_t>(p + 60);
    h.id = p[62];
  }

  std::array<std::uint8_t, kMavlinkMaxPayload + 1> buffer_{};
};

}  // namespace plumb::io::detail

// tests/support/mavlink_log_difference.h — the first difference between two decoded tlogs, or
// none: the counts, every decoded message field by field, the message counts per id, the
// warnings. For tests and the differential fuzz target of the two-part read
// (tests/fuzz/mavlink_tlog_two_part_fuzz.cc), which must find the log read in two parts the
// same as read in one.
#pragma once

#include <array>
#include <cstddef>
#include <cstring>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "plumb/io/mavlink/mavlink_tlog.h"

namespace plumb::testing {
namespace mavlink_difference {

// Every field of each decoded message, as a tuple to compare.
inline auto Fields(const io::MavlinkHeartbeat& h) {
  return std::tie(h.log_time_s, h.system_id, h.component_id, h.custom_mode, h.type, h.autopilot,
                  h.base_mode, h.system_status, h.mavlink_version);
}
inline auto Fields(const io::MavlinkInt16Imu& s) {
  return std::tie(s.log_time_s, s.time_us, s.acc, s.gyr, s.mag, s.temperature_cdegc, s.id,
                  s.system_id, s.component_id);
}
inline auto Fields(const io::MavlinkHighresImu& h) {
  return std::tie(h.log_time_s, h.time_us, h.acc, h.gyr, h.mag, h.abs_pressure_hpa,
                  h.diff_pressure_hpa, h.pressure_alt, h.temperature_degc, h.fields_updated, h.id,
                  h.system_id, h.component_id);
}
inline auto Fields(const io::MavlinkGpsRawInt& g) {
  return std::tie(g.log_time_s, g.time_us, g.lat_e7, g.lon_e7, g.alt_mm, g.eph, g.epv, g.vel_cm_s,
                  g.cog_cdeg, g.fix_type, g.satellites_visible, g.alt_ellipsoid_mm, g.h_acc_mm,
                  g.v_acc_mm, g.vel_acc_mm_s, g.hdg_acc_degE5, g.yaw_cdeg, g.system_id,
                  g.component_id);
}
inline auto Fields(const io::MavlinkParamValue& v) {
  return std::tie(v.log_time_s, v.value, v.count, v.index, v.id, v.type, v.system_id,
                  v.component_id);
}

/// Whether two fields hold the same value: floating-point ones bit for bit (a NaN decoded twice
/// is the same NaN).
template <class T>
bool Same(const T& a, const T& b) {
  if constexpr (std::is_floating_point_v<T>) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
  } else {
    return a == b;
  }
}
template <class T, std::size_t N>
bool Same(const std::array<T, N>& a, const std::array<T, N>& b) {
  for (std::size_t k = 0; k < N; ++k) {
    if (!Same(a[k], b[k])) return false;
  }
  return true;
}
template <class Tuple, std::size_t... I>
bool SameFields(const Tuple& a, const Tuple& b, std::index_sequence<I...>) {
  return (Same(std::get<I>(a), std::get<I>(b)) && ...);
}

/// "" when `a` and `b` hold the same messages; else which message differs first.
template <class Message>
std::string VectorDifference(const std::string& what, const std::vector<Message>& a,
                             const std::vector<Message>& b) {
  if (a.size() != b.size()) {
    return what + ": " + std::to_string(a.size()) + " != " + std::to_string(b.size());
  }
  for (std::size_t k = 0; k < a.size(); ++k) {
    const auto fa = Fields(a[k]);
    constexpr std::size_t kFields = std::tuple_size_v<decltype(fa)>;
    if (!SameFields(fa, Fields(b[k]), std::make_index_sequence<kFields>{})) {
      return what + "[" + std::to_string(k) + "]";
    }
  }
  return "";
}

}  // namespace mavlink_difference

inline std::string MavlinkWarningsDifference(const io::MavlinkWarnings& a,
                                             const io::MavlinkWarnings& b) {
  if (a.bytes_skipped != b.bytes_skipped || a.skip_runs != b.skip_runs ||
      a.first_skip_offset != b.first_skip_offset) {
    return "skipped bytes";
  }
  if (a.crc_failures != b.crc_failures ||
      a.first_crc_failure_offset != b.first_crc_failure_offset) {
    return "CRC failures";
  }
  if (a.truncated_records != b.truncated_records || a.truncated_bytes != b.truncated_bytes) {
    return "truncated record";
  }
  if (a.unchecked_frames != b.unchecked_frames) return "unchecked frames";
  return "";
}

/// "" when the tlogs `a` and `b` were decoded the same; else what differs first.
inline std::string MavlinkLogDifference(const io::MavlinkLog& a, const io::MavlinkLog& b) {
  using mavlink_difference::VectorDifference;
  if (a.source != b.source || a.size_bytes != b.size_bytes) return "source or size";
  if (a.frames_v1 != b.frames_v1 || a.frames_v2 != b.frames_v2 ||
      a.frames_signed != b.frames_signed || a.checked_frames != b.checked_frames) {
    return "frame counts";
  }
  if (a.record_bytes != b.record_bytes) return "record bytes";
  if (a.message_counts != b.message_counts) return "message counts";
  for (const std::string& d :
       {VectorDifference("HEARTBEAT", a.heartbeat, b.heartbeat),
        VectorDifference("RAW_IMU", a.raw_imu, b.raw_imu),
        VectorDifference("SCALED_IMU", a.scaled_imu, b.scaled_imu),
        VectorDifference("SCALED_IMU2", a.scaled_imu2, b.scaled_imu2),
        VectorDifference("SCALED_IMU3", a.scaled_imu3, b.scaled_imu3),
        VectorDifference("HIGHRES_IMU", a.highres_imu, b.highres_imu),
        VectorDifference("GPS_RAW_INT", a.gps_raw_int, b.gps_raw_int),
        VectorDifference("PARAM_VALUE", a.param_value, b.param_value)}) {
    if (!d.empty()) return d;
  }
  if (const std::string d = MavlinkWarningsDifference(a.warnings, b.warnings); !d.empty()) {
    return "warnings: " + d;
  }
  if (a.warnings.Describe(a.message_counts) != b.warnings.Describe(b.message_counts)) {
    return "warnings' text";
  }
  return "";
}

}  // namespace plumb::testing

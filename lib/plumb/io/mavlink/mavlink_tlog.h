// plumb/io/mavlink/mavlink_tlog.h — MAVLink telemetry logs (.tlog, as Mission Planner,
// QGroundControl and MAVProxy save them).
//
// Format: a sequence of records [8-byte big-endian uint64 time, microseconds since the unix
// epoch, when the ground station received the frame][one MAVLink frame]:
//  * v1: 0xFE, len, seq, sysid, compid, msgid (1 byte), payload (len bytes), crc16 (LE);
//  * v2: 0xFD, len, incompat_flags, compat_flags, seq, sysid, compid, msgid (3 bytes LE),
//    payload (len bytes; trailing zero bytes truncated by the sender: zero-extended here to the
//    message's full length), crc16 (LE), then a 13-byte signature when incompat_flags & 1.
// CRC: X.25 / CRC-16/MCRF4XX (init 0xFFFF, reflected polynomial 0x8408) over every byte after
// the STX up to the end of the payload, then the message's CRC_EXTRA byte.
//
// Messages known (MavlinkMessages()): the whole common dialect (common.xml with minimal.xml and
// standard.xml) and ArduPilot's (ardupilotmega.xml with uAvionix.xml and icarous.xml), a table
// generated at build time by scripts/gen-mavlink-dialect from the npm package pinned in
// scripts/mavlink-definitions.pin (the MAVLink XML definitions as JavaScript); the generator
// computes each CRC_EXTRA from the message's fields and refuses to build when one differs from
// the package's own value.
// Payload fields are little-endian, ordered by size (largest first), extension fields last in
// declaration order.
//
// Decoding contract (one pass over the file held in memory, no per-frame allocation; a large
// file may be read in two parts at once, TlogReadOptions, to the same log):
//  * A record starts where the 8-byte time is plausible (unix time between 2000-01-01 and
//    2100-01-01) and is followed by 0xFE or 0xFD (v2 with incompat_flags other than 1 is
//    rejected: unknown incompatible features).
//  * Messages of the known dialects are accepted only when their CRC matches (counted in
//    checked_frames); a mismatch is counted (crc_failures) and the reader resynchronises.
//  * Other message ids (outside those dialects) cannot be CRC-checked: such a frame is
//    accepted (counted per id in message_counts, total in unchecked_frames, never decoded) only
//    when the next record starts right after it (plausible time and STX) or the file ends there.
//  * Bytes that start no accepted record are skipped one by one (counted, with the number of
//    separate runs = resyncs). A record whose frame runs past the end of the file, with no
//    valid record after it, is the truncated last record: dropped and counted. So is a tail of
//    fewer than 9 bytes right after an accepted record (elsewhere such a tail is skipped).
//  * A payload shorter than the message's full length is zero-extended (MAVLink 2 truncation;
//    missing extension fields read 0); bytes beyond the full length are ignored.
//
// Decoded messages (units as common.xml states them; ArduPilot fills RAW_IMU with the same
// calibrated units as SCALED_IMU, not with ADC counts):
//  * HEARTBEAT (0); PARAM_VALUE (22); GPS_RAW_INT (24: degE7, mm MSL);
//  * SCALED_IMU (26), SCALED_IMU2 (116), SCALED_IMU3 (129): int16 mG, mrad/s, mgauss,
//    cdegC, time_boot_ms;
//  * RAW_IMU (27): int16 "raw" (mG, mrad/s, mgauss on ArduPilot), time_usec, extensions id
//    and temperature (cdegC);
//  * HIGHRES_IMU (105): float m/s^2, rad/s, gauss, hPa, degC, time_usec, extension id.
// Every decoded record keeps the tlog time (log_time_s, unix s), the message's own time
// (time_us) and the sender's system and component ids: a tlog may hold several vehicles and
// the ground station itself (mavlink_session.h picks the autopilot).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "plumb/io/common/split_read.h"

namespace plumb::io {

/// MAVLink message ids decoded by this reader (common.xml).
inline constexpr std::uint32_t kMavHeartbeat = 0;
inline constexpr std::uint32_t kMavParamValue = 22;
inline constexpr std::uint32_t kMavGpsRawInt = 24;
inline constexpr std::uint32_t kMavScaledImu = 26;
inline constexpr std::uint32_t kMavRawImu = 27;
inline constexpr std::uint32_t kMavHighresImu = 105;
inline constexpr std::uint32_t kMavScaledImu2 = 116;
inline constexpr std::uint32_t kMavScaledImu3 = 129;

/// HEARTBEAT (0).
struct MavlinkHeartbeat {
  double log_time_s = 0.0;        ///< tlog time, s since the unix epoch
  std::uint8_t system_id = 0;     ///< sender's system id, 0..255
  std::uint8_t component_id = 0;  ///< sender's component id, 0..255
  std::uint32_t custom_mode = 0;  ///< autopilot-specific mode
  std::uint8_t type = 0;          ///< MAV_TYPE (1 fixed wing, 2 quadrotor, 6 GCS, ...)
  std::uint8_t autopilot = 0;     ///< MAV_AUTOPILOT (3 ArduPilotMega, 8 invalid/GCS, 12 PX4)
  std::uint8_t base_mode = 0;     ///< MAV_MODE_FLAG bits (128 = armed)
  std::uint8_t system_status = 0; ///< MAV_STATE
  std::uint8_t mavlink_version = 0;  ///< MAVLink protocol version field (3 for 1.0/2.0)
};

/// RAW_IMU (27), SCALED_IMU (26), SCALED_IMU2 (116), SCALED_IMU3 (129): int16 triads.
struct MavlinkInt16Imu {
  double log_time_s = 0.0;        ///< tlog time, s since the unix epoch
  /// The message's own time, microseconds: RAW_IMU time_usec (since boot or the unix epoch,
  /// ArduPilot: since boot), SCALED_IMU* time_boot_ms * 1000 (since boot).
  std::uint64_t time_us = 0;
  std::array<std::int16_t, 3> acc{};  ///< x, y, z acceleration, mG (RAW_IMU: raw, mG on ArduPilot)
  std::array<std::int16_t, 3> gyr{};  ///< x, y, z angular rate, mrad/s (RAW_IMU: raw, mrad/s on ArduPilot)
  std::array<std::int16_t, 3> mag{};  ///< x, y, z magnetic field, mgauss (RAW_IMU: raw)
  std::int16_t temperature_cdegc = 0; ///< cdegC; 0 = not provided (extension field)
  std::uint8_t id = 0;            ///< RAW_IMU instance (extension, 0-based); 0 for SCALED_IMU*
  std::uint8_t system_id = 0;     ///< sender's system id
  std::uint8_t component_id = 0;  ///< sender's component id
};

/// HIGHRES_IMU (105).
struct MavlinkHighresImu {
  double log_time_s = 0.0;         ///< tlog time, s since the unix epoch
  std::uint64_t time_us = 0;       ///< time_usec, µs (since boot or the unix epoch)
  std::array<float, 3> acc{};      ///< m/s^2
  std::array<float, 3> gyr{};      ///< rad/s
  std::array<float, 3> mag{};      ///< gauss
  float abs_pressure_hpa = 0.0f;   ///< hPa
  float diff_pressure_hpa = 0.0f;  ///< hPa
  float pressure_alt = 0.0f;       ///< altitude from pressure (unit unstated, m in practice)
  float temperature_degc = 0.0f;   ///< degC
  std::uint16_t fields_updated = 0;  ///< bit 0 xacc ... bit 12 temperature
  std::uint8_t id = 0;             ///< IMU instance (extension, 0-based)
  std::uint8_t system_id = 0;      ///< sender's system id
  std::uint8_t component_id = 0;   ///< sender's component id
};

/// GPS_RAW_INT (24).
struct MavlinkGpsRawInt {
  double log_time_s = 0.0;      ///< tlog time, s since the unix epoch
  std::uint64_t time_us = 0;    ///< time_usec, µs
  std::int32_t lat_e7 = 0;      ///< latitude, degE7 (1e-7 degrees)
  std::int32_t lon_e7 = 0;      ///< longitude, degE7
  std::int32_t alt_mm = 0;      ///< altitude above mean sea level, mm
  std::uint16_t eph = 0;        ///< HDOP * 100 (65535 unknown)
  std::uint16_t epv = 0;        ///< VDOP * 100 (65535 unknown)
  std::uint16_t vel_cm_s = 0;   ///< ground speed, cm/s
  std::uint16_t cog_cdeg = 0;   ///< course over ground, cdeg
  std::uint8_t fix_type = 0;    ///< GPS_FIX_TYPE (3 = 3D fix, higher = better)
  std::uint8_t satellites_visible = 0;  ///< 255 unknown
  std::int32_t alt_ellipsoid_mm = 0;    ///< altitude above the WGS84 ellipsoid, mm (extension)
  std::uint32_t h_acc_mm = 0;     ///< horizontal accuracy, mm (extension)
  std::uint32_t v_acc_mm = 0;     ///< vertical accuracy, mm (extension)
  std::uint32_t vel_acc_mm_s = 0; ///< speed accuracy, mm/s (extension)
  std::uint32_t hdg_acc_degE5 = 0;  ///< heading accuracy, degE5 (extension)
  std::uint16_t yaw_cdeg = 0;     ///< yaw from GPS, cdeg, 0 = not provided (extension)
  std::uint8_t system_id = 0;     ///< sender's system id
  std::uint8_t component_id = 0;  ///< sender's component id
};

/// PARAM_VALUE (22).
struct MavlinkParamValue {
  double log_time_s = 0.0;        ///< tlog time, s since the unix epoch
  float value = 0.0f;             ///< param_value as sent (see TlogParams for int types)
  std::uint16_t count = 0;        ///< param_count: parameters on the vehicle
  std::uint16_t index = 0;        ///< param_index (65535 when sent unrequested)
  std::array<char, 16> id{};      ///< param_id, NUL-padded, not terminated when 16 long
  std::uint8_t type = 0;          ///< MAV_PARAM_TYPE (9 = REAL32, 1..8 integer types)
  std::uint8_t system_id = 0;     ///< sender's system id
  std::uint8_t component_id = 0;  ///< sender's component id

  /// param_id as text (up to the first NUL, at most 16 characters).
  std::string Name() const { return std::string(NameView()); }
  /// Name() as a view into `id` (valid while this message lives).
  std::string_view NameView() const;
};

/// What the reader skipped or repaired. Counts, never fatal.
struct MavlinkWarnings {
  std::size_t bytes_skipped = 0;       ///< bytes outside any accepted record
  std::size_t skip_runs = 0;           ///< separate runs of skipped bytes (resyncs)
  std::size_t first_skip_offset = 0;   ///< byte offset of the first skipped byte (if any)
  std::size_t crc_failures = 0;        ///< candidate frames of a known id with a wrong CRC
  std::size_t first_crc_failure_offset = 0;  ///< byte offset of the first one (if any)
  std::size_t truncated_records = 0;   ///< 0 or 1: the cut last record, dropped
  std::size_t truncated_bytes = 0;     ///< bytes of that dropped record
  std::size_t unchecked_frames = 0;    ///< frames of ids outside the known dialects, accepted

  /// One readable line per non-zero count (unchecked ids listed from `counts`).
  std::vector<std::string> Describe(const std::map<std::uint32_t, std::size_t>& counts) const;
};

/// A decoded tlog.
struct MavlinkLog {
  std::string source;               ///< file name (or the name given to ParseTlog)
  std::size_t size_bytes = 0;       ///< input size, bytes
  std::size_t frames_v1 = 0;        ///< accepted MAVLink 1 frames
  std::size_t frames_v2 = 0;        ///< accepted MAVLink 2 frames
  std::size_t frames_signed = 0;    ///< accepted v2 frames carrying a signature (not verified)
  /// Accepted frames whose CRC was checked (with their message's CRC_EXTRA); the others are
  /// warnings.unchecked_frames: checked_frames + unchecked_frames == frames_v1 + frames_v2.
  std::size_t checked_frames = 0;
  /// Bytes in accepted records (times included): record_bytes + bytes_skipped +
  /// truncated_bytes == size_bytes.
  std::size_t record_bytes = 0;
  std::map<std::uint32_t, std::size_t> message_counts;  ///< accepted frames per message id
  std::vector<MavlinkHeartbeat> heartbeat;
  std::vector<MavlinkInt16Imu> raw_imu;       ///< RAW_IMU (27)
  std::vector<MavlinkInt16Imu> scaled_imu;    ///< SCALED_IMU (26)
  std::vector<MavlinkInt16Imu> scaled_imu2;   ///< SCALED_IMU2 (116)
  std::vector<MavlinkInt16Imu> scaled_imu3;   ///< SCALED_IMU3 (129)
  std::vector<MavlinkHighresImu> highres_imu; ///< HIGHRES_IMU (105)
  std::vector<MavlinkGpsRawInt> gps_raw_int;  ///< GPS_RAW_INT (24)
  std::vector<MavlinkParamValue> param_value; ///< PARAM_VALUE (22)
  MavlinkWarnings warnings;

  /// (name, count) of every message id seen, by id ("MSG<id>" for unnamed ids).
  std::vector<std::pair<std::string, std::size_t>> MessageCounts() const;
};

/// A message of the known dialects (one row of the generated table).
struct MavlinkMessageInfo {
  std::uint32_t id = 0;          ///< message id, 0..2^24-1
  const char* name = "";         ///< MAVLink name ("RAW_IMU")
  std::uint8_t crc_extra = 0;    ///< CRC_EXTRA, computed from the fields by the generator
  std::uint8_t min_length = 0;   ///< payload bytes without extension fields (MAVLink 1)
  std::uint8_t max_length = 0;   ///< payload bytes with every extension field
  const char* dialect = "";      ///< its dialect as the package names it ("common", "uavionix")
};

/// Every message of the known dialects, by increasing id.
const std::vector<MavlinkMessageInfo>& MavlinkMessages();

/// The message `msgid` of the known dialects, or nullptr.
const MavlinkMessageInfo* FindMavlinkMessage(std::uint32_t msgid);

/// Where the known dialects come from: "<dialects> (mavlink-mappings <version>)".
std::string MavlinkDefinitionsSource();

/// Name of a message id of the known dialects ("RAW_IMU", "AHRS3", ...), else "MSG<id>".
std::string MavlinkMessageName(std::uint32_t msgid);

/// CRC_EXTRA of `msgid`, or -1 when it is in none of the known dialects (frame cannot be
/// checked).
int MavlinkCrcExtra(std::uint32_t msgid);

/// X.25 / CRC-16/MCRF4XX of `size` bytes continuing from `crc` (start with 0xFFFF).
std::uint16_t MavlinkCrc(const std::uint8_t* data, std::size_t size, std::uint16_t crc = 0xFFFF);

/// True when `size` >= 9 and `data` starts like a tlog record: an 8-byte big-endian time
/// between 2000-01-01 and 2100-01-01 (µs since the unix epoch), then 0xFE or 0xFD.
bool LooksLikeTlogRecord(const std::uint8_t* data, std::size_t size);

/// How ParseTlog and ReadTlog read: in one part, or, given run_jobs, a log of split_bytes
/// or more in two parts at once (plumb/io/common/split_read.h). A tlog has no definitions:
/// both parts start at once, the second at a chain of records found from
/// lead_bytes + second_part_at * (size - lead_bytes) on, and reads to the end; the log is the
/// same, to the byte, as read in one part.
using TlogReadOptions = SplitReadOptions;

/// Decodes a tlog held in memory; `source` names it in errors. Throws plumb::InputError(source,
/// "byte 0", ...) when not a single MAVLink frame is found.
MavlinkLog ParseTlog(const std::uint8_t* data, std::size_t size, const std::string& source,
                     const TlogReadOptions& options = {});

/// Reads and decodes a .tlog file. Throws plumb::InputError(path, "byte N", what) when it
/// cannot be read or holds no MAVLink frame.
MavlinkLog ReadTlog(const std::string& path, const TlogReadOptions& options = {});

}  // namespace plumb::io

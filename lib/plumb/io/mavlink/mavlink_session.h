// plumb/io/mavlink/mavlink_session.h — a MAVLink telemetry log (.tlog) as a plumb Session: its IMU
// streams, parameters, site, and ArduPilot's own correction undone.
//
// The vehicle: a tlog may hold several systems (vehicles, the ground station itself,
// companion computers). The autopilot is the (system id, component id) that sent the most IMU
// frames (RAW_IMU, SCALED_IMU*, HIGHRES_IMU; ties: the first seen); its HEARTBEAT's autopilot
// field says the firmware (MAV_AUTOPILOT: 3 = ArduPilotMega, 12 = PX4). Streams, parameters
// and GPS fixes are taken from that system only (parameters and GPS from any component of it).
//
// Streams (ImuStreamInfo): RAW_IMU (instance = its id field, 0 when absent), SCALED_IMU
// (instance 0), SCALED_IMU2 (1), SCALED_IMU3 (2), HIGHRES_IMU (instance = its id field).
// Units into the session (SI, body frame FRD as the messages state it):
//   SCALED_IMU*: acc mG * 9.80665e-3 -> m/s^2, gyr mrad/s * 1e-3 -> rad/s, temperature
//     cdegC * 0.01 -> degC (0 means "not provided");
//   RAW_IMU: the same on ArduPilot (which fills it with the corrected mG and mrad/s of
//     SCALED_IMU); from any other autopilot its values are raw sensor counts (acc_unit and
//     gyr_unit "counts");
//   HIGHRES_IMU: m/s^2, rad/s, degC as sent.
// The int16 messages quantise to 1 mG (0.0098 m/s^2) and 1 mrad/s.
// Time: sample times are the message's own time (time_usec / time_boot_ms, s; on ArduPilot
// since boot), so that the ground link's delays do not jitter them; the tlog time (unix s) is
// used only when a stream's message times are all zero. RAW_IMU times below 2^32 µs that fall
// back by more than 2^31 µs are unwrapped (ArduPilot 3.x sends a 32-bit micros()). A sample is
// dropped when its time does not exceed the last kept one's or is not below the next one's
// (a corrupted spike); drops are counted in the session's warnings. t_start_s/t_end_s and
// FlightLogSelection::from_s/to_s use the same times.
// ArduPilot's correction: on ArduPilot the samples are corrected with INS_ACC*OFFS/SCAL and
// INS_GYR*OFFS (instance 0 = RAW_IMU / SCALED_IMU, 1 = SCALED_IMU2, 2 = SCALED_IMU3); the
// session undoes it from the PARAM_VALUE messages (ardupilot_correction.h has the equations).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/session.h"
#include "plumb/io/common/flight_log.h"
#include "plumb/io/mavlink/mavlink_tlog.h"

namespace plumb::io {

/// MAV_AUTOPILOT values used here (common.xml / minimal.xml).
inline constexpr int kMavAutopilotArdupilotMega = 3;
inline constexpr int kMavAutopilotPx4 = 12;

/// The autopilot whose IMU messages a tlog holds.
struct MavlinkVehicle {
  std::uint8_t system_id = 0;      ///< MAVLink system id, 0..255
  std::uint8_t component_id = 0;   ///< component id that sent the IMU messages, 0..255
  /// MAV_AUTOPILOT from that component's HEARTBEAT; without one, 3 (ArduPilotMega) when the
  /// system sent an INS_ACCOFFS_X PARAM_VALUE, else -1 (unknown).
  int autopilot = -1;
  std::size_t imu_frames = 0;      ///< IMU frames it sent
  std::size_t other_sources = 0;   ///< other (system, component) pairs that sent IMU frames
};

/// The vehicle of the file comment, or nullopt when the log holds no IMU message.
std::optional<MavlinkVehicle> TlogVehicle(const MavlinkLog& log);

/// Every IMU stream of the vehicle (see the file comment), ordered RAW_IMU, SCALED_IMU,
/// SCALED_IMU2, SCALED_IMU3, HIGHRES_IMU, then by instance. `applied` is
/// ArdupilotCorrection::Describe on ArduPilot (INS_* offsets/scales, AHRS_ORIENTATION,
/// INS_TCAL), "" for RAW_IMU of other autopilots (raw counts) and "autopilot calibration
/// (unknown)" for their scaled messages; `undoable` is ArdupilotCorrection::Undoable.
std::vector<ImuStreamInfo> TlogImuStreams(const MavlinkLog& log);

/// The site from the vehicle's GPS_RAW_INT with fix_type >= 3: the median latitude and
/// longitude (degE7 * 1e-7 degrees) and altitude (alt, mm * 1e-3, above mean sea level, used as
/// the height: the geoid separation, tens of metres, changes gravity by about 1e-5 relative).
/// nullopt without such fixes.
std::optional<SiteInput> SiteFromTlog(const MavlinkLog& log);

/// Where the tlog's GPS_RAW_INT (vel, cm/s, with fix_type >= 3) says the vehicle moved
/// (core/log_motion.h), on the IMU stream's clock: each report placed by the IMU sample received
/// nearest to it (`log_time_s`, increasing, tlog time; `t_s`, that sample's time), since the
/// message's own time_usec may count from boot or from the unix epoch.
std::vector<LogMotion> TlogMotion(const MavlinkLog& log, const std::vector<double>& log_time_s,
                                  const std::vector<double>& t_s);

/// The vehicle's parameters from PARAM_VALUE (param_id up to its first NUL, last value wins).
/// ArduPilot (and any autopilot other than PX4) sends integer parameters converted to float
/// (MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_C_CAST), so the float is the value; PX4 sends them
/// byte-wise (the int32 bits in the float's bytes) and they are bit-cast back by param_type
/// (1..6: UINT8, INT8, UINT16, INT16, UINT32, INT32).
std::map<std::string, double> TlogParams(const MavlinkLog& log);

/// The session of one stream (selection.stream by name at instance selection.imu, or the only
/// instance of that name, e.g. "SCALED_IMU2"; else the default stream of instance
/// selection.imu: highest rate, then most samples), in SI FRD units, inside the
/// time window, with ArduPilot's correction undone when selection.undo_correction. Warnings
/// say which message the samples came from, in which units, what was reconstructed and what
/// taken as logged, plus the reader's own warnings. Throws plumb::InputError naming the log
/// when the stream is absent or the window holds fewer than 2 samples.
/// `chosen` (optional): set to the description of the stream read (its name and instance).
Session TlogSession(const MavlinkLog& log, const FlightLogSelection& selection,
                    ImuStreamInfo* chosen = nullptr);

/// The log as `plumb info` shows it: format "mavlink-tlog", format_detail "MAVLink v1 N
/// frames, v2 M frames (K signed), C CRC-checked, autopilot A (system S, component C)" (the
/// frames not CRC-checked are in a warning, by message id), the streams, the site,
/// the calibration parameters in force (names starting INS_ACC, INS_GYR, INS_TCAL,
/// AHRS_ORIENTATION, CAL_ACC, CAL_GYRO), the message counts by name and the reader's warnings.
FlightLogSummary TlogSummary(const MavlinkLog& log);

/// True when the file starts with a plausible tlog record: an 8-byte big-endian time between
/// 2000 and 2100 (µs since the unix epoch) followed by 0xFE or 0xFD.
bool LooksLikeTlog(const std::string& path);

}  // namespace plumb::io

// plumb/io/common/flight_log.h — what every flight-log reader offers, whatever the format.
//
// A flight log (ArduPilot DataFlash .bin or text .log, MAVLink .tlog, PX4 ULog .ulg, ROS 1
// .bag, ROS 2 .mcap or .db3) holds one or more IMU streams: a message or topic carrying accelerometer and/or
// gyroscope samples of one sensor instance (ArduPilot IMU/IMU2/ACC/GYR/ISBD, MAVLink
// RAW_IMU/SCALED_IMU2/HIGHRES_IMU, PX4 sensor_combined/sensor_accel/vehicle_imu, a ROS bag's
// sensor_msgs/Imu topics). Each format's reader lists its streams as
// ImuStreamInfo and turns one of them into a Session from a FlightLogSelection, undoing what the
// firmware applied before logging when the log says what that was.
//
// ReadFlightLog()/FlightLogSession() dispatch on the file's content (not its name).
#pragma once

#include <algorithm>
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/session.h"

namespace plumb::io {

/// One IMU stream of a log.
struct ImuStreamInfo {
  std::string name;          ///< message or topic name, e.g. "IMU2", "SCALED_IMU2", "sensor_combined"
  int instance = 0;          ///< sensor instance, 0-based, >= 0
  std::size_t samples = 0;   ///< samples in the log
  /// The stream's records (messages) in the log: more than `samples` when the reader left
  /// some out (a time not finite, not above the last kept one, or a spike above the next
  /// record's); DroppedRecordsWarning says so.
  std::size_t records = 0;
  /// The time as read (s; NaN for a stamp that is not a number) of the first record left
  /// out, when the reader knows it.
  std::optional<double> first_left_out_t_s;
  double rate_hz = 0.0;      ///< (samples - 1) / (t_end_s - t_start_s), Hz; 0 when undefined
  double t_start_s = 0.0;    ///< first sample's log time, s
  double t_end_s = 0.0;      ///< last sample's log time, s
  bool has_accel = true;     ///< the stream carries accelerometer samples
  bool has_gyro = true;      ///< the stream carries gyroscope samples
  bool has_temperature = false;  ///< the stream carries a sensor temperature
  /// What the firmware applied before logging, as the log states it: empty for the sensor's
  /// own output ("raw"), else e.g. "INS_ACCOFFS/INS_ACCSCAL, INS_GYROFFS" or "CAL_ACC0_*".
  std::string applied;
  /// True when the reader can undo `applied` from the log's own parameters.
  bool undoable = false;
};

/// The warning for the records of `info`'s stream a reader left out because of their times
/// ("IMU of IMU instance 0: left out 3 of 17070 records ..."), with the time of the first
/// left out when the reader knows it; nullopt when none was.
std::optional<std::string> DroppedRecordsWarning(const ImuStreamInfo& info);

/// Which samples of a log become the session.
struct FlightLogSelection {
  int imu = 0;                   ///< sensor instance, 0-based, >= 0
  /// Stream (message or topic) name; empty means the reader's default stream for `imu` (the
  /// one carrying both accelerometer and gyroscope at the highest rate). For a ROS bag, the
  /// topic (Option::kTopic); empty: the bag's only sensor_msgs/Imu topic.
  std::string stream;
  /// A ROS bag's record times (when the recorder received each message) instead of the
  /// messages' header stamps (Clock::kReceive); only bags have them.
  bool receive_time = false;
  std::optional<double> from_s;  ///< keep samples at or after this log time, s
  std::optional<double> to_s;    ///< keep samples at or before this log time, s
  bool undo_correction = true;   ///< recover the sensor's own output from the log's parameters
  /// The board's other IMUs to read besides `imu` (Session::other_imus; SPEC "Several IMUs of
  /// one board"): sensor instances, 0-based, in the order given, each read from the reader's
  /// default stream for that instance (as `imu` = k with an empty `stream` picks it; for a ROS
  /// bag, the IMU topic of index k) with the same window, clock and undo_correction as IMU 0.
  /// Each at most once, none equal to IMU 0's instance. Empty: IMU 0 alone. FlightLog::Select
  /// reads them; the formats' own session functions (ArdupilotSession, ...) ignore them.
  std::vector<int> other_imus;
};

/// A flight log's contents as `plumb info` shows them.
struct FlightLogSummary {
  std::string source;                  ///< file name
  std::string format;                  ///< "ardupilot-dataflash", "ardupilot-text", "mavlink-tlog", "px4-ulog", "ros1-bag", "ros2-mcap", "ros2-db3"
  std::string format_detail;           ///< e.g. "MAVLink v1+v2, 41230 frames", "ULog version 1"
  std::size_t size_bytes = 0;          ///< file size, bytes
  std::vector<ImuStreamInfo> imus;     ///< every IMU stream
  std::optional<SiteInput> site;       ///< from the log's GPS, when it has a fix
  /// Where the log says the vehicle flew or moved (its land detector, its GPS), on the IMU
  /// streams' clock (for a tlog, its first stream's).
  std::vector<LogMotion> motion;
  std::map<std::string, double> params;  ///< the calibration parameters in force (firmware names)
  std::vector<std::pair<std::string, std::size_t>> messages;  ///< (message, count), log order
  /// What the reader skipped or repaired, with counts (codes log_damaged, records_dropped:
  /// core/notice.h).
  std::vector<Notice> warnings;
};

/// The first and last sample times over the streams with samples, s ({0, 0} without any).
inline std::pair<double, double> LogSpan(const std::vector<ImuStreamInfo>& imus) {
  std::optional<std::pair<double, double>> span;
  for (const ImuStreamInfo& i : imus) {
    if (i.samples == 0) continue;
    if (!span) span = std::pair<double, double>{i.t_start_s, i.t_end_s};
    span->first = std::min(span->first, i.t_start_s);
    span->second = std::max(span->second, i.t_end_s);
  }
  return span.value_or(std::pair<double, double>{0.0, 0.0});
}

}  // namespace plumb::io

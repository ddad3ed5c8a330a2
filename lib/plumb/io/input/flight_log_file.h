// plumb/io/input/flight_log_file.h — any flight log plumb reads (ROS 1 and 2 bags included), opened by content: the format is
// recognised from the file's first bytes (not its name), the log decoded once, and then its
// summary (`plumb info`) and any number of sessions (calibrate, diagnose, report) come from it.
//
//   const FlightLog log = FlightLog::Open("00000042.BIN");
//   for (const ImuStreamInfo& s : log.Summary().imus) ...;
//   FlightLogSelection pick;  pick.imu = 1;  pick.to_s = 60.0;
//   const Session session = log.Select(pick);   // INS_* correction undone, site from GPS
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "plumb/core/session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/common/flight_log.h"
#include "plumb/io/mavlink/mavlink_tlog.h"
#include "plumb/io/px4/ulog.h"
#include "plumb/io/ros/db3.h"
#include "plumb/io/ros/mcap.h"
#include "plumb/io/ros/rosbag.h"

namespace plumb::io {

/// The flight-log formats plumb reads.
enum class FlightLogFormat {
  kNone,             ///< not a flight log plumb knows (a text table, say)
  kDataflashBinary,  ///< ArduPilot DataFlash .bin (0xA3 0x95 records)
  kDataflashText,    ///< ArduPilot text log .log ("FMT, ..." lines)
  kMavlinkTlog,      ///< MAVLink telemetry log .tlog (time-stamped v1/v2 frames)
  kPx4ULog,          ///< PX4 ULog .ulg ("ULog" magic)
  kRosBag,           ///< ROS 1 bag .bag ("#ROSBAG V" line; version 2.0 is read)
  kRos2Mcap,         ///< ROS 2 bag in MCAP .mcap (0x89 "MCAP" magic; version 0 is read)
  kRos2Db3,          ///< ROS 2 sqlite3 bag .db3 ("SQLite format 3\0", tables topics, messages)
};

/// True for the ROS bag formats (kRosBag, kRos2Mcap, kRos2Db3): sensor_msgs/Imu topics picked
/// by name (Option::kTopic), receive times (Clock::kReceive).
bool IsRosBag(FlightLogFormat format);

/// The format of the file at `path`, from its first bytes; kNone when it is none of them or
/// cannot be read.
FlightLogFormat SniffFlightLog(const std::string& path);

/// "ardupilot-dataflash", "ardupilot-text", "mavlink-tlog", "px4-ulog", "ros1-bag", "ros2-mcap",
/// "ros2-db3" ("none" for
/// kNone).
const char* FlightLogFormatName(FlightLogFormat format);

/// The instances InputOptions::all_imus reads besides IMU 0 (SPEC "Several IMUs of one
/// board"): every instance of summary.imus other than `imu0` with a stream of at least 2
/// samples that carries accelerometer samples, ascending, each once. A declared stream without
/// samples (an IMU3 format in a log that wrote no IMU3 record) is not one.
std::vector<int> BoardInstances(const FlightLogSummary& summary, int imu0);

/// A decoded flight log of any supported format.
class FlightLog {
 public:
  /// Reads and decodes the log at `path`. Throws plumb::InputError naming the file when it is
  /// not a flight log plumb reads, and as the format's reader does. `run_jobs` (core/jobs.h):
  /// a large .bin, .tlog or .ulg is read in two parts at once (SplitReadOptions), a large
  /// .mcap has its chunks decompressed ahead of their parse (ReadMcap); the same log either
  /// way. Empty: one part, on the calling thread.
  static FlightLog Open(const std::string& path, const JobRunner& run_jobs = {});

  FlightLogFormat format() const { return format_; }
  const std::string& source() const { return source_; }

  /// Every IMU stream, the site, the calibration parameters in force, the message counts and
  /// the reader's warnings.
  FlightLogSummary Summary() const;

  /// The session of the selected stream, with the firmware's correction undone when
  /// selection.undo_correction and the log says what it was (the session's warnings say which
  /// inputs were raw and which reconstructed), the site from the log's GPS. Throws
  /// plumb::InputError naming the log when the stream is absent or holds too few samples.
  /// selection.other_imus: Session::other_imus, one BoardImu per instance in that order, read
  /// as IMU 0 is (window, clock, undo_correction); their warnings join the session's, each
  /// prefixed "IMU instance k (STREAM): " (those the log's reading gives every stream, said
  /// once). Throws plumb::InputError naming the log and the instance when one is absent or
  /// holds too few samples, plumb::Error when one is listed twice or is IMU 0's.
  Session Select(const FlightLogSelection& selection) const;

 private:
  FlightLog() = default;
  /// The session of one stream (selection.other_imus not read), and that stream's description.
  Session SelectStream(const FlightLogSelection& selection, ImuStreamInfo* chosen) const;
  /// The board's IMU `instance` read as `imu0` (the selection of IMU 0) says; its warnings
  /// that `shared` (IMU 0's) lacks appended to `warnings`, prefixed with the instance.
  BoardImu SelectBoardImu(const FlightLogSelection& imu0, int instance,
                          const std::vector<Notice>& shared, std::vector<Notice>* warnings) const;
  FlightLogFormat format_ = FlightLogFormat::kNone;
  std::string source_;
  std::variant<DataflashLog, MavlinkLog, ULog, RosBag> log_;
};

}  // namespace plumb::io

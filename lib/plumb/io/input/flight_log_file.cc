// plumb/io/input/flight_log_file.cc — see flight_log_file.h.
#include "plumb/io/input/flight_log_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "plumb/core/error.h"
#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/mavlink/mavlink_session.h"
#include "plumb/io/px4/px4_session.h"
#include "plumb/io/ros/ros_session.h"
#include "plumb/io/common/stream_spool.h"

namespace plumb::io {
namespace {

/// ArduPilot's parameters that shape the logged IMU samples.
bool IsArdupilotCalibrationParameter(const std::string& name) {
  for (const char* prefix : {"INS_ACC", "INS_GYR", "INS_TCAL", "AHRS_ORIENTATION"}) {
    if (name.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

FlightLogSummary DataflashSummary(const DataflashLog& log, FlightLogFormat format) {
  FlightLogSummary out;
  out.source = log.source;
  out.format = FlightLogFormatName(format);
  out.format_detail = format == FlightLogFormat::kDataflashText
                          ? "ArduPilot text log"
                          : "ArduPilot DataFlash binary log";
  out.size_bytes = log.size_bytes;
  out.imus = DataflashImuStreams(log);
  out.site = SiteFromDataflash(log);
  out.motion = DataflashMotion(log, LogSpan(out.imus).second);
  for (const auto& [name, value] : log.params) {
    if (IsArdupilotCalibrationParameter(name)) out.params[name] = value;
  }
  out.messages = log.MessageCounts();
  AddNotices(out.warnings, "log_damaged", log.warnings.Describe());
  return out;
}

}  // namespace

FlightLogFormat SniffFlightLog(const std::string& path) {
  if (LooksLikeDataflash(path)) return FlightLogFormat::kDataflashBinary;
  if (LooksLikeULog(path)) return FlightLogFormat::kPx4ULog;
  if (LooksLikeRosBag(path)) return FlightLogFormat::kRosBag;
  if (LooksLikeMcap(path)) return FlightLogFormat::kRos2Mcap;
  if (LooksLikeDb3(path)) return FlightLogFormat::kRos2Db3;
  if (LooksLikeTlog(path)) return FlightLogFormat::kMavlinkTlog;
  if (LooksLikeDataflashText(path)) return FlightLogFormat::kDataflashText;
  return FlightLogFormat::kNone;
}

const char* FlightLogFormatName(FlightLogFormat format) {
  switch (format) {
    case FlightLogFormat::kDataflashBinary:
      return "ardupilot-dataflash";
    case FlightLogFormat::kDataflashText:
      return "ardupilot-text";
    case FlightLogFormat::kMavlinkTlog:
      return "mavlink-tlog";
    case FlightLogFormat::kPx4ULog:
      return "px4-ulog";
    case FlightLogFormat::kRosBag:
      return RosBagFormatName(RosBagKind::kRos1);
    case FlightLogFormat::kRos2Mcap:
      return RosBagFormatName(RosBagKind::kMcap);
    case FlightLogFormat::kRos2Db3:
      return RosBagFormatName(RosBagKind::kSqlite3);
    case FlightLogFormat::kNone:
      break;
  }
  return "none";
}

bool IsRosBag(FlightLogFormat format) {
  return format == FlightLogFormat::kRosBag || format == FlightLogFormat::kRos2Mcap ||
         format == FlightLogFormat::kRos2Db3;
}

namespace {

/// Two parts at once through `run_jobs` for a large log (the defaults of SplitReadOptions).
SplitReadOptions InParts(const JobRunner& run_jobs) {
  SplitReadOptions options;
  options.run_jobs = run_jobs;
  return options;
}

}  // namespace

FlightLog FlightLog::Open(const std::string& path, const JobRunner& run_jobs) {
  const StreamSpool stream({path}, StreamBound(0));  // a pipe: held already, or read whole now
  {  // a missing, unreadable or folder path says so (not "not a flight log")
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw InputError(path, "", "is a folder, not a file");
    std::ifstream probe(OpenPath(path), std::ios::binary);
    if (!probe) throw InputError(path, "", std::string("cannot open the file: ") + std::strerror(errno));
  }
  FlightLog out;
  out.source_ = path;
  out.format_ = SniffFlightLog(path);
  switch (out.format_) {
    case FlightLogFormat::kDataflashBinary:
      out.log_ = ReadDataflash(path, ArdupilotSessionRecords(), InParts(run_jobs));
      break;
    case FlightLogFormat::kDataflashText:
      out.log_ = ReadDataflashText(path, ArdupilotSessionRecords());
      break;
    case FlightLogFormat::kMavlinkTlog:
      out.log_ = ReadTlog(path, InParts(run_jobs));
      break;
    case FlightLogFormat::kPx4ULog:
      out.log_ = ReadULog(path, Px4SessionTopics(), InParts(run_jobs));
      break;
    case FlightLogFormat::kRosBag:
      out.log_ = ReadRosBag(path);
      break;
    case FlightLogFormat::kRos2Mcap:
      out.log_ = ReadMcap(path);
      break;
    case FlightLogFormat::kRos2Db3:
      out.log_ = ReadDb3(path);
      break;
    case FlightLogFormat::kNone:
      throw InputError(path, "byte 0",
                       "not a flight log plumb reads (ArduPilot DataFlash .bin or text .log, "
                       "MAVLink .tlog, PX4 ULog .ulg, ROS 1 bag .bag, ROS 2 bag .mcap or .db3)");
  }
  return out;
}

FlightLogSummary FlightLog::Summary() const {
  switch (format_) {
    case FlightLogFormat::kDataflashBinary:
    case FlightLogFormat::kDataflashText:
      return DataflashSummary(std::get<DataflashLog>(log_), format_);
    case FlightLogFormat::kMavlinkTlog:
      return TlogSummary(std::get<MavlinkLog>(log_));
    case FlightLogFormat::kPx4ULog:
      return ULogSummary(std::get<ULog>(log_));
    case FlightLogFormat::kRosBag:
    case FlightLogFormat::kRos2Mcap:
    case FlightLogFormat::kRos2Db3:
      return RosBagSummary(std::get<RosBag>(log_));
    case FlightLogFormat::kNone:
      break;
  }
  throw Error("FlightLog::Summary: no log");
}

Session FlightLog::Select(const FlightLogSelection& selection) const {
  if (selection.receive_time && !IsRosBag(format_)) {
    throw InputError(source_, "",
                     std::string(FlightLogFormatName(format_)) + " has no receive times (" +
                         OptionText(Option::kClock, "receive") + " is for ROS bags)",
                     {Option::kClock});
  }
  switch (format_) {
    case FlightLogFormat::kDataflashBinary:
    case FlightLogFormat::kDataflashText:
      return ArdupilotSession(std::get<DataflashLog>(log_), selection);
    case FlightLogFormat::kMavlinkTlog:
      return TlogSession(std::get<MavlinkLog>(log_), selection);
    case FlightLogFormat::kPx4ULog:
      return ULogSession(std::get<ULog>(log_), selection);
    case FlightLogFormat::kRosBag:
    case FlightLogFormat::kRos2Mcap:
    case FlightLogFormat::kRos2Db3:
      return RosBagSession(std::get<RosBag>(log_), selection);
    case FlightLogFormat::kNone:
      break;
  }
  throw Error("FlightLog::Select: no log");
}

}  // namespace plumb::io

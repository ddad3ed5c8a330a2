// plumb/io/input/flight_log_file.cc — see flight_log_file.h.
#include "plumb/io/input/flight_log_file.h"

#include <algorithm>
#include <cerrno>
#include <cstddef>
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
      out.log_ = ReadRosBag(path, run_jobs);
      break;
    case FlightLogFormat::kRos2Mcap:
      out.log_ = ReadMcap(path, run_jobs);
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

std::vector<int> BoardInstances(const FlightLogSummary& summary, int imu0) {
  std::vector<int> out;
  for (const ImuStreamInfo& i : summary.imus) {
    if (i.instance != imu0 && i.samples >= 2 && i.has_accel) out.push_back(i.instance);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {

/// Throws plumb::Error when `instances` (FlightLogSelection::other_imus) lists one twice or
/// lists `imu0`, IMU 0's instance (the board's IMUs are each read once).
void CheckBoardInstances(const std::string& source, const std::vector<int>& instances,
                         int imu0) {
  for (std::size_t i = 0; i < instances.size(); ++i) {
    const std::string k = std::to_string(instances[i]);
    if (instances[i] < 0) throw Error(source + ": board IMU instance " + k + " must be >= 0");
    if (instances[i] == imu0) {
      throw Error(source + ": IMU instance " + k +
                  " is IMU 0 (the body frame); list only the board's other IMUs");
    }
    if (std::find(instances.begin(), instances.begin() + static_cast<std::ptrdiff_t>(i),
                  instances[i]) != instances.begin() + static_cast<std::ptrdiff_t>(i)) {
      throw Error(source + ": IMU instance " + k + " is listed twice among the board's IMUs");
    }
  }
}

bool SameNotice(const Notice& a, const Notice& b) {
  return a.code == b.code && a.message == b.message;
}

}  // namespace

Session FlightLog::Select(const FlightLogSelection& selection) const {
  if (selection.receive_time && !IsRosBag(format_)) {
    throw InputError(source_, "",
                     std::string(FlightLogFormatName(format_)) + " has no receive times (" +
                         OptionText(Option::kClock, "receive") + " is for ROS bags)",
                     {Option::kClock});
  }
  ImuStreamInfo imu0;
  Session s = SelectStream(selection, &imu0);
  CheckBoardInstances(source_, selection.other_imus, imu0.instance);
  const std::vector<Notice> shared = s.warnings;  // IMU 0's: what the log says of every stream
  for (const int instance : selection.other_imus) {
    s.other_imus.push_back(SelectBoardImu(selection, instance, shared, &s.warnings));
  }
  return s;
}

BoardImu FlightLog::SelectBoardImu(const FlightLogSelection& imu0, int instance,
                                   const std::vector<Notice>& shared,
                                   std::vector<Notice>* warnings) const {
  FlightLogSelection one = imu0;  // the same window, clock and undo_correction
  one.imu = instance;
  one.stream.clear();  // the reader's default stream of the instance
  one.other_imus.clear();
  if (IsRosBag(format_)) {  // a bag's instance k is its IMU topic k (imu 0 picks no topic)
    const auto& topics = std::get<RosBag>(log_).imu_topics;
    if (static_cast<std::size_t>(instance) < topics.size()) {
      one.stream = topics[static_cast<std::size_t>(instance)].topic;
    }
  }
  ImuStreamInfo info;
  Session s = SelectStream(one, &info);
  BoardImu out;
  out.instance = instance;
  out.name = info.name;
  out.series = std::move(s.series);
  out.firmware_left = std::move(s.firmware_left);
  out.device_ids = s.device_ids;
  const std::string who = "IMU instance " + std::to_string(instance) + " (" + info.name + "): ";
  for (Notice& n : s.warnings) {
    const auto same = [&n](const Notice& m) { return SameNotice(n, m); };
    if (std::any_of(shared.begin(), shared.end(), same)) continue;  // said once, for IMU 0
    // The readers name the stream and instance in most of their messages ("IMU2 of IMU
    // instance 1: ..."); the others are prefixed with them.
    if (n.message.find(info.name) == std::string::npos) n.message = who + n.message;
    warnings->push_back(std::move(n));
  }
  return out;
}

Session FlightLog::SelectStream(const FlightLogSelection& selection,
                                ImuStreamInfo* chosen) const {
  switch (format_) {
    case FlightLogFormat::kDataflashBinary:
    case FlightLogFormat::kDataflashText:
      return ArdupilotSession(std::get<DataflashLog>(log_), selection, chosen);
    case FlightLogFormat::kMavlinkTlog:
      return TlogSession(std::get<MavlinkLog>(log_), selection, chosen);
    case FlightLogFormat::kPx4ULog:
      return ULogSession(std::get<ULog>(log_), selection, chosen);
    case FlightLogFormat::kRosBag:
    case FlightLogFormat::kRos2Mcap:
    case FlightLogFormat::kRos2Db3:
      return RosBagSession(std::get<RosBag>(log_), selection, chosen);
    case FlightLogFormat::kNone:
      break;
  }
  throw Error("FlightLog::Select: no log");
}

}  // namespace plumb::io

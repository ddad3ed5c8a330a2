// plumb/io/ros/ros_session.cc — see ros_session.h.
#include "plumb/io/ros/ros_session.h"

#include <string>
#include <utility>

#include "plumb/core/error.h"
#include "plumb/core/notice.h"
#include "plumb/core/option_name.h"
#include "plumb/io/common/log_common.h"

namespace plumb::io {
namespace {

/// The samples of `t` on the chosen clock, times not increasing left out.
struct Extracted {
  ImuSeries series;
  LeftOutTimes left_out;
};

/// True when `t` gives no angular_velocity (every covariance[0] is -1).
bool NoGyro(const RosImuTopic& t) {
  return !t.samples.empty() && t.gyr_not_given == t.samples.size();
}

Extracted Extract(const RosImuTopic& t, bool receive_time) {
  Extracted e;
  e.series = CopySeries(t.samples);
  if (receive_time) e.series.t_s = t.receive_s;
  if (NoGyro(t)) e.series.gyr.clear();
  e.left_out = KeepIncreasingTimes(e.series);
  return e;
}

ImuStreamInfo Describe(const RosImuTopic& t, int instance, const ImuSeries& s,
                       const LeftOutTimes& left_out) {
  ImuStreamInfo info = StreamInfoOf(s, left_out);
  info.name = t.topic;
  info.instance = instance;
  return info;
}

std::string TopicList(const RosBag& bag) {
  std::string out;
  for (const RosImuTopic& t : bag.imu_topics) {
    out += (out.empty() ? "" : ", ") + t.topic + " (" + std::to_string(t.samples.size()) +
           " messages)";
  }
  return out.empty() ? "none" : out;
}

/// The topic the selection names, or the bag's only IMU topic; throws otherwise.
std::size_t Choose(const RosBag& bag, const FlightLogSelection& selection) {
  const auto& topics = bag.imu_topics;
  if (!selection.stream.empty()) {
    for (std::size_t i = 0; i < topics.size(); ++i) {
      if (topics[i].topic == selection.stream) return i;
    }
    throw InputError(bag.source, "",
                     "no sensor_msgs/Imu topic " + selection.stream + "; its IMU topics: " +
                         TopicList(bag),
                     {Option::kTopic});
  }
  if (selection.imu > 0) {  // an instance other than the default: the IMU topic of that index
    if (static_cast<std::size_t>(selection.imu) < topics.size()) {
      return static_cast<std::size_t>(selection.imu);
    }
    throw InputError(bag.source, "",
                     "no IMU instance " + std::to_string(selection.imu) + "; its IMU topics: " +
                         TopicList(bag),
                     {Option::kTopic});
  }
  if (topics.size() == 1) return 0;
  if (topics.empty()) {
    throw InputError(bag.source, "", "no sensor_msgs/Imu topic in the bag");
  }
  throw InputError(bag.source, "",
                   "the bag has " + std::to_string(topics.size()) + " sensor_msgs/Imu topics (" +
                       TopicList(bag) + "); pick one with " + OptionText(Option::kTopic, "NAME"),
                   {Option::kTopic});
}

/// The sample_source and sample_times notices of topic `t`.
void SayWhat(const RosImuTopic& t, bool receive_time, std::vector<Notice>* out) {
  std::string source =
      t.topic + ": sensor_msgs/Imu linear_acceleration (m/s^2) and angular_velocity (rad/s) " +
      "as logged, in frame '" + t.frame_id +
      "' (REP-103: x forward, y left, z up); the sensor's axes are kept as logged, not turned "
      "into FRD, and whatever the driver applied before publishing stays in the samples; "
      "orientation and covariances are not used";
  if (t.orientation_zero > 0) {
    source += " (" + std::to_string(t.orientation_zero) + " message(s) with an all-zero orientation)";
  }
  AddNotice(*out, "sample_source", std::move(source));
  if (NoGyro(t)) {
    AddNotice(*out, "sample_source",
              t.topic + ": every angular_velocity_covariance[0] is -1 (not given): "
                        "accelerometer only");
  }
  if (t.md5_differs) {
    AddNotice(*out, "log_damaged",
              t.topic + ": a connection's sensor_msgs/Imu md5sum is not " + kRosImuMd5 +
                  "; decoded by the standard layout where the size fits");
  }
  AddNotice(*out, "sample_times",
            receive_time ? t.topic + ": times are the bag's record times (when the recorder "
                                     "received each message), s since the unix epoch"
                         : t.topic + ": times are the messages' header stamps, s since the "
                                     "unix epoch");
}

std::string FormatDetail(const RosBag& bag) {
  const auto n = [](std::size_t v) { return std::to_string(v); };
  if (bag.kind == RosBagKind::kSqlite3) {
    return "ROS 2 sqlite3 bag, " + n(bag.connections.size()) + " topics";
  }
  std::string chunks;
  for (const auto& [compression, count] : bag.compression) {
    chunks += (chunks.empty() ? "" : ", ") + compression + " " + n(count);
  }
  const std::string chunk_text =
      n(bag.chunks) + " chunks" + (chunks.empty() ? "" : " (" + chunks + ")");
  if (bag.kind == RosBagKind::kMcap) {
    return "MCAP, " + chunk_text + ", " + n(bag.connections.size()) + " channels";
  }
  return "ROS bag 2.0, " + chunk_text + ", " + n(bag.connections.size()) + " connections, " +
         (bag.chunk_infos > 0 ? "indexed" : "no index (read linearly)");
}

}  // namespace

const char* RosBagFormatName(RosBagKind kind) {
  switch (kind) {
    case RosBagKind::kMcap: return "ros2-mcap";
    case RosBagKind::kSqlite3: return "ros2-db3";
    case RosBagKind::kRos1: break;
  }
  return "ros1-bag";
}

bool IsRosBag(const std::string& format) {
  for (const RosBagKind kind : {RosBagKind::kRos1, RosBagKind::kMcap, RosBagKind::kSqlite3}) {
    if (format == RosBagFormatName(kind)) return true;
  }
  return false;
}

std::vector<ImuStreamInfo> RosBagImuStreams(const RosBag& bag) {
  std::vector<ImuStreamInfo> out;
  for (std::size_t i = 0; i < bag.imu_topics.size(); ++i) {
    const RosImuTopic& t = bag.imu_topics[i];
    const Extracted e = Extract(t, false);
    out.push_back(Describe(t, static_cast<int>(i), e.series, e.left_out));
  }
  return out;
}

Session RosBagSession(const RosBag& bag, const FlightLogSelection& selection,
                      ImuStreamInfo* chosen_info) {
  const std::size_t chosen = Choose(bag, selection);
  const RosImuTopic& t = bag.imu_topics[chosen];
  if (!t.samples.empty() && t.acc_not_given == t.samples.size()) {
    throw InputError(bag.source, t.topic,
                     "every linear_acceleration_covariance[0] is -1: the topic gives no "
                     "accelerometer samples");
  }
  Extracted e = Extract(t, selection.receive_time);
  const ImuStreamInfo info = Describe(t, static_cast<int>(chosen), e.series, e.left_out);
  if (chosen_info != nullptr) *chosen_info = info;
  Session s;
  s.source = bag.source + " (" + t.topic + ")";
  for (const std::string& w : bag.warnings.Describe()) {
    AddNotice(s.warnings, "log_damaged", bag.source + ": " + w);
  }
  if (auto w = DroppedRecordsWarning(info)) AddNotice(s.warnings, "records_dropped", *w);
  SayWhat(t, selection.receive_time, &s.warnings);
  const ImuSeries& whole = e.series;
  s.series = WindowOf(whole, selection);
  if (s.series.size() < 2) {
    throw InputError(bag.source, t.topic,
                     EmptyWindowMessage(selection.from_s, selection.to_s,
                                        whole.empty() ? 0.0 : whole.t_s.front(),
                                        whole.empty() ? 0.0 : whole.t_s.back()));
  }
  return s;
}

FlightLogSummary RosBagSummary(const RosBag& bag) {
  FlightLogSummary out;
  out.source = bag.source;
  out.format = RosBagFormatName(bag.kind);
  out.format_detail = FormatDetail(bag);
  out.size_bytes = bag.size_bytes;
  out.imus = RosBagImuStreams(bag);
  out.messages = bag.MessageCounts();
  AddNotices(out.warnings, "log_damaged", bag.warnings.Describe());
  return out;
}

}  // namespace plumb::io

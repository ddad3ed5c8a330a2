// plumb/io/ros/ros_session.h — a ROS bag (ROS 1 .bag: rosbag.h; ROS 2 MCAP: mcap.h; ROS 2
// sqlite3 .db3: db3.h; all read into a RosBag) as plumb IMU streams and Sessions.
//
// IMU streams: one per sensor_msgs/Imu topic, named by the topic ("/imu/data_raw"), instance =
// its index among the bag's IMU topics (order of first connection). accel =
// linear_acceleration (m/s^2), gyro = angular_velocity (rad/s), as logged: the message's own
// frame (REP-103 asks for x forward, y left, z up: FLU), not turned into FRD. plumb calibrates
// the sensor's axes as the log gives them, as it does for every log (the ArduPilot and PX4
// readers take their firmware's FRD as logged too); the session's sample_source warning says
// the frame. Whatever the driver applied before publishing stays in the samples (a bag does
// not say what). orientation and the covariances are not used; a topic whose every
// angular_velocity_covariance[0] is -1 ("not given") is accelerometer-only.
//
// Time: header.stamp (sec + nsec * 1e-9, s since the unix epoch, as a .tlog's times), or with
// FlightLogSelection::receive_time the record time (when the recorder received the message:
// ROS 1 the record's time, MCAP the message's log_time, .db3 the messages table's timestamp).
// Samples whose time does not increase are left out (KeepIncreasingTimes, counted in a
// records_dropped warning).
#pragma once

#include <string>
#include <vector>

#include "plumb/core/session.h"
#include "plumb/io/common/flight_log.h"
#include "plumb/io/ros/rosbag.h"

namespace plumb::io {

/// "ros1-bag", "ros2-mcap", "ros2-db3": the format names of FlightLogSummary::format.
const char* RosBagFormatName(RosBagKind kind);

/// True when `format` (FlightLogSummary::format) is one of a ROS bag's (RosBagFormatName).
bool IsRosBag(const std::string& format);

/// Every IMU stream of `bag` (see the file comment), on header stamps.
std::vector<ImuStreamInfo> RosBagImuStreams(const RosBag& bag);

/// The session of one topic: selection.stream (the topic), else the IMU topic of instance
/// selection.imu when it is above 0 (the default 0 does not pick among several), else the bag's
/// only IMU topic;
/// windowed to [from_s, to_s] on the chosen clock. Throws plumb::InputError naming the bag when
/// the topic is absent (listing the IMU topics), when several IMU topics and none is named
/// (pointing to Option::kTopic), when the topic gives no linear_acceleration, or when the
/// window holds fewer than 2 samples.
/// `chosen` (optional): set to the description of the stream read (its name and instance).
Session RosBagSession(const RosBag& bag, const FlightLogSelection& selection,
                      ImuStreamInfo* chosen = nullptr);

/// The bag as `plumb info` shows it: format RosBagFormatName(bag.kind), format_detail "ROS bag
/// 2.0, N chunks (bz2 4), K connections, indexed", "MCAP, N chunks (zstd N), K channels" or
/// "ROS 2 sqlite3 bag, K topics", the IMU streams, message counts per "topic (type)" and the
/// reader's warnings.
FlightLogSummary RosBagSummary(const RosBag& bag);

}  // namespace plumb::io

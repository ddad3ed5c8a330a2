// plumb/io/ros/ros_imu.h — what the ROS 1 and ROS 2 bag readers share: one decoded
// sensor_msgs/Imu message, whatever its serialization (ROS 1's, or CDR for ROS 2:
// DecodeCdrImu), and how it becomes a sample of a bag's IMU topic (RosBag, rosbag.h), so that
// one session builder (ros_session.h) serves every bag format. Internal to io/ros.
//
// CDR (OMG XCDR1, as ROS 2's rmw implementations write it) of sensor_msgs/msg/Imu: a 4-byte
// encapsulation header (0x00 0x01: little endian, 0x00 0x00: big endian; two option bytes),
// then, each primitive aligned to its size relative to the byte after that header:
//   std_msgs/Header: builtin_interfaces/Time stamp (int32 sec, uint32 nanosec),
//                    string frame_id (uint32 length counting the NUL, the bytes, the NUL);
//   geometry_msgs/Quaternion orientation (4 float64 x y z w, aligned to 8);
//   float64[9] orientation_covariance; geometry_msgs/Vector3 angular_velocity (3 float64);
//   float64[9] angular_velocity_covariance; geometry_msgs/Vector3 linear_acceleration;
//   float64[9] linear_acceleration_covariance.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "plumb/core/types.h"
#include "plumb/io/ros/rosbag.h"

namespace plumb::io::detail {

/// One decoded sensor_msgs/Imu message.
struct RosImuMessage {
  std::int64_t sec = 0;             ///< header.stamp (ROS 1 uint32, ROS 2 int32)
  std::uint32_t nsec = 0;
  std::string_view frame_id;
  double orientation[4] = {};       ///< x y z w
  double orientation_cov0 = 0.0;
  Vec3 gyr = Vec3::Zero();          ///< angular_velocity, rad/s
  double gyr_cov0 = 0.0;
  Vec3 acc = Vec3::Zero();          ///< linear_acceleration, m/s^2
  double acc_cov0 = 0.0;
};

/// Decodes a CDR-serialized sensor_msgs/msg/Imu [p, p + n) (see the file comment). False, with
/// `why` (the byte offset in the message and what was wrong), when the encapsulation is not
/// plain CDR, the frame_id's length runs past the data or lacks its NUL, or the data ends
/// before the last covariance. Bytes past the message are allowed (CDR pads to 4).
bool DecodeCdrImu(const std::uint8_t* p, std::size_t n, RosImuMessage* out, std::string* why);

/// The index in bag->imu_topics of the sensor_msgs/Imu topic `topic`, added when new.
int ImuTopicIndex(RosBag* bag, const std::string& topic);

/// Appends `m` to `t`: its sample (header stamp, acc and gyr as float), the receive time
/// receive_sec + receive_nsec * 1e-9, and the counts of covariances not given and all-zero
/// orientations; the topic's frame_id from its first message.
void AppendImu(RosImuTopic* t, const RosImuMessage& m, std::int64_t receive_sec,
               std::uint32_t receive_nsec);

/// Splits a time in nanoseconds (MCAP's log_time, a .db3 timestamp) into seconds and
/// nanoseconds (0 to 999999999) for AppendImu.
inline void SplitNanoseconds(std::int64_t ns, std::int64_t* sec, std::uint32_t* nsec) {
  std::int64_t s = ns / 1000000000;
  std::int64_t r = ns % 1000000000;
  if (r < 0) {
    r += 1000000000;
    --s;
  }
  *sec = s;
  *nsec = static_cast<std::uint32_t>(r);
}

}  // namespace plumb::io::detail

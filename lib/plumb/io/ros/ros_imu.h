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
#include "plumb/io/common/log_common.h"
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

/// The doubles after the frame_id: orientation (4), its covariance (9), angular_velocity (3),
/// its covariance (9), linear_acceleration (3), its covariance (9).
inline constexpr std::size_t kCdrImuDoubles = 4 + 9 + 3 + 9 + 3 + 9;

/// Fills the message's doubles from `d(i)`, the i-th double after the frame_id. Only the 13
/// used are read (the other covariances' 25 are not).
template <typename Double>
void TakeCdrImuDoubles(Double d, RosImuMessage* out) {
  for (std::size_t i = 0; i < 4; ++i) out->orientation[i] = d(i);
  out->orientation_cov0 = d(4);
  out->gyr = Vec3(d(13), d(14), d(15));
  out->gyr_cov0 = d(16);
  out->acc = Vec3(d(25), d(26), d(27));
  out->acc_cov0 = d(28);
}

/// Where the doubles of [p, p + n) start, counted from p, when it is the usual message:
/// little endian (0x00 0x01), its frame_id ending in its NUL and all its doubles there (its
/// fields then at offsets fixed by the frame_id's length, checked at once); 0 for any other,
/// which DecodeCdrImu's general path decodes or says what is wrong with.
inline std::size_t CdrImuDoublesAt(const std::uint8_t* p, std::size_t n) {
  if (n < 16 || p[0] != 0x00 || p[1] != 0x01) return 0;
  const std::size_t body = n - 4;  // the bytes after the encapsulation header
  const std::uint32_t len = LoadLittleEndian<std::uint32_t>(p + 12);
  if (len == 0 || len > body - 12 || p[16 + std::size_t{len} - 1] != 0) return 0;
  // The doubles start at the frame_id's end aligned to 8 (relative to p + 4).
  const std::size_t doubles = (12 + std::size_t{len} + 7) & ~std::size_t{7};
  if (doubles > body || body - doubles < kCdrImuDoubles * 8) return 0;
  return 4 + doubles;
}

/// The frame_id of a message CdrImuDoublesAt takes.
inline std::string_view CdrImuFrameId(const std::uint8_t* p) {
  return std::string_view(reinterpret_cast<const char*>(p + 16),
                          LoadLittleEndian<std::uint32_t>(p + 12) - 1);
}

/// DecodeCdrImu's path for the usual message (CdrImuDoublesAt). False, `out` untouched, for
/// any other. Inline: a reader calls it once per message.
inline bool DecodeCdrImuFast(const std::uint8_t* p, std::size_t n, RosImuMessage* out) {
  const std::size_t at = CdrImuDoublesAt(p, n);
  if (at == 0) return false;
  out->sec = LoadLittleEndian<std::int32_t>(p + 4);
  out->nsec = LoadLittleEndian<std::uint32_t>(p + 8);
  out->frame_id = CdrImuFrameId(p);
  const std::uint8_t* d = p + at;
  TakeCdrImuDoubles([d](std::size_t i) { return LoadLittleEndian<double>(d + 8 * i); }, out);
  return true;
}

/// The index in bag->imu_topics of the sensor_msgs/Imu topic `topic`, added when new.
int ImuTopicIndex(RosBag* bag, const std::string& topic);

/// t->frame_id: `frame_id`'s first 256 bytes (set at a topic's first message).
void SetFrameId(RosImuTopic* t, std::string_view frame_id);

/// Appends one sample to `t`: the header stamp sec + nsec * 1e-9 (s), the receive time
/// receive_sec + receive_nsec * 1e-9 (s), acc (m/s^2) and gyr (rad/s) as float, beyond the
/// float range +-infinity (SaturatedFloat). Shared by AppendImu and AppendCdrImuFast.
inline void AppendSample(RosImuTopic* t, std::int64_t sec, std::uint32_t nsec,
                         std::int64_t receive_sec, std::uint32_t receive_nsec, const Vec3& acc,
                         const Vec3& gyr) {
  t->samples.t_s.push_back(static_cast<double>(sec) + static_cast<double>(nsec) * 1e-9);
  t->receive_s.push_back(static_cast<double>(receive_sec) +
                         static_cast<double>(receive_nsec) * 1e-9);
  t->samples.acc.push_back(SaturatedFloat(acc));
  t->samples.gyr.push_back(SaturatedFloat(gyr));
}

/// Counts a message's covariances not given (their first element -1, ROS's convention) and an
/// all-zero orientation quaternion (none given). Comparisons added as 0 or 1: no branch that
/// the data decides.
inline void CountNotGiven(RosImuTopic* t, double orientation_cov0, double gyr_cov0,
                          double acc_cov0, const double (&orientation)[4]) {
  t->orientation_not_given += orientation_cov0 == -1.0;
  t->gyr_not_given += gyr_cov0 == -1.0;
  t->acc_not_given += acc_cov0 == -1.0;
  t->orientation_zero += (orientation[0] == 0.0) & (orientation[1] == 0.0) &
                         (orientation[2] == 0.0) & (orientation[3] == 0.0);
}

/// Appends `m` to `t`: its sample (header stamp, acc and gyr as float), the receive time
/// receive_sec + receive_nsec * 1e-9, and the counts of covariances not given and all-zero
/// orientations; the topic's frame_id from its first message. Inline: the readers call it
/// once per message.
inline void AppendImu(RosImuTopic* t, const RosImuMessage& m, std::int64_t receive_sec,
                      std::uint32_t receive_nsec) {
  if (t->samples.empty()) SetFrameId(t, m.frame_id);
  AppendSample(t, m.sec, m.nsec, receive_sec, receive_nsec, m.acc, m.gyr);
  CountNotGiven(t, m.orientation_cov0, m.gyr_cov0, m.acc_cov0, m.orientation);
}

/// DecodeCdrImu and AppendImu at once for the usual message (CdrImuDoublesAt): the same
/// sample and counts, its 13 doubles read straight from the message's bytes at their fixed
/// offsets. False, `t` untouched, for any other message, which DecodeCdrImu then decodes (or
/// says what is wrong with).
inline bool AppendCdrImuFast(RosImuTopic* t, const std::uint8_t* p, std::size_t n,
                             std::int64_t receive_sec, std::uint32_t receive_nsec) {
  const std::size_t at = CdrImuDoublesAt(p, n);
  if (at == 0) return false;
  const std::uint8_t* d = p + at;
  const auto v = [d](std::size_t i) { return LoadLittleEndian<double>(d + 8 * i); };
  if (t->samples.empty()) SetFrameId(t, CdrImuFrameId(p));
  AppendSample(t, LoadLittleEndian<std::int32_t>(p + 4), LoadLittleEndian<std::uint32_t>(p + 8),
               receive_sec, receive_nsec, Vec3(v(25), v(26), v(27)), Vec3(v(13), v(14), v(15)));
  const double orientation[4] = {v(0), v(1), v(2), v(3)};
  CountNotGiven(t, v(4), v(16), v(28), orientation);
  return true;
}

/// Room for `n` samples in all in `t`'s vectors (samples.t_s, acc, gyr and receive_s,
/// together: std::vector::reserve), so that appending does not grow them one doubling at a
/// time. Returns the samples all four have room for (at least `n`).
std::size_t ReserveImu(RosImuTopic* t, std::size_t n);

/// Grows `t`'s vectors, full, to the samples the file holds if the rest of it is like the part
/// read (the topic's samples per byte of file so far, `read_to` bytes of `size` read, the
/// record being read counted whole, an eighth more), at least 1.5 times their size (twice, and
/// 1024 at least, before the projection means anything: `read_to` 0 when it does not) and at
/// most 16 times. A file of one IMU topic throughout is read with a few reallocations, each a
/// copy of all the samples so far, instead of one at every doubling; a file whose first part
/// misleads the projection costs at most the growth doubling would (the 16 times bound the
/// room reserved ahead, its pages never touched). Returns the samples it has room for.
std::size_t ReserveImuAhead(RosImuTopic* t, std::size_t read_to, std::size_t size);

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

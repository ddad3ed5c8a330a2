// plumb/io/ros/ros_imu.cc — see ros_imu.h.
#include "plumb/io/ros/ros_imu.h"

#include <algorithm>
#include <cstring>

#include "plumb/io/common/log_common.h"

namespace plumb::io::detail {
namespace {

/// Reads CDR primitives of one byte order from [p, p + n), aligned relative to p.
class CdrCursor {
 public:
  CdrCursor(const std::uint8_t* p, std::size_t n, bool little) : p_(p), n_(n), little_(little) {}

  std::size_t pos() const { return pos_; }

  /// Aligns to `size` and checks that `size` * `count` bytes follow. False when they do not.
  bool Need(std::size_t size, std::size_t count) {
    const std::size_t aligned = (pos_ + size - 1) / size * size;
    if (aligned > n_ || (n_ - aligned) / size < count) return false;
    pos_ = aligned;
    return true;
  }
  template <typename T>
  T Read() {  // after Need(sizeof(T), ...)
    const T v = At<T>(0);
    pos_ += sizeof(T);
    return v;
  }
  /// The T `offset` bytes on (within what Need checked), the cursor left where it is.
  template <typename T>
  T At(std::size_t offset) const {
    if (little_) return LoadLittleEndian<T>(p_ + pos_ + offset);
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, p_ + pos_ + offset, sizeof(T));
    std::reverse(b, b + sizeof(T));
    return LoadLittleEndian<T>(b);
  }
  const std::uint8_t* here() const { return p_ + pos_; }
  void Skip(std::size_t bytes) { pos_ += bytes; }

 private:
  const std::uint8_t* p_;
  std::size_t n_;
  bool little_;
  std::size_t pos_ = 0;
};

/// DecodeCdrImu in general: either byte order, every fault said. DecodeCdrImuFast gives the
/// same values for the messages it takes.
bool DecodeCdrImuChecked(const std::uint8_t* p, std::size_t n, RosImuMessage* out,
                         std::string* why) {
  if (n < 4) {
    *why = "byte 0: " + std::to_string(n) + " bytes, less than the CDR encapsulation header";
    return false;
  }
  if (p[0] != 0x00 || (p[1] != 0x00 && p[1] != 0x01)) {
    *why = "byte 0: encapsulation " + std::to_string(p[0]) + " " + std::to_string(p[1]) +
           " is not plain CDR (0 1 little endian, 0 0 big endian)";
    return false;
  }
  CdrCursor c(p + 4, n - 4, p[1] == 0x01);
  const auto at = [&c](const std::string& what) {
    return "byte " + std::to_string(4 + c.pos()) + ": the message ends in " + what;
  };
  if (!c.Need(4, 3)) {
    *why = at("its header");
    return false;
  }
  out->sec = c.Read<std::int32_t>();
  out->nsec = c.Read<std::uint32_t>();
  const std::uint32_t len = c.Read<std::uint32_t>();
  if (!c.Need(1, len)) {
    *why = at("header.frame_id (length " + std::to_string(len) + ")");
    return false;
  }
  if (len == 0 || c.here()[len - 1] != 0) {
    *why = "byte " + std::to_string(4 + c.pos()) + ": header.frame_id of length " +
           std::to_string(len) + " without its terminating NUL";
    return false;
  }
  out->frame_id = std::string_view(reinterpret_cast<const char*>(c.here()), len - 1);
  c.Skip(len);
  if (!c.Need(8, kCdrImuDoubles)) {
    *why = at("its orientation, velocities or covariances (" +
              std::to_string(kCdrImuDoubles * 8) + " bytes from there)");
    return false;
  }
  TakeCdrImuDoubles([&c](std::size_t i) { return c.At<double>(8 * i); }, out);
  return true;
}

}  // namespace

bool DecodeCdrImu(const std::uint8_t* p, std::size_t n, RosImuMessage* out, std::string* why) {
  return DecodeCdrImuFast(p, n, out) || DecodeCdrImuChecked(p, n, out, why);
}

int ImuTopicIndex(RosBag* bag, const std::string& topic) {
  auto& topics = bag->imu_topics;
  const auto it = std::find_if(topics.begin(), topics.end(),
                               [&](const RosImuTopic& t) { return t.topic == topic; });
  const int index = static_cast<int>(it - topics.begin());
  if (it == topics.end()) {
    topics.emplace_back();
    topics.back().topic = topic;
  }
  return index;
}

void SetFrameId(RosImuTopic* t, std::string_view frame_id) {
  t->frame_id = std::string(frame_id.substr(0, 256));
}

std::size_t ReserveImuAhead(RosImuTopic* t, std::size_t read_to, std::size_t size) {
  const std::size_t n = t->samples.t_s.size();
  std::size_t want = std::max<std::size_t>(2 * n, 1024);
  if (n >= 1024 && read_to > 0 && read_to < size) {
    const double projected = static_cast<double>(n) *
                             (static_cast<double>(size) / static_cast<double>(read_to)) * 1.125;
    want = std::max<std::size_t>(
        n + n / 2, static_cast<std::size_t>(std::min(projected, 16.0 * static_cast<double>(n))));
  }
  return ReserveImu(t, want);
}

std::size_t ReserveImu(RosImuTopic* t, std::size_t n) {
  t->samples.t_s.reserve(n);
  t->samples.acc.reserve(n);
  t->samples.gyr.reserve(n);
  t->receive_s.reserve(n);
  return std::min({t->samples.t_s.capacity(), t->samples.acc.capacity(),
                   t->samples.gyr.capacity(), t->receive_s.capacity()});
}

}  // namespace plumb::io::detail

// All a ROS bag reader gives, as text (tests/io, and the rosbag and mcap fuzz targets): its
// counts, connections, warnings and the samples' bits, or the error it throws, so that two
// readings of a file compare whole (the chunks read ahead or not).
#pragma once

#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/io/ros/rosbag.h"

namespace plumb::test {

/// The bytes of `v`, appended to `out`: samples compared bit for bit.
template <typename T>
void AppendBytes(std::ostringstream& out, const std::vector<T>& v) {
  out.write(reinterpret_cast<const char*>(v.data()),
            static_cast<std::streamsize>(v.size() * sizeof(T)));
}

/// What `read()` gives (an io::RosBag) as text, or the plumb::Error it throws (an InputError's
/// file, place and words).
inline std::string BagText(const std::function<io::RosBag()>& read) {
  std::ostringstream out;
  try {
    const io::RosBag bag = read();
    out << bag.chunks << ' ' << bag.messages << ' ' << bag.chunk_infos << ' ' << bag.index_pos
        << '\n';
    for (const auto& [c, n] : bag.compression) out << c << ' ' << n << '\n';
    for (const auto& [id, c] : bag.connections) {
      out << id << ' ' << c.topic << ' ' << c.type << ' ' << c.messages << '\n';
    }
    const io::RosBagWarnings& w = bag.warnings;
    out << w.cut_at.value_or(0) << ' ' << w.cut_messages_kept << ' ' << w.messages_read << ' '
        << w.index_past_end << ' ' << w.bad_records << ' ' << w.first_bad_record << ' '
        << w.damaged_chunks << ' ' << w.first_damaged_chunk << ' ' << w.first_damage << ' '
        << w.unknown_ops << ' ' << w.orphan_messages << ' ' << w.first_orphan << ' '
        << w.malformed_imu << ' ' << w.first_malformed_imu << ' ' << w.first_malformed_why
        << '\n';
    for (const std::string& line : w.Describe()) out << line << '\n';
    for (const io::RosImuTopic& t : bag.imu_topics) {
      out << t.topic << ' ' << t.frame_id << ' ' << t.malformed << ' ' << t.samples.size() << ' '
          << t.acc_not_given << ' ' << t.gyr_not_given << ' ' << t.orientation_not_given << ' '
          << t.orientation_zero << '\n';
      AppendBytes(out, t.samples.t_s);
      AppendBytes(out, t.samples.acc);
      AppendBytes(out, t.samples.gyr);
      AppendBytes(out, t.receive_s);
    }
  } catch (const InputError& e) {
    out << "InputError " << e.file() << ' ' << e.where() << ' ' << e.what();
  } catch (const Error& e) {
    out << "Error " << e.what();
  }
  return out.str();
}

/// Runs the jobs on this thread, the last first: a reading must not depend on their order.
inline void Backwards(int count, const std::function<void(int)>& job) {
  for (int k = count - 1; k >= 0; --k) job(k);
}

}  // namespace plumb::test

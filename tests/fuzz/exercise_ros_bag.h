// What the ROS bag readers' fuzz targets (rosbag, mcap, db3) do with the bag parsed from their
// bytes: its warnings, counts and summary, and every IMU stream's session on both clocks
// (header stamps and receive times), where a plumb::Error is an accepted answer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "plumb/core/error.h"
#include "plumb/io/ros/ros_session.h"
#include "plumb/io/ros/rosbag.h"

#include "select_every_stream.h"

namespace plumb::fuzz {

/// Parses [data, data + size) with `parse(data, size, name)` (ParseRosBag, ParseMcap, ParseDb3)
/// and uses everything it gives.
template <typename Parse>
void ExerciseRosBag(const std::uint8_t* data, std::size_t size, Parse parse) {
  try {
    const io::RosBag bag = parse(data, size, std::string("fuzz"));
    (void)bag.warnings.Describe();
    (void)bag.MessageCounts();
    (void)io::RosBagSummary(bag);
    for (const bool receive : {false, true}) {
      SelectEveryStream(io::RosBagImuStreams(bag), [&](io::FlightLogSelection selection) {
        selection.receive_time = receive;
        (void)io::RosBagSession(bag, selection);
      });
    }
  } catch (const Error&) {
  }
}

}  // namespace plumb::fuzz

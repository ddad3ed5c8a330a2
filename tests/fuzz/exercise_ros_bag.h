// What the ROS bag readers' fuzz targets (rosbag, mcap, db3) do with the bag parsed from their
// bytes: its warnings, counts and summary, and every IMU stream's session on both clocks
// (header stamps and receive times), where a plumb::Error is an accepted answer; and for the
// readers that read chunks ahead (rosbag, mcap), the same bytes read ahead: the same bag or the
// same error, else the target aborts.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <string>

#include "plumb/core/error.h"
#include "plumb/core/jobs.h"
#include "plumb/io/ros/ros_session.h"
#include "plumb/io/ros/rosbag.h"

#include "../io/ros_bag_text.h"
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

/// [data, data + size) read in order (`in_order(data, size, name)`) and with every chunk read
/// ahead through a runner that runs the jobs on this thread, the last first
/// (`ahead(data, size, name, runner, 0)`, detail::ParseRosBagReadingAhead or
/// detail::ParseMcapReadingAhead): aborts unless both give the same.
template <typename InOrder, typename Ahead>
void ExerciseReadAhead(const std::uint8_t* data, std::size_t size, InOrder in_order,
                       Ahead ahead) {
  const JobRunner backwards = [](int count, const std::function<void(int)>& job) {
    for (int k = count - 1; k >= 0; --k) job(k);
  };
  const std::string name = "fuzz";
  if (test::BagText([&] { return in_order(data, size, name); }) !=
      test::BagText([&] { return ahead(data, size, name, backwards, 0); })) {
    std::abort();
  }
}

}  // namespace plumb::fuzz

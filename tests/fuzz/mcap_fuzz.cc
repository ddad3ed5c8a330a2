// libFuzzer target for the ROS 2 MCAP reader: any byte sequence must yield a RosBag or a
// plumb::Error, never a crash, a hang or a huge allocation (a chunk's stated size is never allocated ahead of its data; every CDR length is
// checked); the streams and sessions built from whatever was decoded must behave the same
// way, on both clocks. Seeds: tests/fuzz/seeds/mcap (CMakeLists.txt says where they come from).
#include <cstddef>
#include <cstdint>

#include "plumb/core/error.h"
#include "plumb/io/ros/mcap.h"
#include "plumb/io/ros/ros_session.h"

#include "select_every_stream.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const plumb::io::RosBag bag = plumb::io::ParseMcap(data, size, "fuzz");
    (void)bag.warnings.Describe();
    (void)bag.MessageCounts();
    (void)plumb::io::RosBagSummary(bag);
    for (const bool receive : {false, true}) {
      plumb::fuzz::SelectEveryStream(
          plumb::io::RosBagImuStreams(bag), [&](plumb::io::FlightLogSelection selection) {
            selection.receive_time = receive;
            (void)plumb::io::RosBagSession(bag, selection);
          });
    }
  } catch (const plumb::Error&) {
  }
  return 0;
}

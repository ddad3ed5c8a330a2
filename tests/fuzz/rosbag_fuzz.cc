// libFuzzer target for the ROS 1 bag reader: any byte sequence must yield a RosBag or a
// plumb::Error, never a crash, a hang or a huge allocation (a chunk's stated size is never
// allocated ahead of its data); the streams and sessions built from whatever was decoded must
// behave the same way, on both clocks.
//   clang++ -fsanitize=fuzzer,address,undefined -std=c++17 -I lib -I <eigen> \
//     tests/fuzz/rosbag_fuzz.cc lib/plumb/io/ros/rosbag_format.cc lib/plumb/io/ros/rosbag.cc \
//     lib/plumb/io/ros/ros_session.cc lib/plumb/io/common/log_common.cc \
//     lib/plumb/io/common/mapping_guard.cc lib/plumb/io/common/stream_spool.cc \
//     lib/plumb/core/imu_series.cc lib/plumb/core/error.cc lib/plumb/core/number_text.cc \
//     lib/plumb/core/option_name.cc -lbz2 -llz4
#include <cstddef>
#include <cstdint>

#include "plumb/core/error.h"
#include "plumb/io/ros/ros_session.h"
#include "plumb/io/ros/rosbag.h"

#include "select_every_stream.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const plumb::io::RosBag bag = plumb::io::ParseRosBag(data, size, "fuzz");
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

// libFuzzer target for the ROS 2 MCAP reader: any byte sequence must yield a RosBag or a
// plumb::Error, never a crash, a hang or a huge allocation (a chunk's stated size is never allocated ahead of its data; every CDR length is
// checked); the streams and sessions built from whatever was decoded must behave the same
// way, on both clocks. Seeds: tests/fuzz/seeds/mcap (CMakeLists.txt says where they come from).
#include <cstddef>
#include <cstdint>

#include "plumb/io/ros/mcap.h"

#include "exercise_ros_bag.h"
#include "plumb/io/ros/read_ahead.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  plumb::fuzz::ExerciseRosBag(data, size, plumb::io::ParseMcap);
  plumb::fuzz::ExerciseReadAhead(data, size, plumb::io::ParseMcap,
                                 plumb::io::detail::ParseMcapReadingAhead);
  return 0;
}

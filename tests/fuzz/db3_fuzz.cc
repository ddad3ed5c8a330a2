// libFuzzer target for the ROS 2 sqlite3 (.db3) reader (sqlite3_deserialize, read-only): any byte sequence must yield a RosBag or a
// plumb::Error, never a crash, a hang or a huge allocation (every CDR length is
// checked); the streams and sessions built from whatever was decoded must behave the same
// way, on both clocks. Seeds: tests/fuzz/seeds/db3 (CMakeLists.txt says where they come from).
#include <cstddef>
#include <cstdint>

#include "plumb/io/ros/db3.h"

#include "exercise_ros_bag.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  plumb::fuzz::ExerciseRosBag(data, size, plumb::io::ParseDb3);
  return 0;
}

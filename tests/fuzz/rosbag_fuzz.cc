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

#include "plumb/io/ros/rosbag.h"

#include "exercise_ros_bag.h"
#include "plumb/io/ros/read_ahead.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  plumb::fuzz::ExerciseRosBag(data, size, plumb::io::ParseRosBag);
  plumb::fuzz::ExerciseReadAhead(data, size, plumb::io::ParseRosBag,
                                 plumb::io::detail::ParseRosBagReadingAhead);
  return 0;
}

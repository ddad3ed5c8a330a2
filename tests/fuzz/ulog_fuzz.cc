// libFuzzer target for the PX4 ULog reader: any byte sequence must yield a ULog or a
// plumb::Error, never a crash, a hang or a huge allocation; the streams and sessions built
// from whatever was decoded must behave the same way.
//   clang++ -fsanitize=fuzzer,address,undefined -std=c++17 -I lib -I <eigen> \
//     tests/fuzz/ulog_fuzz.cc lib/plumb/io/px4/ulog_format.cc lib/plumb/io/px4/ulog_parser.cc \
//     lib/plumb/io/px4/ulog_two_part.cc lib/plumb/io/px4/ulog.cc \
//     lib/plumb/io/px4/px4_session.cc lib/plumb/io/px4/px4_correction.cc \
//     lib/plumb/io/common/log_common.cc lib/plumb/io/common/mapping_guard.cc \
//     lib/plumb/io/common/stream_spool.cc lib/plumb/core/imu_series.cc \
//     lib/plumb/core/error.cc lib/plumb/core/number_text.cc
#include <cstddef>
#include <cstdint>

#include "plumb/core/error.h"
#include "plumb/io/px4/px4_session.h"
#include "plumb/io/px4/ulog.h"

#include "select_every_stream.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Every topic kept, then the session's filter (sensor_combined decoded in the read pass).
  for (const bool session_filter : {false, true}) {
    try {
      const plumb::io::ULog log = plumb::io::ParseULog(
          data, size, "fuzz", session_filter ? plumb::io::Px4SessionTopics() : plumb::io::RecordFilter{});
      (void)log.warnings.Describe();
      (void)plumb::io::SiteFromULog(log);
      (void)plumb::io::ULogParams(log);
      plumb::fuzz::SelectEveryStream(
          plumb::io::ULogImuStreams(log),
          [&](const plumb::io::FlightLogSelection& selection) {
            (void)plumb::io::ULogSession(log, selection);
          });
    } catch (const plumb::Error&) {
    }
  }
  return 0;
}

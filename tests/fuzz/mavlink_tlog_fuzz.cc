// libFuzzer target for the MAVLink tlog reader: any byte sequence must either decode or throw
// plumb::Error, never crash, hang or read out of bounds; then every stream of whatever was
// decoded becomes a session the same way.
//
// Built by tests/fuzz/CMakeLists.txt (scripts/fuzz); by hand:
//   clang++ -fsanitize=fuzzer,address,undefined -std=c++17 -I lib -I /usr/include/eigen3 \
//     -I build/lib/plumb/io/mavlink/generated \
//     tests/fuzz/mavlink_tlog_fuzz.cc lib/plumb/io/mavlink/mavlink_dialect.cc \
//     lib/plumb/io/mavlink/mavlink_frame.cc lib/plumb/io/mavlink/mavlink_tlog.cc \
//     lib/plumb/io/mavlink/mavlink_session.cc lib/plumb/io/ardupilot/ardupilot_correction.cc \
//     lib/plumb/io/common/log_common.cc lib/plumb/io/common/mapping_guard.cc \
//     lib/plumb/io/common/stream_spool.cc lib/plumb/core/imu_series.cc \
//     lib/plumb/core/error.cc lib/plumb/core/number_text.cc
#include <cstddef>
#include <cstdint>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/io/mavlink/mavlink_session.h"
#include "plumb/io/mavlink/mavlink_tlog.h"

#include "select_every_stream.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const plumb::io::MavlinkLog log = plumb::io::ParseTlog(data, size, "fuzz.tlog");
    (void)plumb::io::TlogParams(log);
    (void)plumb::io::SiteFromTlog(log);
    plumb::fuzz::SelectEveryStream(
        plumb::io::TlogImuStreams(log),
        [&](const plumb::io::FlightLogSelection& selection) {
          (void)plumb::io::TlogSession(log, selection);
        });
  } catch (const plumb::Error&) {
  }
  return 0;
}

// libFuzzer target: any byte sequence as an ArduPilot DataFlash .bin log. Decoding (all records,
// and with the session's filter), listing
// the IMU streams and making each one a session (ArduPilot's correction undone) must either
// succeed or throw plumb::Error; never crash, hang or read out of bounds (build with
// -fsanitize=fuzzer,address,undefined).
#include <cstddef>
#include <cstdint>

#include "plumb/core/error.h"
#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/common/flight_log.h"

#include "select_every_stream.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Every record kept, then the session's filter (its IMU messages decoded in the read pass).
  for (const bool session_filter : {false, true}) {
    try {
      const plumb::io::DataflashLog log = plumb::io::ParseDataflash(
          data, size, "fuzz.bin",
          session_filter ? plumb::io::ArdupilotSessionRecords() : plumb::io::RecordFilter{});
      plumb::fuzz::SelectEveryStream(
          plumb::io::DataflashImuStreams(log),
          [&](const plumb::io::FlightLogSelection& selection) {
            (void)plumb::io::ArdupilotSession(log, selection);
          });
    } catch (const plumb::Error&) {
    }
  }
  return 0;
}

// libFuzzer target: any byte sequence as an ArduPilot DataFlash .bin log. Decoding, listing
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
  try {
    const plumb::io::DataflashLog log = plumb::io::ParseDataflash(data, size, "fuzz.bin");
    plumb::fuzz::SelectEveryStream(
        plumb::io::DataflashImuStreams(log),
        [&](const plumb::io::FlightLogSelection& selection) {
          (void)plumb::io::ArdupilotSession(log, selection);
        });
  } catch (const plumb::Error&) {
  }
  return 0;
}

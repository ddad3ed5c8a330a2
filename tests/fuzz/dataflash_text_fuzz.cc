// libFuzzer target: any byte sequence as an ArduPilot TEXT log (.log). Decoding, listing the
// IMU streams and reading every one of them must either succeed or throw plumb::Error; never
// crash, hang or read out of bounds (build with -fsanitize=fuzzer,address,undefined).
#include <cstddef>
#include <cstdint>

#include "plumb/core/error.h"
#include "plumb/io/dataflash.h"
#include "plumb/io/flight_log.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const plumb::io::DataflashLog log = plumb::io::ParseDataflashText(
        reinterpret_cast<const char*>(data), size, "fuzz.log");
    for (const plumb::io::ImuStreamInfo& info : plumb::io::DataflashImuStreams(log)) {
      plumb::io::FlightLogSelection selection;
      selection.imu = info.instance;
      selection.stream = info.name;
      try {
        plumb::io::DataflashStream(log, selection);
      } catch (const plumb::Error&) {
      }
    }
  } catch (const plumb::Error&) {
  }
  return 0;
}

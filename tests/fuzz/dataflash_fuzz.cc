// libFuzzer target: the DataFlash binary reader and the IMU stream extraction on any bytes.
// Contract (SPEC section 8): never crash; bad input is a plumb::Error or a warning count.
#include <cstddef>
#include <cstdint>

#include "plumb/core/error.h"
#include "plumb/io/dataflash.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const plumb::io::DataflashLog log = plumb::io::ParseDataflash(data, size, "fuzz.bin");
    for (const auto& imu : plumb::io::DataflashImuInstances(log)) {
      try {
        (void)plumb::io::ImuFromDataflash(log, imu.instance);
      } catch (const plumb::Error&) {
      }
    }
  } catch (const plumb::Error&) {
  }
  return 0;
}

// libFuzzer target, differential: any byte sequence as an ArduPilot DataFlash .bin log decoded
// in two parts (DataflashReadOptions) must give the very log decoded in one part, or the same
// error (split_read_differential.h); never crash, hang or read out of bounds (build with
// -fsanitize=fuzzer,address,undefined).
#include <cstddef>
#include <cstdint>

#include "../support/dataflash_log_difference.h"
#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "split_read_differential.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  plumb::fuzz::CheckSplitRead(
      data, size, plumb::io::ArdupilotSessionRecords(),
      [](const uint8_t* bytes, size_t n, const plumb::io::RecordFilter& filter,
         const plumb::io::DataflashReadOptions& options) {
        return plumb::io::ParseDataflash(bytes, n, "fuzz.bin", filter, options);
      },
      plumb::testing::DataflashLogDifference);
  return 0;
}

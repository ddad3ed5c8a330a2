// libFuzzer target, differential: any byte sequence as a MAVLink tlog decoded in two parts
// (TlogReadOptions) must give the very log decoded in one part, or the same error
// (split_read_differential.h); never crash, hang or read out of bounds (build with
// -fsanitize=fuzzer,address,undefined).
#include <cstddef>
#include <cstdint>

#include "../support/mavlink_log_difference.h"
#include "plumb/io/mavlink/mavlink_tlog.h"
#include "split_read_differential.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  plumb::fuzz::CheckSplitReadOf(
      size,
      [&](const plumb::io::TlogReadOptions& options) {
        return plumb::io::ParseTlog(data, size, "fuzz.tlog", options);
      },
      plumb::testing::MavlinkLogDifference, "tlog");
  return 0;
}

// libFuzzer target, differential: any byte sequence as a PX4 ULog decoded in two parts
// (ULogReadOptions) must give the very log decoded in one part, or the same error
// (split_read_differential.h); never crash, hang or read out of bounds (build with
// -fsanitize=fuzzer,address,undefined).
#include <cstddef>
#include <cstdint>

#include "../support/ulog_log_difference.h"
#include "plumb/io/px4/px4_session.h"
#include "plumb/io/px4/ulog.h"
#include "split_read_differential.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  plumb::fuzz::CheckSplitRead(
      data, size, plumb::io::Px4SessionTopics(),
      [](const uint8_t* bytes, size_t n, const plumb::io::RecordFilter& filter,
         const plumb::io::ULogReadOptions& options) {
        return plumb::io::ParseULog(bytes, n, "fuzz.ulg", filter, options);
      },
      plumb::testing::ULogDifference);
  return 0;
}

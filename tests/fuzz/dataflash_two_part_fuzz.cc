// libFuzzer target, differential: any byte sequence as an ArduPilot DataFlash .bin log decoded
// in two parts (DataflashReadOptions: a first part from the start, a second from a record
// boundary guessed at several places, joined) must give the very log decoded in one part, or
// the same error; never crash, hang or read out of bounds (build with
// -fsanitize=fuzzer,address,undefined). A difference aborts, naming it.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "../support/dataflash_log_difference.h"
#include "plumb/core/error.h"
#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"

namespace {

/// The log of `data`, or the error's text (in `error`) when it throws.
plumb::io::DataflashLog Decode(const uint8_t* data, size_t size,
                               const plumb::io::RecordFilter& filter,
                               const plumb::io::DataflashReadOptions& options,
                               std::string* error) {
  try {
    return plumb::io::ParseDataflash(data, size, "fuzz.bin", filter, options);
  } catch (const plumb::Error& e) {
    *error = e.what();
    return {};
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const plumb::JobRunner in_order = [](int count, const std::function<void(int)>& job) {
    for (int k = 0; k < count; ++k) job(k);
  };
  for (const bool session_filter : {false, true}) {
    const plumb::io::RecordFilter filter =
        session_filter ? plumb::io::ArdupilotSessionRecords() : plumb::io::RecordFilter{};
    std::string one_error;
    const plumb::io::DataflashLog one = Decode(data, size, filter, {}, &one_error);
    for (const double at : {0.0, 0.37, 0.71}) {
      plumb::io::DataflashReadOptions options;
      options.run_jobs = in_order;
      options.two_part_bytes = 0;
      options.lead_bytes = size / 8;
      options.second_part_at = at;
      std::string two_error;
      const plumb::io::DataflashLog two = Decode(data, size, filter, options, &two_error);
      const std::string difference = one_error != two_error
                                         ? "error: \"" + one_error + "\" != \"" + two_error + "\""
                                         : plumb::testing::DataflashLogDifference(one, two);
      if (!difference.empty()) {
        std::fprintf(stderr, "two-part read differs (filter %d, at %.2f): %s\n",
                     session_filter ? 1 : 0, at, difference.c_str());
        std::abort();
      }
    }
  }
  return 0;
}

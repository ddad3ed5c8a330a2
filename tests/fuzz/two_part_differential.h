// tests/fuzz/two_part_differential.h — the differential check of a reader's two-part read
// (TwoPartReadOptions, plumb/io/common/two_part_read.h) for the fuzz targets
// dataflash_two_part, ulog_two_part and mavlink_tlog_two_part: any byte sequence decoded in two
// parts (a first part from the start, a second from a record boundary guessed at several places,
// joined) must give the very log decoded in one part, or the same error. A difference aborts,
// naming it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/two_part_read.h"

namespace plumb::fuzz {

/// Checks `parse(options) -> Log`, which decodes `size` bytes, in two parts against one part,
/// `difference(a, b)` naming what differs ("" when nothing does); `label` says what is checked
/// in the message when something does.
template <class Parse, class Difference>
void CheckTwoPartReadOf(std::size_t size, const Parse& parse, const Difference& difference,
                        const std::string& label) {
  const JobRunner in_order = [](int count, const std::function<void(int)>& job) {
    for (int k = 0; k < count; ++k) job(k);
  };
  // The log, or the error's text (in `error`) when it throws.
  const auto decode = [&](const io::TwoPartReadOptions& options, std::string* error) {
    try {
      return parse(options);
    } catch (const Error& e) {
      *error = e.what();
      return decltype(parse(options)){};
    }
  };
  std::string one_error;
  const auto one = decode({}, &one_error);
  for (const double at : {0.0, 0.37, 0.71}) {
    io::TwoPartReadOptions options;
    options.run_jobs = in_order;
    options.two_part_bytes = 0;
    options.lead_bytes = size / 8;
    options.second_part_at = at;
    std::string two_error;
    const auto two = decode(options, &two_error);
    const std::string what = one_error != two_error
                                 ? "error: \"" + one_error + "\" != \"" + two_error + "\""
                                 : difference(one, two);
    if (!what.empty()) {
      std::fprintf(stderr, "two-part read differs (%s at %.2f): %s\n", label.c_str(), at,
                   what.c_str());
      std::abort();
    }
  }
}

/// Checks `parse(data, size, filter, options) -> Log` in two parts against one part with each
/// of `filters` (every record kept, then `session`), `difference(a, b)` naming what differs
/// ("" when nothing does).
template <class Parse, class Difference>
void CheckTwoPartRead(const std::uint8_t* data, std::size_t size, const io::RecordFilter& session,
                      const Parse& parse, const Difference& difference) {
  for (const bool session_filter : {false, true}) {
    const io::RecordFilter filter = session_filter ? session : io::RecordFilter{};
    CheckTwoPartReadOf(
        size, [&](const io::TwoPartReadOptions& options) {
          return parse(data, size, filter, options);
        },
        difference, session_filter ? "session filter" : "no filter");
  }
}

}  // namespace plumb::fuzz

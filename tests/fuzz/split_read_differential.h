// tests/fuzz/split_read_differential.h — the differential check of a reader's read in parts
// (SplitReadOptions, plumb/io/common/split_read.h) for the fuzz targets
// dataflash_two_part, ulog_two_part and mavlink_tlog_two_part: any byte sequence decoded in
// parts (a first part from the start, the others from record boundaries guessed at several
// places, joined: two parts, then five and eight) must give the very log decoded in one part,
// or the same error. A difference aborts, naming it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/common/split_read.h"
#include "../support/split_read_testing.h"

namespace plumb::fuzz {

/// Checks `parse(options) -> Log`, which decodes `size` bytes, in parts against one part,
/// `difference(a, b)` naming what differs ("" when nothing does); `label` says what is checked
/// in the message when something does.
template <class Parse, class Difference>
void CheckSplitReadOf(std::size_t size, const Parse& parse, const Difference& difference,
                        const std::string& label) {
  // The log, or the error's text (in `error`) when it throws.
  const auto decode = [&](const io::SplitReadOptions& options, std::string* error) {
    try {
      return parse(options);
    } catch (const Error& e) {
      *error = e.what();
      return decltype(parse(options)){};
    }
  };
  std::string one_error;
  const auto one = decode({}, &one_error);
  // Two parts from three places, then five and eight parts.
  const struct {
    int parts;
    double at;
  } splits[] = {{2, 0.0}, {2, 0.37}, {2, 0.71}, {5, 0.2}, {8, 0.125}};
  for (const auto& split : splits) {
    const double at = split.at;
    const io::SplitReadOptions options =
        testing::TwoParts(size / 8, at, testing::InOrder, split.parts);
    std::string two_error;
    const auto two = decode(options, &two_error);
    const std::string what = one_error != two_error
                                 ? "error: \"" + one_error + "\" != \"" + two_error + "\""
                                 : difference(one, two);
    if (!what.empty()) {
      std::fprintf(stderr, "read in %d parts differs (%s at %.3f): %s\n", split.parts,
                   label.c_str(), at, what.c_str());
      std::abort();
    }
  }
}

/// Checks `parse(data, size, filter, options) -> Log` in parts against one part with each
/// of `filters` (every record kept, then `session`), `difference(a, b)` naming what differs
/// ("" when nothing does).
template <class Parse, class Difference>
void CheckSplitRead(const std::uint8_t* data, std::size_t size, const io::RecordFilter& session,
                      const Parse& parse, const Difference& difference) {
  for (const bool session_filter : {false, true}) {
    const io::RecordFilter filter = session_filter ? session : io::RecordFilter{};
    CheckSplitReadOf(
        size, [&](const io::SplitReadOptions& options) {
          return parse(data, size, filter, options);
        },
        difference, session_filter ? "session filter" : "no filter");
  }
}

}  // namespace plumb::fuzz

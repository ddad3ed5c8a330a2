// plumb/io/common/two_part_read.h — reading a large log in two parts at once, for readers whose
// parser decides each record from a bounded look-ahead (the DataFlash .bin and ULog readers; the
// tlog reader, whose parser holds no definitions and looks ahead without bound over the mapped
// file, takes TwoPartReadOptions and the boundary constants below but joins its own way).
//
// The first part is read alone for a lead (the log's definitions); a second parser, made from
// the first and knowing what it knows then (Parser::Ahead), starts at a record boundary guessed
// near the middle of the rest, while the first reads on to that byte. The second part counts
// only when the first ends exactly on its start; it stops, leaving the rest to the first, at
// anything it cannot decide as the first would there; what it decoded is joined to what the
// first did (Parser::Absorb) as one parser going through both parts would have it. So the log
// is the same, to the byte, as read in one part.
//
// The parser concept (DataflashParser, the ULog parser):
//   Feed(data, n, offset, at_end) -> offset     the one-pass decoder (see ReadForward)
//   kUntilSlack                                 bytes past `until` Feed may be given: with them
//                                               it decodes no record starting at `until` or
//                                               after, and reaches `until` exactly when a
//                                               record ends there
//   Ahead(Log* out) const -> Parser             the second part's parser, decoding into `out`
//   FeedAhead(data, n, offset) -> offset        its Feed: stops (stopped()) where it cannot go on
//   stopped() -> bool
//   FindRecordChain(data, n, records) const     first position in [0, n) where `records` records
//                                               this parser would decode follow one another; n
//   Absorb(ahead, ahead_log, run_jobs) -> bool  the join; false (nothing changed) when it fails
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/jobs.h"
#include "plumb/io/common/log_common.h"

namespace plumb::io {

/// How a reader reads a file: in one part, or in two at once (see the file comment).
struct TwoPartReadOptions {
  /// Runs independent jobs at once (core/jobs.h). When given, an input of `two_part_bytes` or
  /// more is read in two parts at once. Empty: one part.
  JobRunner run_jobs;
  /// Inputs from this size on are read in two parts when run_jobs is given (32 MiB: below, a
  /// part takes a few milliseconds, what starting and joining it costs).
  std::size_t two_part_bytes = std::size_t{32} << 20;
  /// Bytes read alone before the second part starts: what the second part knows is what is
  /// defined in them (the logs' definitions come first; a definition met later stops the
  /// second part there). 1 MiB.
  std::size_t lead_bytes = std::size_t{1} << 20;
  /// Where the second part's start is looked for, as a fraction of the bytes after the lead
  /// (0.5: the middle, which gives both parts the same bytes).
  double second_part_at = 0.5;
};

/// Hands an input's bytes from offset `from` on to `consume` as ReadForward does: a file span
/// by span, bytes in memory in one call that ends them.
using ByteSource = std::function<void(std::size_t from, const ForwardConsumer& consume)>;

/// The ByteSource of the file at `path` (ReadForward with `lookahead`; `what` names the format).
inline ByteSource FileBytes(const std::string& path, const std::string& what,
                            std::size_t lookahead) {
  return [path, what, lookahead](std::size_t from, const ForwardConsumer& consume) {
    ReadForward(path, what, lookahead, consume, from);
  };
}

/// The ByteSource of `size` bytes held at `data` (not copied: they must outlive it).
inline ByteSource MemoryBytes(const std::uint8_t* data, std::size_t size) {
  return [data, size](std::size_t from, const ForwardConsumer& consume) {
    from = std::min(from, size);
    consume(data + from, size - from, from, true);
  };
}

/// Appends the samples [first, end) of `more` to `s`, each column (times, accelerometer,
/// gyroscope, temperature; those `more` lacks stay as they are) a job run through `run_jobs`:
/// the join of a second part's decoded samples to the first's.
inline void AppendSamples(ImuSeries& s, const ImuSeries& more, std::size_t first,
                          const JobRunner& run_jobs) {
  const auto append = [first](auto& out, const auto& in) {
    out.insert(out.end(), in.begin() + static_cast<std::ptrdiff_t>(std::min(first, in.size())),
               in.end());
  };
  RunJobs(run_jobs, 4, [&](int column) {  // each job appends its own column
    if (column == 0) append(s.t_s, more.t_s);
    if (column == 1) append(s.acc, more.acc);
    if (column == 2) append(s.gyr, more.gyr);
    if (column == 3) append(s.temp_c, more.temp_c);
  });
}

namespace detail {

/// Bytes looked at from the second part's nominal start for a record boundary.
inline constexpr std::size_t kBoundaryWindow = std::size_t{64} << 10;
/// Records in a row that make a guessed record boundary.
inline constexpr int kBoundaryRecords = 16;

/// Decodes the records of `source` starting in [from, until) into `parser`; returns the offset
/// it reached: `until` when a record ends there, past it when one starting before it runs on.
template <class Parser>
std::size_t DecodeUntil(const ByteSource& source, Parser& parser, std::size_t from,
                        std::size_t until) {
  std::size_t reached = from;
  source(from, [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
    const std::size_t limit = until - offset + Parser::kUntilSlack;
    if (n < limit && !at_end) return parser.Feed(data, n, offset, false);
    reached = parser.Feed(data, std::min(n, limit), offset, false);
    return kStopReading;
  });
  return reached;
}

/// Decodes the records of `source` from `from` on into `ahead` (Parser::Ahead) until it stops;
/// returns the offset it reached.
template <class Parser>
std::size_t DecodeAhead(const ByteSource& source, Parser& ahead, std::size_t from) {
  std::size_t reached = from;
  source(from, [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
    reached = ahead.FeedAhead(data, n, offset);
    return ahead.stopped() || at_end ? kStopReading : reached;
  });
  return reached;
}

/// A record boundary at byte `from` or after in `source`, as `parser` makes one
/// (FindRecordChain over kBoundaryWindow bytes); nullopt when none is found.
template <class Parser>
std::optional<std::size_t> RecordBoundary(const ByteSource& source, const Parser& parser,
                                          std::size_t from) {
  std::optional<std::size_t> found;
  source(from, [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool) {
    const std::size_t window = std::min(n, kBoundaryWindow);
    const std::size_t at = parser.FindRecordChain(data, window, kBoundaryRecords);
    if (at < window) found = offset + at;
    return kStopReading;
  });
  return found;
}

/// Decodes `source` (`size` bytes) into `parser` in two parts at once through options.run_jobs
/// (TwoPartReadOptions); `Log` is what Parser::Ahead decodes into. Returns the offset from
/// which the input is still to be decoded (by `parser`'s Feed): where the second part stopped,
/// or, when it does not count, where the first did.
template <class Log, class Parser>
std::size_t DecodeInTwo(const ByteSource& source, std::size_t size, Parser& parser,
                        const TwoPartReadOptions& options) {
  const std::size_t lead = DecodeUntil(source, parser, 0, std::min(options.lead_bytes, size));
  const double at = std::clamp(options.second_part_at, 0.0, 1.0);
  const auto nominal = lead + static_cast<std::size_t>(at * static_cast<double>(size - lead));
  const std::optional<std::size_t> start = RecordBoundary(source, parser, nominal);
  if (!start || *start <= lead) return lead;
  Log ahead_log;
  Parser ahead = parser.Ahead(&ahead_log);
  std::size_t reached = lead;
  std::size_t stop = *start;
  std::exception_ptr first_failed;
  bool ahead_failed = false;
  RunJobs(options.run_jobs, 2, [&](int job) {
    try {
      if (job == 0) {
        reached = DecodeUntil(source, parser, lead, *start);
      } else {
        stop = DecodeAhead(source, ahead, *start);
      }
    } catch (...) {  // the jobs throw nothing (core/jobs.h)
      if (job == 0) {
        first_failed = std::current_exception();
      } else {
        ahead_failed = true;
      }
    }
  });
  if (first_failed) std::rethrow_exception(first_failed);
  // The second part counts when the first ended exactly on its start (the guess was a record
  // boundary) and what it decoded joins; else the first part goes on alone from where it is
  // (and meets the second part's read error, if there was one, itself).
  if (ahead_failed || reached != *start || !parser.Absorb(ahead, ahead_log, options.run_jobs)) {
    return reached;
  }
  return stop;
}

/// The offset from which `parser` is to decode `source` (`size` bytes; 0: unknown) in one
/// pass: 0, or, when options call for two parts, where DecodeInTwo left it.
template <class Log, class Parser>
std::size_t DecodeStart(const ByteSource& source, std::size_t size, Parser& parser,
                        const TwoPartReadOptions& options) {
  if (!options.run_jobs || size == 0 || size < options.two_part_bytes) return 0;
  return DecodeInTwo<Log>(source, size, parser, options);
}

}  // namespace detail
}  // namespace plumb::io

// plumb/io/common/split_read.h — reading a large log in parts at once, for readers whose parser
// decides each record from a bounded look-ahead (the DataFlash .bin and ULog readers; the tlog
// reader, whose parser holds no definitions and looks ahead without bound over the mapped file,
// takes SplitReadOptions and the boundary constants below but splits its own way).
//
// The first part is read alone for a lead (the log's definitions); then the rest is cut at
// record boundaries guessed at even steps (two parts by default), and each later part gets a
// parser made from the first and knowing what it knows then (Parser::Ahead), while the first
// reads on to the second part's start: the parts are jobs run at once, as many at a time as the
// runner has threads. Then, in order,
// each part counts only when the log read so far ends exactly on its start; a part stops,
// leaving the rest of its bytes to the first parser, at anything it cannot decide as the first
// would there; what it decoded is joined to what the first did (Parser::Absorb) as one parser
// going through both would have it, and the first parser decodes itself whatever no part
// joined covers. So the log is the same, to the byte, as read in one part.
//
// The parser concept (DataflashParser, the ULog parser):
//   Feed(data, n, offset, at_end) -> offset     the one-pass decoder (see ReadForward)
//   kUntilSlack                                 bytes past `until` Feed may be given: with them
//                                               it decodes no record starting at `until` or
//                                               after, and reaches `until` exactly when a
//                                               record ends there
//   Ahead(Log* out, bytes) const -> Parser      a later part's parser, decoding into `out` the
//                                               records of about `bytes` bytes (what it
//                                               reserves for them)
//   FeedAhead(data, n, offset) -> offset        its Feed: stops (stopped()) where it cannot go
//                                               on; given kUntilSlack bytes past `until`, it
//                                               also decodes no record starting there or after
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

/// How a reader reads a file: in one part, or in parts at once (see the file comment).
struct SplitReadOptions {
  /// Runs independent jobs at once (core/jobs.h). When given, an input of `split_bytes` or
  /// more is read in parts at once. Empty: one part.
  JobRunner run_jobs;
  /// Inputs from this size on are read in parts when run_jobs is given (32 MiB: below, a part
  /// takes a few milliseconds, what starting and joining it costs).
  std::size_t split_bytes = std::size_t{32} << 20;
  /// Bytes read alone before the other parts start: what they know is what is defined in them
  /// (the logs' definitions come first; a definition met later stops a part there). 1 MiB.
  std::size_t lead_bytes = std::size_t{1} << 20;
  /// Parts, the first included (2 or more to split at all). 2: more parts let a fast thread
  /// take over parts a slowed one has not started, but each part's samples are copied once
  /// more in the joins; measured on two cores, eight parts read 15-35 % slower than two on an
  /// idle machine and no faster beside a busy thread (docs/performance.md, "More than two
  /// parts, measured").
  int parts = 2;
  /// Where the second part's start is looked for, as a fraction of the bytes after the lead;
  /// the later parts' at its multiples (those below 1). 0.5 with two parts: the middle, which
  /// gives both the same bytes (1 / parts in general).
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

/// Bytes looked at from a part's nominal start for a record boundary.
inline constexpr std::size_t kBoundaryWindow = std::size_t{64} << 10;
/// Records in a row that make a guessed record boundary.
inline constexpr int kBoundaryRecords = 16;

/// Decodes the records of `source` starting in [from, until) into `parser`; returns the offset
/// it reached: `until` when a record ends there, past it when one starting before it runs on.
/// With `ahead`, through FeedAhead (a parser made by Ahead), stopping where it stops.
template <class Parser>
std::size_t DecodeUntil(const ByteSource& source, Parser& parser, std::size_t from,
                        std::size_t until, bool ahead = false) {
  std::size_t reached = from;
  if (from >= until) return from;
  const auto feed = [&](const std::uint8_t* data, std::size_t n, std::size_t offset) {
    return ahead ? parser.FeedAhead(data, n, offset) : parser.Feed(data, n, offset, false);
  };
  source(from, [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
    const std::size_t limit = until - offset + Parser::kUntilSlack;
    if (n < limit && !at_end) {
      reached = feed(data, n, offset);
      return ahead && parser.stopped() ? kStopReading : reached;
    }
    reached = feed(data, std::min(n, limit), offset);
    return kStopReading;
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

/// The starts of the parts after the first, increasing, each after `lead`: record boundaries
/// `find_boundary(nominal)` (nullopt: none) near lead + k * options.second_part_at * (size -
/// lead), k = 1 .. options.parts - 1, those below `size`.
template <class FindBoundary>
std::vector<std::size_t> PartStarts(std::size_t size, std::size_t lead,
                                    const SplitReadOptions& options,
                                    const FindBoundary& find_boundary) {
  std::vector<std::size_t> starts;
  const double step = std::clamp(options.second_part_at, 0.0, 1.0);
  for (int k = 1; k < options.parts; ++k) {
    const double nominal = static_cast<double>(lead) + k * step * static_cast<double>(size - lead);
    if (nominal >= static_cast<double>(size)) break;
    const std::optional<std::size_t> start = find_boundary(static_cast<std::size_t>(nominal));
    const std::size_t after = starts.empty() ? lead : starts.back();
    if (start && *start > after && *start < size) starts.push_back(*start);
  }
  return starts;
}

/// Decodes `source` (`size` bytes) into `parser` in parts at once through options.run_jobs
/// (SplitReadOptions); `Log` is what Parser::Ahead decodes into. Returns the offset from which
/// the input is still to be decoded (by `parser`'s Feed): where the last part joined stopped,
/// or where `parser` itself got to.
template <class Log, class Parser>
std::size_t DecodeInParts(const ByteSource& source, std::size_t size, Parser& parser,
                          const SplitReadOptions& options) {
  const std::size_t lead = DecodeUntil(source, parser, 0, std::min(options.lead_bytes, size));
  const std::vector<std::size_t> starts = PartStarts(
      size, lead, options, [&](std::size_t from) { return RecordBoundary(source, parser, from); });
  if (starts.empty()) return lead;
  const std::size_t later = starts.size();  // parts after the first
  // aheads[i] reads part i + 1 (part 0: `parser`'s), from starts[i] to end_of(i): the next
  // part's start, or the end of the input.
  const auto end_of = [&](std::size_t i) { return i + 1 < later ? starts[i + 1] : size; };
  std::vector<Log> logs(later);
  std::vector<Parser> aheads;
  aheads.reserve(later);
  for (std::size_t i = 0; i < later; ++i) {
    aheads.push_back(parser.Ahead(&logs[i], end_of(i) - starts[i]));
  }
  std::size_t reached = lead;
  std::vector<std::size_t> stops(later, 0);
  std::vector<char> failed(later + 1, 0);
  std::exception_ptr first_failed;
  RunJobs(options.run_jobs, static_cast<int>(later + 1), [&](int job) {
    const auto k = static_cast<std::size_t>(job);
    try {
      if (k == 0) {
        reached = DecodeUntil(source, parser, lead, starts[0]);
      } else {
        stops[k - 1] = DecodeUntil(source, aheads[k - 1], starts[k - 1], end_of(k - 1), true);
      }
    } catch (...) {  // the jobs throw nothing (core/jobs.h)
      if (k == 0) first_failed = std::current_exception();
      failed[k] = 1;
    }
  });
  if (first_failed) std::rethrow_exception(first_failed);
  // In order: a part counts when the log read so far ends exactly on its start (its guess was
  // a record boundary) and what it decoded joins; else `parser` reads its bytes itself (and
  // meets the part's read error, if there was one). After a part that stopped early, `parser`
  // reads the rest of its bytes.
  for (std::size_t i = 0; i < later; ++i) {
    if (!failed[i + 1] && reached == starts[i] &&
        parser.Absorb(aheads[i], logs[i], options.run_jobs)) {
      reached = stops[i];
    }
    if (i + 1 == later) return reached;  // the rest: the caller's Feed
    reached = DecodeUntil(source, parser, reached, end_of(i));
  }
  return reached;
}

/// The offset from which `parser` is to decode `source` (`size` bytes; 0: unknown) in one
/// pass: 0, or, when options call for parts, where DecodeInParts left it.
template <class Log, class Parser>
std::size_t DecodeStart(const ByteSource& source, std::size_t size, Parser& parser,
                        const SplitReadOptions& options) {
  if (!options.run_jobs || size == 0 || size < options.split_bytes || options.parts < 2) return 0;
  return DecodeInParts<Log>(source, size, parser, options);
}

}  // namespace detail
}  // namespace plumb::io

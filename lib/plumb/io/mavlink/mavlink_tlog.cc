// plumb/io/mavlink/mavlink_tlog.cc — see mavlink_tlog.h for the format and the decoding
// contract: the scan from record to record (accepting, counting, skipping, resynchronising),
// the read in parts at once and the join of their logs, the reader's entry points (ReadTlog,
// ParseTlog) and the decoded log's own functions. The framing is in mavlink_frame.h, the
// message table in mavlink_dialect.cc, the decoding of payloads in mavlink_decode.h.
#include "plumb/io/mavlink/mavlink_tlog.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/mavlink/mavlink_decode.h"
#include "plumb/io/mavlink/mavlink_dialect.h"
#include "plumb/io/mavlink/mavlink_frame.h"

namespace plumb::io {
namespace {

using detail::ExamineTlogRecord;
using detail::kMavlinkIds;
using detail::kTlogTimeBytes;
using detail::MavlinkDecoder;
using detail::MavlinkFrame;
using detail::NextLooksLikeTlogRecord;
using detail::TlogVerdict;

/// The one-pass decoder. What it does at a position depends only on the bytes from there on
/// (ExamineTlogRecord, NextLooksLikeTlogRecord, FindRecord look ahead, never back) and on
/// whether a record ended there, so a parser started at a record another one accepts goes on
/// exactly as that one would: the read in parts (ReadInParts) rests on it.
class Parser {
 public:
  /// Decodes `data` (`size` bytes) into `log`. `file`: the mapped file `data` is, told what has
  /// been read (LogFile::Release) from byte `from` on, or nullptr.
  Parser(const std::uint8_t* data, std::size_t size, MavlinkLog* log, const LogFile* file,
         std::size_t from = 0)
      : data_(data), size_(size), log_(log), file_(file), released_(from), last_end_(from) {
    low_counts_.fill(0);
  }

  /// Decodes the records starting in [from, until); returns the position reached: `until` when
  /// a record ends there (or a skipped byte does), past it when a record starting before it
  /// runs on, size_ when the data end. Called again with what it returned, it goes on.
  std::size_t Run(std::size_t from, std::size_t until) {
    std::size_t pos = from;
    MavlinkFrame f;
    while (pos < until) {
      if (file_ != nullptr && pos >= released_ + LogFile::kReleaseStep) {
        file_->Release(released_, pos);
        released_ = pos;
      }
      const TlogVerdict v = ExamineTlogRecord(data_, size_, pos, &f);
      if (Accepted(v, f, pos)) {
        Accept(f, v == TlogVerdict::kChecked);
        pos += f.record_bytes;
        last_end_ = pos;
        continue;
      }
      if (v == TlogVerdict::kCrcFailed) {
        MavlinkWarnings& w = log_->warnings;
        if (w.crc_failures == 0) w.first_crc_failure_offset = pos;
        ++w.crc_failures;
      }
      if (v == TlogVerdict::kIncomplete) {
        if (size_ - pos < kTlogTimeBytes + 1 && pos != last_end_) {
          SkipTo(pos, size_);
          return size_;
        }
        const std::size_t next = FindRecord(pos + 1);
        if (next == size_) {
          log_->warnings.truncated_records = 1;
          log_->warnings.truncated_bytes = size_ - pos;
          return size_;
        }
        SkipTo(pos, next);
        pos = next;
        continue;
      }
      SkipTo(pos, pos + 1);
      ++pos;
    }
    return pos;
  }

  /// Adds the frames counted per id below 256 to the log's message_counts: once, after the
  /// last Run.
  void Finish() {
    for (std::uint32_t id = 0; id < 256; ++id) {
      if (low_counts_[id] > 0) log_->message_counts[id] += low_counts_[id];
    }
    low_counts_.fill(0);
  }

  /// Takes over where `part` (a parser of the same data whose log was joined to this one's)
  /// got to: the next Run goes on as `part` would have.
  void GoOnFrom(const Parser& part) {
    last_end_ = part.last_end_;
    skip_end_ = part.skip_end_;
  }

  /// First position in [from, to) where `records` records this parser would accept follow one
  /// another; `to` when there is none: where a later part may start.
  std::size_t FindRecordChain(std::size_t from, std::size_t to, int records) const {
    MavlinkFrame f;
    for (std::size_t p = from; p < to; ++p) {
      std::size_t at = p;
      int found = 0;
      while (found < records && at < size_ &&
             Accepted(ExamineTlogRecord(data_, size_, at, &f), f, at)) {
        at += f.record_bytes;
        ++found;
      }
      if (found == records) return p;
    }
    return to;
  }

 private:
  /// Whether the record ExamineTlogRecord found at `pos` (verdict `v`, frame `f`) is accepted:
  /// its CRC checked, or of an id it cannot check and followed by what looks like a record.
  bool Accepted(TlogVerdict v, const MavlinkFrame& f, std::size_t pos) const {
    return v == TlogVerdict::kChecked ||
           (v == TlogVerdict::kUnchecked &&
            NextLooksLikeTlogRecord(data_, size_, pos + f.record_bytes));
  }

  /// First position >= from where a record is accepted, or size_.
  std::size_t FindRecord(std::size_t from) const {
    MavlinkFrame f;
    for (std::size_t p = from; p < size_; ++p) {
      if (Accepted(ExamineTlogRecord(data_, size_, p, &f), f, p)) return p;
    }
    return size_;
  }

  /// Counts bytes [from, to) as skipped.
  void SkipTo(std::size_t from, std::size_t to) {
    CountSkipped(log_->warnings, from, to, skip_end_);
  }

  void Accept(const MavlinkFrame& f, bool checked) {
    if (f.v2) {
      ++log_->frames_v2;
      if (f.is_signed) ++log_->frames_signed;
    } else {
      ++log_->frames_v1;
    }
    log_->record_bytes += f.record_bytes;
    if (checked) {
      ++log_->checked_frames;
    } else {
      ++log_->warnings.unchecked_frames;
    }
    if (f.msgid >= 256) {
      ++log_->message_counts[f.msgid];
      return;
    }
    ++low_counts_[f.msgid];
    const std::size_t full = kMavlinkIds.full_len[f.msgid];
    if (full == 0 || !checked) return;
    decoder_.Decode(f, full, log_);
  }

  const std::uint8_t* data_;
  std::size_t size_;
  MavlinkLog* log_;
  const LogFile* file_;
  std::size_t released_;   // the file is released up to here (LogFile::Release)
  std::size_t last_end_;   // end of the last accepted record
  std::array<std::size_t, 256> low_counts_;
  MavlinkDecoder decoder_;
  std::size_t skip_end_ = 0;
};

}  // namespace

std::string_view MavlinkParamValue::NameView() const {
  return {id.data(), strnlen(id.data(), id.size())};
}

std::vector<std::string> MavlinkWarnings::Describe(
    const std::map<std::uint32_t, std::size_t>& counts) const {
  std::vector<std::string> out;
  if (bytes_skipped) {
    out.push_back("skipped " + std::to_string(bytes_skipped) + " bytes in " +
                  std::to_string(skip_runs) +
                  " run(s) not forming a valid tlog record (first at byte " +
                  std::to_string(first_skip_offset) + ")");
  }
  if (crc_failures) {
    out.push_back(std::to_string(crc_failures) + " frame(s) failed their CRC and were dropped " +
                  "(first at byte " + std::to_string(first_crc_failure_offset) + ")");
  }
  if (truncated_records) {
    out.push_back("dropped the truncated last record (" + std::to_string(truncated_bytes) +
                  " bytes)");
  }
  if (unchecked_frames) {
    std::string ids;
    for (const auto& [id, n] : counts) {
      if (MavlinkCrcExtra(id) >= 0) continue;
      ids += (ids.empty() ? "" : ", ") + MavlinkMessageName(id) + " (id " + std::to_string(id) +
             ") x" + std::to_string(n);
    }
    out.push_back(std::to_string(unchecked_frames) +
                  " frame(s) of messages outside the known MAVLink dialects (" +
                  MavlinkDefinitionsSource() + "), so without a CRC_EXTRA, kept unchecked and "
                  "not decoded: " + ids);
  }
  return out;
}

std::vector<std::pair<std::string, std::size_t>> MavlinkLog::MessageCounts() const {
  std::vector<std::pair<std::string, std::size_t>> out;
  for (const auto& [id, n] : message_counts) out.emplace_back(MavlinkMessageName(id), n);
  return out;
}

namespace {

/// Appends `later`'s warnings, those of the bytes after `w`'s, to `w`.
void AddWarnings(MavlinkWarnings& w, const MavlinkWarnings& later) {
  if (w.bytes_skipped == 0) w.first_skip_offset = later.first_skip_offset;
  if (w.crc_failures == 0) w.first_crc_failure_offset = later.first_crc_failure_offset;
  w.bytes_skipped += later.bytes_skipped;
  w.skip_runs += later.skip_runs;
  w.crc_failures += later.crc_failures;
  w.truncated_records += later.truncated_records;
  w.truncated_bytes += later.truncated_bytes;
  w.unchecked_frames += later.unchecked_frames;
}

/// Appends `later`, decoded from the bytes right after `log`'s (a later part starting on a
/// record the log so far reached), to `log`: as one parser going through both would have it.
/// The message vectors are appended as jobs through `run_jobs`.
void Join(MavlinkLog& log, const MavlinkLog& later, const JobRunner& run_jobs) {
  log.frames_v1 += later.frames_v1;
  log.frames_v2 += later.frames_v2;
  log.frames_signed += later.frames_signed;
  log.checked_frames += later.checked_frames;
  log.record_bytes += later.record_bytes;
  for (const auto& [id, n] : later.message_counts) log.message_counts[id] += n;
  AddWarnings(log.warnings, later.warnings);
  const auto append = [](auto& out, const auto& in) {
    out.insert(out.end(), in.begin(), in.end());
  };
  RunJobs(run_jobs, 8, [&](int job) {  // each job appends its own vector
    switch (job) {
      case 0: append(log.heartbeat, later.heartbeat); break;
      case 1: append(log.raw_imu, later.raw_imu); break;
      case 2: append(log.scaled_imu, later.scaled_imu); break;
      case 3: append(log.scaled_imu2, later.scaled_imu2); break;
      case 4: append(log.scaled_imu3, later.scaled_imu3); break;
      case 5: append(log.highres_imu, later.highres_imu); break;
      case 6: append(log.gps_raw_int, later.gps_raw_int); break;
      default: append(log.param_value, later.param_value); break;
    }
  });
}

/// Decodes `data` (`size` bytes) into `first`, which writes `log`, in parts at once through
/// options.run_jobs: each part after the first starts at a chain of records
/// (detail::kBoundaryRecords) looked for near its nominal start (detail::PartStarts; no lead
/// is read alone: a tlog has no definitions) and reads to the next part's start, the last to
/// the end; the first reads to the second's start. Then, in order, a part's log is joined when
/// the log so far ends exactly on its start; else `first` reads the part's bytes itself. Either
/// way the log is the one a single pass makes.
void ReadInParts(const std::uint8_t* data, std::size_t size, Parser& first, MavlinkLog& log,
                 const LogFile* file, const SplitReadOptions& options) {
  const std::size_t lead = std::min(options.lead_bytes, size);
  const std::vector<std::size_t> starts =
      detail::PartStarts(size, lead, options, [&](std::size_t from) -> std::optional<std::size_t> {
        const std::size_t end = std::min(size, from + detail::kBoundaryWindow);
        const std::size_t at = first.FindRecordChain(from, end, detail::kBoundaryRecords);
        if (at == end) return std::nullopt;
        return at;
      });
  if (starts.empty()) {
    first.Run(0, size);
    return;
  }
  const std::size_t later = starts.size();  // parts after the first
  std::vector<MavlinkLog> logs(later);
  std::vector<Parser> parts;
  parts.reserve(later);
  for (std::size_t i = 0; i < later; ++i) parts.emplace_back(data, size, &logs[i], file, starts[i]);
  // parts[i] reads part i + 1 (part 0: `first`'s), from starts[i] to end_of(i).
  const auto end_of = [&](std::size_t i) { return i + 1 < later ? starts[i + 1] : size; };
  std::size_t reached = 0;
  std::vector<std::size_t> stops(later, 0);
  RunJobs(options.run_jobs, static_cast<int>(later + 1), [&](int job) {
    if (job == 0) {
      reached = first.Run(0, starts[0]);
      return;
    }
    const auto i = static_cast<std::size_t>(job - 1);
    stops[i] = parts[i].Run(starts[i], end_of(i));
    parts[i].Finish();
  });
  for (std::size_t i = 0; i < later; ++i) {
    if (reached == starts[i]) {
      Join(log, logs[i], options.run_jobs);
      first.GoOnFrom(parts[i]);
      reached = stops[i];
    } else {
      reached = first.Run(reached, end_of(i));
    }
  }
}

/// ParseTlog, telling `file` (nullptr: none) what the parser has read.
MavlinkLog ParseTlogFrom(const std::uint8_t* data, std::size_t size, const std::string& source,
                         const LogFile* file, const TlogReadOptions& options) {
  MavlinkLog log;
  log.source = source;
  log.size_bytes = size;
  Parser parser(data, size, &log, file);
  if (options.run_jobs && size > 0 && size >= options.split_bytes) {
    ReadInParts(data, size, parser, log, file, options);
  } else {
    parser.Run(0, size);
  }
  parser.Finish();
  if (log.frames_v1 + log.frames_v2 == 0) {
    throw InputError(source, "byte 0",
                     "no MAVLink frame ([8-byte big-endian unix time in µs][0xFE or 0xFD "
                     "frame] with a valid CRC) in " + std::to_string(size) +
                         " bytes: not a MAVLink .tlog");
  }
  return log;
}

}  // namespace

MavlinkLog ParseTlog(const std::uint8_t* data, std::size_t size, const std::string& source,
                     const TlogReadOptions& options) {
  return ParseTlogFrom(data, size, source, nullptr, options);
}

MavlinkLog ReadTlog(const std::string& path, const TlogReadOptions& options) {
  const LogFile file(path, "MAVLink tlog");
  try {
    MavlinkLog log = ParseTlogFrom(file.data(), file.size(), path, &file, options);
    file.ThrowIfCut();
    return log;
  } catch (const Error&) {
    file.ThrowIfCut();  // the zeros of a cut may have caused it
    throw;
  }
}

}  // namespace plumb::io

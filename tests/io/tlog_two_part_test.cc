// The .tlog reader in two parts (TlogReadOptions, split_read.h): the log is the one the
// reader gives in one part, to the byte (frame counts, every decoded message, message counts per
// id, skipped bytes and their runs, CRC failures, unchecked frames, the truncated last record),
// wherever the second part's start is looked for: among v1 and v2 frames, signed and with
// truncated payloads, frames of ids outside the dialects (accepted, and not: followed by
// garbage), CRC failures, implausible times, a v2 frame with unknown incompatible flags, runs of
// garbage, a short tail or a cut last record; a start guessed inside a frame whose payload holds
// records (the first part jumps over it: not joined, the first part goes on); the shared tlog
// through ReadTlog, jobs run in either order or at once.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "io_test_util.h"
#include "plumb/io/mavlink/mavlink_tlog.h"
#include "support/mavlink_log_difference.h"
#include "support/reverse_jobs.h"
#include "support/split_read_testing.h"
#include "tlog_builder.h"

namespace plumb::io {
namespace {

using testing::Append;
using testing::Bytes;
using testing::FrameSpec;
using testing::GpsRawInt;
using testing::Heartbeat;
using testing::HighresImu;
using testing::kT0_us;
using testing::kUnknownId;
using testing::ParamValue;
using testing::RawImu;
using testing::Record;
using testing::ScaledImu;

/// Every part of two decoded logs the same (MavlinkLogDifference).
void ExpectSameLog(const MavlinkLog& one, const MavlinkLog& two) {
  EXPECT_EQ(plumb::testing::MavlinkLogDifference(one, two), "");
}

using plumb::testing::TwoParts;

/// Jobs in order, counting in `joins` the joins of a later part's messages (the eight vectors
/// appended at once are the only eight jobs run in a read).
JobRunner CountingJoins(std::size_t* joins) { return plumb::testing::CountingCalls(8, joins); }

/// `second_part_at` that puts the nominal start of the second part at byte `at` of `size`
/// (lead 0).
double AtByte(std::size_t at, std::size_t size) {
  return (static_cast<double>(at) + 0.5) / static_cast<double>(size);
}

/// The record of message `n` of a clean stretch: each kind the reader decodes, v1 and v2,
/// signed, payloads truncated, from the vehicle and the ground station.
Bytes CleanRecord(int n) {
  const std::uint64_t t = kT0_us + 1000u * static_cast<std::uint64_t>(n);
  const auto v = [n](int k) { return static_cast<std::int16_t>(n * 7 + k); };
  switch (n % 8) {
    case 0: return Record({kMavHeartbeat, Heartbeat(3), 1, 1, false, false, true, t});
    case 1: return Record({kMavHeartbeat, Heartbeat(8), 255, 190, true, false, true, t});
    case 2:
      return Record({kMavRawImu, RawImu(t, {v(0), v(1), v(2), v(3), v(4), v(5), 0, 0, 0}), 1, 1,
                     true, false, true, t});
    case 3:
      return Record({kMavScaledImu2, ScaledImu(n, {v(0), v(1), -1000, 1, 2, 3, 4, 5, 6}, 3500),
                     1, 1, false, false, true, t});
    case 4:
      return Record({kMavScaledImu3, ScaledImu(n, {v(2), v(3), -990, 3, 2, 1, 0, 0, 0}), 1, 1,
                     true, true, true, t});
    case 5:
      return Record({kMavHighresImu,
                     HighresImu(t, {0.1f * n, -0.2f, -9.7f, 0.01f, 0.02f, -0.03f, 0.2f, 0.0f,
                                    0.4f, 1013.0f, 0.0f, 12.0f, 31.5f}),
                     1, 1, true, false, true, t});
    case 6:
      return Record({kMavGpsRawInt, GpsRawInt(515000000 + n, -1000000, 90000, 3), 1, 1, false,
                     false, true, t});
    default:
      return Record({kMavParamValue, ParamValue("INS_ACC" + std::to_string(n % 3), 0.5f * n, 9),
                     1, 1, true, false, true, t});
  }
}

/// A tlog with long clean stretches (chains a second part can start at) between every kind of
/// damage the reader meets; it ends with `ending` (0: a cut last record, 1: 12 bytes of
/// garbage, 2: nothing more).
Bytes SeamLog(int ending) {
  std::mt19937 rng(20261128);  // fixed: the same bytes every run
  Bytes t;
  int n = 0;
  const auto stretch = [&](int records) {
    for (int k = 0; k < records; ++k) Append(&t, CleanRecord(n++));
  };
  for (int damage = 0; damage < 12; ++damage) {
    stretch(20 + damage * 3);
    const std::uint64_t time = kT0_us + 1000u * static_cast<std::uint64_t>(n);
    switch (damage % 6) {
      case 0: {  // an id outside the dialects, accepted unchecked (a record follows)
        Append(&t, Record({kUnknownId, {1, 2, 3, 4}, 1, 1, false, false, true, time}));
        Append(&t, Record({0x012345, {9, 8, 7}, 1, 1, true, false, true, time}));
        break;
      }
      case 1: {  // a CRC failure: one payload byte flipped
        Bytes r = CleanRecord(n++);
        r[20] ^= 0x10;
        Append(&t, r);
        break;
      }
      case 2: {  // garbage, some of it looking like a record's start
        for (int k = 0; k < 37; ++k) t.push_back(static_cast<std::uint8_t>(rng()));
        Bytes head = CleanRecord(n++);
        head.resize(12);
        Append(&t, head);
        break;
      }
      case 3: {  // an unknown id followed by garbage: not a frame
        Append(&t, Record({kUnknownId, {5, 5}, 1, 1, false, false, true, time}));
        t.insert(t.end(), {0x00, 0x01, 0x02, 0xFE});
        break;
      }
      case 4: {  // an implausible time, then a v2 frame with unknown incompatible flags
        Append(&t, Record({kMavHeartbeat, Heartbeat(3), 1, 1, false, false, true, 5}));
        Bytes r = CleanRecord(8 * n + 1);  // a v2 HEARTBEAT
        r[10] = 0x04;
        Append(&t, r);
        break;
      }
      default: {  // a v1 frame whose length runs into the next records (CRC fails)
        Bytes r = CleanRecord(8 * n + 3);
        r[9] = 200;
        Append(&t, r);
        break;
      }
    }
  }
  stretch(30);
  if (ending == 0) {
    Bytes cut = CleanRecord(5);
    cut.resize(cut.size() - 7);
    Append(&t, cut);
  } else if (ending == 1) {
    t.insert(t.end(), {0xFE, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88, 0x99, 0x01, 0x02});
  }
  return t;
}

TEST(TlogTwoParts, SameLogWhereverTheSecondPartStarts) {
  for (const int ending : {0, 1, 2}) {
    SCOPED_TRACE(::testing::Message() << "ending " << ending);
    const Bytes log = SeamLog(ending);
    const MavlinkLog one = ParseTlog(log.data(), log.size(), "seam.tlog");
    ASSERT_GT(one.warnings.bytes_skipped, 0u);
    ASSERT_GT(one.warnings.skip_runs, 4u);
    ASSERT_GT(one.warnings.crc_failures, 2u);
    ASSERT_EQ(one.warnings.unchecked_frames, 4u);
    ASSERT_EQ(one.warnings.truncated_records, ending == 0 ? 1u : 0u);
    ASSERT_GT(one.frames_signed, 10u);
    for (const auto* v : {&one.raw_imu, &one.scaled_imu2, &one.scaled_imu3}) {
      ASSERT_GT(v->size(), 20u);
    }
    ASSERT_GT(one.highres_imu.size(), 20u);
    ASSERT_GT(one.param_value.size(), 20u);
    std::size_t joins = 0;
    for (int k = 0; k <= 1000; ++k) {
      const double at = k / 1000.0;
      SCOPED_TRACE(::testing::Message() << "at " << at);
      ExpectSameLog(one, ParseTlog(log.data(), log.size(), "seam.tlog",
                                   TwoParts(0, at, CountingJoins(&joins))));
      if (::testing::Test::HasFailure()) return;
    }
    // Every start but those in the last records (no chain of 16 after them) joins.
    EXPECT_GT(joins, 900u);
  }
}

/// The log in 3 to 16 parts at once (SplitReadOptions::parts; the starts at the multiples of
/// `second_part_at`), jobs in order and in reverse on two threads: the log read in one part,
/// with parts joined one after another and parts left to the first parser between them.
TEST(TlogTwoParts, SameLogInManyParts) {
  for (const int ending : {0, 1, 2}) {
    const Bytes log = SeamLog(ending);
    const MavlinkLog one = ParseTlog(log.data(), log.size(), "seam.tlog");
    std::size_t joins = 0;
    for (const int parts : {3, 5, 8, 16}) {
      for (int k = 1; k <= 40; ++k) {
        const double at = k / (40.0 * (parts - 1));
        SCOPED_TRACE(::testing::Message() << "ending " << ending << ", " << parts << " parts, at "
                                          << at);
        TlogReadOptions options = TwoParts(0, at, CountingJoins(&joins), parts);
        ExpectSameLog(one, ParseTlog(log.data(), log.size(), "seam.tlog", options));
        options.run_jobs = plumb::testing::ReverseOnTwoThreads;
        ExpectSameLog(one, ParseTlog(log.data(), log.size(), "seam.tlog", options));
        if (::testing::Test::HasFailure()) return;
      }
    }
    EXPECT_GT(joins, 1000u);  // of 160 reads of 2 to 15 parts after the first
  }
}

TEST(TlogTwoParts, StartGuessedInsideAFrameIsNotJoined) {
  // A v2 HEARTBEAT of 255 payload bytes (beyond the message's 9 ignored, but in its CRC) that
  // holds 14 v1 HEARTBEATs of payload length 0 and a frame of an unknown id covering the rest
  // of the payload and the outer CRC: from inside it, 16 records follow one another (14, the
  // unknown one, then the next real record), a chain the second part would start at, but the
  // first part accepts the outer frame and jumps over it.
  Bytes inner;
  for (int k = 0; k < 14; ++k) {
    Append(&inner, Record({kMavHeartbeat, {}, 1, 1, false, false, true, kT0_us + k}));
  }
  const std::size_t outer_header = 8 + 10;
  const Bytes hb = Heartbeat(3);
  // Unknown-id v1 record: 8 + 6 + len + 2 bytes ending where the outer frame ends.
  const std::size_t rest = 255 - hb.size() - inner.size() + 2;  // inner payload + outer CRC
  const std::size_t unknown_len = rest - (8 + 6 + 2);
  Bytes unknown = Record({kUnknownId, Bytes(unknown_len, 0x55), 1, 1, false, false, true, kT0_us});
  Bytes payload = hb;
  Append(&payload, inner);
  Append(&payload, unknown);
  payload.resize(255);  // the unknown frame's last 2 bytes are the outer CRC's
  Bytes log;
  for (int k = 0; k < 40; ++k) Append(&log, CleanRecord(k));
  const std::size_t outer_at = log.size();
  Append(&log, Record({kMavHeartbeat, payload, 1, 1, true, false, false, kT0_us + 99}));
  for (int k = 40; k < 80; ++k) Append(&log, CleanRecord(k));

  const MavlinkLog one = ParseTlog(log.data(), log.size(), "inside.tlog");
  ASSERT_EQ(one.warnings.bytes_skipped, 0u);
  ASSERT_EQ(one.heartbeat.size(), 20u + 1u);  // the outer frame accepted, whole
  const std::size_t inner_at = outer_at + outer_header + hb.size();
  std::size_t joins = 0;
  ExpectSameLog(one, ParseTlog(log.data(), log.size(), "inside.tlog",
                               TwoParts(0, AtByte(inner_at, log.size()), CountingJoins(&joins))));
  EXPECT_EQ(joins, 0u);  // the guess was inside the outer frame: the first part went on
  // Looked for from the outer frame itself, the start is a real record: joined.
  ExpectSameLog(one, ParseTlog(log.data(), log.size(), "inside.tlog",
                               TwoParts(0, AtByte(outer_at, log.size()), CountingJoins(&joins))));
  EXPECT_EQ(joins, 1u);
}

/// A part that ends past the next part's start (its last frame holds what looked like a chain
/// of records) hands on to the first parser, which reads the rest as that part would have: here
/// the log's short tail right after that frame is a cut last record, not skipped bytes.
TEST(TlogTwoParts, PartEndingPastTheNextStartHandsOnToTheFirst) {
  // A v2 HEARTBEAT of 255 payload bytes (its first 9 read as the message) holding 15 v1
  // HEARTBEATs of payload length 0 and a 17-byte frame of an unknown id that ends with the
  // outer frame (the outer CRC its last 2 bytes); then a 5-byte tail.
  Bytes payload;
  for (int k = 0; k < 15; ++k) {
    Append(&payload, Record({kMavHeartbeat, {}, 1, 1, false, false, true, kT0_us + k}));
  }
  Append(&payload, Record({kUnknownId, {0x55}, 1, 1, false, false, true, kT0_us}));
  ASSERT_EQ(payload.size(), 257u);
  payload.resize(255);
  Bytes log;
  for (int k = 0; k < 40; ++k) Append(&log, CleanRecord(k));
  const std::size_t inner_at = log.size() + 8 + 10;
  Append(&log, Record({kMavHeartbeat, payload, 1, 1, true, false, false, kT0_us + 99}));
  log.insert(log.end(), {0x00, 0x01, 0x02, 0x03, 0x04});

  const MavlinkLog one = ParseTlog(log.data(), log.size(), "past.tlog");
  ASSERT_EQ(one.warnings.truncated_records, 1u);
  ASSERT_EQ(one.warnings.bytes_skipped, 0u);
  // Three parts: the second from a record in the middle of the clean ones, the third guessed
  // at the outer frame's inner records; the second joins, reads the outer frame whole and ends
  // past the third's start, which does not join.
  std::size_t joins = 0;
  const TlogReadOptions options =
      TwoParts(0, AtByte(inner_at, 2 * log.size()), CountingJoins(&joins), 3);
  ExpectSameLog(one, ParseTlog(log.data(), log.size(), "past.tlog", options));
  EXPECT_EQ(joins, 1u);
}

/// ReadTlog in two parts, jobs run one after another and at once in the other order, the
/// second part's start looked for at several places: the log read in one part.
TEST(TlogTwoParts, SharedTlogReadInTwoPartsAsInOne) {
  const std::string dir = testing::SharedLogPath("mavlink", "");
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "shared data absent: " << dir;
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".tlog") continue;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    ++files;
    const MavlinkLog one = ReadTlog(path);
    for (const double at : {0.0, 0.13, 0.5, 0.77, 0.999}) {
      SCOPED_TRACE(at);
      std::size_t joins = 0;
      const JobRunner run_jobs =
          at == 0.5 ? JobRunner(plumb::testing::ReverseOnTwoThreads) : CountingJoins(&joins);
      ExpectSameLog(one, ReadTlog(path, TwoParts(64 << 10, at, run_jobs)));
      if (::testing::Test::HasFailure()) return;
      if (at != 0.5 && at < 0.99) EXPECT_EQ(joins, 1u);
    }
  }
  EXPECT_GE(files, 1u);
}

}  // namespace
}  // namespace plumb::io

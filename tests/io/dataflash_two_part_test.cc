// The .bin reader in two parts (DataflashReadOptions, DataflashParser::Ahead / Absorb): the log
// is the one the reader gives in one part, to the byte (types, counts, kept bodies, decoded IMU
// samples and the reader's state, parameters, warnings), wherever the second part starts: on a
// record boundary (joined), inside a record (not joined: the first part goes on), at a spike or
// a time going back in either IMU instance, before an FMT of a new type, a redefinition, an
// invalid FMT or skipped bytes; on every shared .bin log through ReadDataflash, jobs run in
// either order or at once.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "dataflash_builder.h"
#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/ardupilot/dataflash_parser.h"
#include "support/dataflash_log_difference.h"
#include "support/reverse_jobs.h"
#include "support/split_read_testing.h"

namespace plumb::io {
namespace {

using detail::DataflashParser;
using testing::Append;
using testing::Bytes;
using testing::Put;

/// Every part of two decoded logs the same (DataflashLogDifference).
void ExpectSameLog(const DataflashLog& one, const DataflashLog& two) {
  EXPECT_EQ(plumb::testing::DataflashLogDifference(one, two), "");
}

/// An IMU record of the layout ArduPilot writes (54 bytes: TimeUS Q, I B, six axes, EG EA I,
/// T f, GH AH B, GHz AHz H) of message type `type`.
Bytes ImuRecord(std::uint8_t type, std::uint64_t time_us, std::uint8_t instance, int n) {
  Bytes r = {0xA3, 0x95, type};
  Put(&r, time_us);
  Put(&r, instance);
  for (int k = 0; k < 6; ++k) Put(&r, 0.25f * static_cast<float>(n + k) - 3.0f);
  Put(&r, std::uint32_t{0});
  Put(&r, std::uint32_t{0});
  Put(&r, 20.0f + 0.125f * static_cast<float>(n % 64));
  for (int k = 0; k < 6; ++k) r.push_back(0);
  return r;
}

/// A PARM record (type 64: TimeUS Q, Name N, Value f).
Bytes ParmRecord(std::uint64_t time_us, const std::string& name, float value) {
  Bytes r = {0xA3, 0x95, 64};
  Put(&r, time_us);
  testing::PutFixed(&r, name, 16);
  Put(&r, value);
  return r;
}

/// A log with what the join must get right near any of its bytes: IMU (two instances, I
/// column) and IMU2 records whose times go back, spike and repeat now and then; PARM bodies
/// kept; a message counted only; FMTs in the middle (a new type, an identical, a conflicting
/// and an invalid redefinition); runs of bytes outside any record; a cut last record.
Bytes SeamLog() {
  const std::string imu_columns = "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz";
  Bytes log = testing::FmtRecord(128, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns");
  Append(&log, testing::FmtRecord(21, 54, "IMU", "QBffffffIIfBBHH", imu_columns));
  Append(&log, testing::FmtRecord(22, 54, "IMU2", "QBffffffIIfBBHH", imu_columns));
  Append(&log, testing::FmtRecord(64, 31, "PARM", "QNf", "TimeUS,Name,Value"));
  Append(&log, testing::FmtRecord(30, 11, "CNT", "Q", "TimeUS"));
  std::uint64_t t = 1000;
  for (int n = 0; n < 900; ++n) {
    // Mostly rising by 1 ms; now and then a spike far ahead, a step back, a repeat.
    std::uint64_t time = t;
    if (n % 37 == 5) time = t + 90000000;          // a spike
    if (n % 53 == 7) time = t - 3500;               // back in time
    if (n % 41 == 9) time = t - 1000;               // the last one's time again
    Append(&log, ImuRecord(21, time, static_cast<std::uint8_t>(n % 2), n));
    if (n % 3 == 0) Append(&log, ImuRecord(22, time + 7, 0, n));
    if (n % 5 == 0) {
      Bytes c = {0xA3, 0x95, 30};
      Put(&c, time);
      Append(&log, c);
    }
    if (n % 50 == 0) Append(&log, ParmRecord(time, "P" + std::to_string(n % 150), n * 0.5f));
    if (n == 300) Append(&log, testing::FmtRecord(31, 11, "NEW", "Q", "TimeUS"));
    if (n > 300 && n % 4 == 0) {
      Bytes c = {0xA3, 0x95, 31};
      Put(&c, time);
      Append(&log, c);
    }
    if (n == 400) Append(&log, testing::FmtRecord(64, 31, "PARM", "QNf", "TimeUS,Name,Value"));
    if (n == 450) Append(&log, testing::FmtRecord(64, 30, "PARX", "QNf", "TimeUS,Name,Value"));
    if (n == 500) Append(&log, testing::FmtRecord(40, 2, "BAD", "", ""));
    if (n == 600) Append(&log, Bytes{0xA3, 0x95, 0xEE, 0x01, 0xA3});  // outside any record
    if (n % 97 == 3) Append(&log, Bytes{0x00, 0x11});
    t += 1000;
  }
  const Bytes cut = ImuRecord(21, t, 0, 1);
  log.insert(log.end(), cut.begin(), cut.begin() + 20);
  return log;
}

/// The record boundaries of `log` as the one-part reader finds them (a plain walk with the
/// FMT lengths), and the bytes it skips.
std::vector<std::size_t> Starts(const Bytes& log) {
  std::vector<std::size_t> length(256, 0);
  length[128] = 89;
  std::vector<std::size_t> starts;
  std::size_t i = 0;
  while (i + 3 <= log.size()) {
    const std::size_t len = length[log[i + 2]];
    if (log[i] == 0xA3 && log[i + 1] == 0x95 && len > 0 && len <= log.size() - i) {
      if (log[i + 2] == 128 && length[log[i + 3]] == 0 && log[i + 4] >= 3) {
        length[log[i + 3]] = log[i + 4];
      }
      starts.push_back(i);
      i += len;
    } else {
      ++i;
    }
  }
  return starts;
}

/// The log of `bytes` decoded in two parts as ReadDataflash does it, in memory: the first part
/// to `lead`, then a parser started at byte `start`, the first going on to it, the two joined
/// when the first ends exactly there. `joined`: whether they were; `second_part_bytes`: the
/// bytes the second part decoded then (0 otherwise).
DataflashLog ParseInTwo(const Bytes& bytes, std::size_t lead, std::size_t start,
                        const RecordFilter& filter, bool* joined,
                        std::size_t* second_part_bytes = nullptr) {
  const std::uint8_t* data = bytes.data();
  const std::size_t n = bytes.size();
  constexpr std::size_t kRoom = DataflashParser::kMaxRecord - 1;
  DataflashLog log;
  log.source = "seam.bin";
  log.size_bytes = n;
  DataflashParser parser(&log, filter, n);
  const std::size_t reached = parser.Feed(data, lead + kRoom, 0, false);
  DataflashLog ahead_log;
  DataflashParser ahead = parser.Ahead(&ahead_log, n - start);
  const std::size_t stop = ahead.FeedAhead(data + start, n - start, start);
  const std::size_t landed = parser.Feed(data + reached, start + kRoom - reached, reached, false);
  *joined = landed == start && parser.Absorb(ahead, ahead_log, {});
  const std::size_t from = *joined ? stop : landed;
  if (second_part_bytes != nullptr) *second_part_bytes = *joined ? stop - start : 0;
  parser.Feed(data + from, n - from, from, true);
  parser.Finish();
  detail::FinishDataflashLog(&log);
  return log;
}

TEST(DataflashTwoParts, SameLogFromEverySecondPartStart) {
  const Bytes log = SeamLog();
  for (const RecordFilter& filter : {RecordFilter{}, ArdupilotSessionRecords()}) {
    const DataflashLog one = ParseDataflash(log.data(), log.size(), "seam.bin", filter);
    ASSERT_GT(one.warnings.fmt_conflicts, 0u);
    ASSERT_GT(one.warnings.fmt_invalid, 0u);
    ASSERT_GT(one.warnings.skip_runs, 3u);
    ASSERT_EQ(one.warnings.truncated_records, 1u);
    const std::size_t lead = 600;
    std::size_t joined_count = 0, tried = 0, long_joins = 0;
    std::vector<std::size_t> starts = Starts(log);
    // Inside records too: a guess that is not a boundary, which the first part passes over.
    for (std::size_t k = 0; k + 1 < starts.size(); k += 7) starts.push_back(starts[k] + 1);
    for (const std::size_t start : starts) {
      if (start <= lead || start + DataflashParser::kMaxRecord > log.size()) continue;
      SCOPED_TRACE(start);
      bool joined = false;
      std::size_t second = 0;
      ExpectSameLog(one, ParseInTwo(log, lead, start, filter, &joined, &second));
      joined_count += joined ? 1 : 0;
      long_joins += second > 4000 ? 1 : 0;
      ++tried;
      if (::testing::Test::HasFailure()) return;
    }
    // Most boundaries join; those after the new type's FMT stop the second part there.
    EXPECT_GT(tried, 1000u);
    EXPECT_GT(joined_count, tried / 2);
    EXPECT_LT(joined_count, tried);
    EXPECT_GT(long_joins, 100u);
  }
}

/// The log in 3 to 16 parts at once through ParseDataflash (SplitReadOptions::parts; the
/// starts at the multiples of `second_part_at`), jobs in order and in reverse on two threads:
/// the log read in one part, with parts joined one after another and parts left to the first
/// parser between them (a start inside a record, after a new type's FMT).
TEST(DataflashTwoParts, SameLogInManyParts) {
  const Bytes log = SeamLog();
  for (const RecordFilter& filter : {RecordFilter{}, ArdupilotSessionRecords()}) {
    const DataflashLog one = ParseDataflash(log.data(), log.size(), "seam.bin", filter);
    std::size_t joins = 0;  // the IMU samples' joins (AppendSamples: four column jobs)
    const JobRunner counting = plumb::testing::CountingCalls(4, &joins);
    for (const int parts : {3, 5, 8, 16}) {
      for (int k = 1; k <= 40; ++k) {
        DataflashReadOptions options =
            plumb::testing::TwoParts(600, k / (40.0 * (parts - 1)), counting, parts);
        SCOPED_TRACE(::testing::Message() << parts << " parts, at " << options.second_part_at);
        ExpectSameLog(one, ParseDataflash(log.data(), log.size(), "seam.bin", filter, options));
        options.run_jobs = plumb::testing::ReverseOnTwoThreads;
        ExpectSameLog(one, ParseDataflash(log.data(), log.size(), "seam.bin", filter, options));
        if (::testing::Test::HasFailure()) return;
      }
    }
    if (filter.decode) EXPECT_GT(joins, 1800u);
  }
}

/// The second part's first records of an instance all before the first part's last kept
/// time (the clock set back by more than the head holds): no join, the same log.
TEST(DataflashTwoParts, ClockSetBackPastTheHeadIsNotJoined) {
  const std::string imu_columns = "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz";
  Bytes log = testing::FmtRecord(128, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns");
  Append(&log, testing::FmtRecord(22, 54, "IMU2", "QBffffffIIfBBHH", imu_columns));
  std::size_t seam = 0;
  for (int n = 0; n < 200; ++n) {
    if (n == 100) seam = log.size();
    const std::uint64_t time = n < 100 ? 1000000 + 1000 * n : 1000 * n;  // set back at 100
    Append(&log, ImuRecord(22, time, 0, n));
  }
  const DataflashLog one =
      ParseDataflash(log.data(), log.size(), "seam.bin", ArdupilotSessionRecords());
  bool joined = true;
  ExpectSameLog(one, ParseInTwo(log, 200, seam, ArdupilotSessionRecords(), &joined));
  EXPECT_FALSE(joined);
  // Set back by less than the head holds: joined.
  ExpectSameLog(one, ParseInTwo(log, 200, seam + 90 * 54, ArdupilotSessionRecords(), &joined));
  EXPECT_TRUE(joined);
}

std::string SharedFile(const std::string& relative) {
  return std::string(PLUMB_SHARED_DATA_DIR) + "/" + relative;
}

/// A real log split near its middle, where ReadDataflash looks for the second part's start:
/// joined, the second part decoding the rest of the file.
TEST(DataflashTwoParts, RealLogJoinedAtItsMiddle) {
  const std::string path = SharedFile("ardupilot/copter36_chibios.bin");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  std::ifstream in(path, std::ios::binary);
  const Bytes log((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const RecordFilter filter = ArdupilotSessionRecords();
  const DataflashLog one = ParseDataflash(log.data(), log.size(), "seam.bin", filter);
  ASSERT_TRUE(one.Find("IMU")->imu_decoded);
  ASSERT_TRUE(one.Find("IMU2")->imu_decoded);
  // The parser's types after the lead, to find a boundary near the middle as the reader does.
  DataflashLog lead_log;
  DataflashParser lead_parser(&lead_log, filter, log.size());
  const std::size_t lead = 64 << 10;
  lead_parser.Feed(log.data(), lead + DataflashParser::kMaxRecord - 1, 0, false);
  const std::size_t middle = log.size() / 2;
  const std::size_t start =
      middle + lead_parser.FindRecordChain(log.data() + middle, 64 << 10, 16);
  ASSERT_LT(start, middle + (64 << 10));
  bool joined = false;
  std::size_t second = 0;
  ExpectSameLog(one, ParseInTwo(log, lead, start, filter, &joined, &second));
  EXPECT_TRUE(joined);
  EXPECT_GT(second, log.size() / 4);
}

/// ReadDataflash in two parts, jobs run one after another and at once in the other order, the
/// second part's start looked for at several places: the log read in one part.
TEST(DataflashTwoParts, EverySharedBinReadInTwoPartsAsInOne) {
  const std::string dir = SharedFile("ardupilot");
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "shared data absent: " << dir;
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) {
      return static_cast<char>(std::tolower(c));
    });
    if (ext != ".bin") continue;
    const std::string path = entry.path().string();
    SCOPED_TRACE(path);
    ++files;
    for (const RecordFilter& filter : {RecordFilter{}, ArdupilotSessionRecords()}) {
      const DataflashLog one = ReadDataflash(path, filter);
      for (const double at : {0.0, 0.13, 0.5, 0.77, 0.999}) {
        SCOPED_TRACE(at);
        const JobRunner run_jobs =
            at == 0.5 ? JobRunner(plumb::testing::ReverseOnTwoThreads) : plumb::testing::InOrder;
        const DataflashReadOptions options = plumb::testing::TwoParts(32 << 10, at, run_jobs);
        ExpectSameLog(one, ReadDataflash(path, filter, options));
        if (::testing::Test::HasFailure()) return;
      }
    }
  }
  EXPECT_GE(files, 5u);
}

}  // namespace
}  // namespace plumb::io

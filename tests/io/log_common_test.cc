// Tests of the pieces every binary-log reader shares (plumb/io/common/log_common.h): the
// forward chunked reading (ReadForward) and the blocked record storage (RecordStore).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/temp_dir.h"
#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"

namespace plumb::io {
namespace {

std::vector<std::uint8_t> Pattern(std::size_t n) {
  std::vector<std::uint8_t> out(n);
  for (std::size_t k = 0; k < n; ++k) out[k] = static_cast<std::uint8_t>((k * 131 + k / 251) & 0xFF);
  return out;
}

std::string WriteFile(const ::plumb::testing::TempDir& dir, const std::vector<std::uint8_t>& b) {
  const std::string path = dir.File("log.bin");
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  return path;
}

TEST(LogCommon, RecordStoreKeepsRowsAcrossBlocksAndCopies) {
  for (const std::size_t body : {std::size_t{0}, std::size_t{1}, std::size_t{37},
                                  std::size_t{4096}, std::size_t{65533}}) {
    RecordStore store(body);
    const std::vector<std::uint8_t> bytes = Pattern(body * 3001 + 1);
    const std::size_t rows = body == 0 ? 5000 : (body > 1000 ? 40 : 3001);
    for (std::size_t r = 0; r < rows; ++r) store.Append(bytes.data() + r * (body > 1000 ? 0 : body));
    ASSERT_EQ(store.rows(), rows);
    EXPECT_EQ(store.size(), rows * body);
    for (std::size_t r = 0; r < rows; ++r) {
      ASSERT_EQ(std::memcmp(store.Row(r), bytes.data() + r * (body > 1000 ? 0 : body), body), 0)
          << body << " " << r;
    }
    const RecordStore copy = store;  // NOLINT: the copy is what is tested
    EXPECT_TRUE(copy == store);
    RecordStore other(body);
    for (std::size_t r = 0; r + 1 < rows; ++r) other.Append(store.Row(r));
    EXPECT_FALSE(other == store);
  }
  // Small rows across blocks (2 MiB each: 32768 rows of 37 bytes).
  RecordStore store(37);
  const std::vector<std::uint8_t> bytes = Pattern(37 * 100003);
  for (std::size_t r = 0; r < 100003; ++r) store.Append(bytes.data() + r * 37);
  ASSERT_EQ(store.rows(), 100003u);
  for (std::size_t r = 0; r < 100003; ++r) {
    ASSERT_EQ(std::memcmp(store.Row(r), bytes.data() + r * 37, 37), 0) << r;
  }
  EXPECT_TRUE(RecordStore(store) == store);
}

TEST(LogCommon, ReadForwardHandsEveryByteOnceWithItsLookahead) {
  ::plumb::testing::TempDir dir;
  const std::vector<std::uint8_t> file = Pattern((std::size_t{21} << 20) + 777);
  const std::string path = WriteFile(dir, file);
  constexpr std::size_t kLookahead = 300000;
  std::vector<std::uint8_t> seen;
  std::size_t calls = 0;
  bool ended = false;
  ReadForward(path, "test log", kLookahead,
              [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
                EXPECT_FALSE(ended);
                EXPECT_EQ(offset, seen.size());  // the bytes kept come again first
                EXPECT_EQ(std::memcmp(data, file.data() + offset, n), 0);
                ++calls;
                ended = at_end;
                if (at_end) {
                  seen.insert(seen.end(), data, data + n);
                  return offset + n;
                }
                EXPECT_GT(n, kLookahead);
                // Consume up to kLookahead bytes before the end, in steps of 7 (a parser).
                const std::size_t take = (n - kLookahead) / 7 * 7;
                seen.insert(seen.end(), data, data + take);
                return offset + take;
              });
  EXPECT_TRUE(ended);
  EXPECT_GT(calls, 4u);
  EXPECT_TRUE(seen == file);
}

TEST(LogCommon, ReadForwardJumpsAndGrowsItsBuffer) {
  ::plumb::testing::TempDir dir;
  const std::vector<std::uint8_t> file = Pattern(std::size_t{12} << 20);
  const std::string path = WriteFile(dir, file);
  std::vector<std::size_t> offsets;
  std::size_t largest = 0;
  ReadForward(path, "test log", 16,
              [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
                EXPECT_EQ(std::memcmp(data, file.data() + offset, n), 0);
                offsets.push_back(offset);
                largest = std::max(largest, n);
                if (at_end) return offset + n;
                // More than one span (of either way of reading) holds, before it goes on.
                if (offset == 0 && n < (std::size_t{5} << 20)) return offset;  // needs more
                if (offset == 0) return std::size_t{10} << 20;  // a jump past the bytes held
                return offset + n - 16;  // not reached: the jump's chunk ends the file
              });
  EXPECT_GE(largest, std::size_t{5} << 20);  // the span grew for the first position
  ASSERT_GE(offsets.size(), 3u);
  EXPECT_EQ(offsets.front(), 0u);
  EXPECT_EQ(offsets[offsets.size() - 2], 0u);
  EXPECT_EQ(offsets.back(), std::size_t{10} << 20);  // the bytes in between never handed over
}

// Part of a file: from an offset (the bytes before it never handed over) to where the consumer
// says stop (no call after it), as the two-part .bin read reads its parts.
TEST(LogCommon, ReadForwardFromAnOffsetUntilTheConsumerStops) {
  ::plumb::testing::TempDir dir;
  const std::vector<std::uint8_t> file = Pattern((std::size_t{9} << 20) + 12345);
  const std::string path = WriteFile(dir, file);
  const std::size_t from = (std::size_t{3} << 20) + 4097;  // not on a page boundary
  const std::size_t stop = (std::size_t{7} << 20) + 5;
  std::vector<std::uint8_t> seen;
  std::size_t calls_after_stop = 0;
  bool stopped = false;
  ReadForward(
      path, "test log", 255,
      [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
        if (stopped) ++calls_after_stop;
        EXPECT_EQ(offset, from + seen.size());
        EXPECT_EQ(std::memcmp(data, file.data() + offset, n), 0);
        EXPECT_FALSE(at_end);
        if (offset + n >= stop) {
          seen.insert(seen.end(), data, data + (stop - offset));
          stopped = true;
          return kStopReading;
        }
        seen.insert(seen.end(), data, data + (n - 255));
        return offset + n - 255;
      },
      from);
  EXPECT_TRUE(stopped);
  EXPECT_EQ(calls_after_stop, 0u);
  EXPECT_TRUE(seen == std::vector<std::uint8_t>(file.begin() + from, file.begin() + stop));
  // From the end: one call, no bytes, at the end.
  std::size_t calls = 0;
  ReadForward(
      path, "test log", 255,
      [&](const std::uint8_t*, std::size_t n, std::size_t offset, bool at_end) {
        ++calls;
        EXPECT_EQ(n, 0u);
        EXPECT_EQ(offset, file.size());
        EXPECT_TRUE(at_end);
        return offset;
      },
      file.size());
  EXPECT_EQ(calls, 1u);
}

TEST(LogCommon, RecordStoreAppendsAnotherStore) {
  const std::vector<std::uint8_t> bytes = Pattern(37 * 70001);
  RecordStore whole(37), first(37), second(37);
  for (std::size_t r = 0; r < 70001; ++r) {
    whole.Append(bytes.data() + r * 37);
    (r < 40000 ? first : second).Append(bytes.data() + r * 37);
  }
  first.Append(second);
  EXPECT_TRUE(first == whole);
  first.Append(RecordStore(37));  // nothing
  EXPECT_TRUE(first == whole);
}

// A log cut short while it is read (copied over, or a card failing) is a read error naming
// the file and the byte, not a SIGBUS from touching a mapped page past the new end.
TEST(LogCommon, ReadForwardReportsAFileCutShortWhileItIsRead) {
  ::plumb::testing::TempDir dir;
  // Cut past the first span (4 MiB mapped, 256 KiB read), while that span is parsed.
  const std::vector<std::uint8_t> file = Pattern(std::size_t{12} << 20);
  const std::string path = WriteFile(dir, file);
  constexpr std::size_t kCut = std::size_t{6} << 20;
  std::size_t handed = 0;  // bytes handed over, all of them before the cut
  try {
    ReadForward(path, "test log", 16,
                [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
                  EXPECT_EQ(std::memcmp(data, file.data() + offset, n), 0);
                  if (offset == 0) std::filesystem::resize_file(path, kCut);
                  handed = offset + n;
                  return at_end ? offset + n : offset + n - 16;
                });
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("cut short or replaced while plumb read it"), std::string::npos) << what;
    EXPECT_LE(handed, kCut);
  }
}

// A parser inside a span when the file is cut (log rotation) touches pages past the new end:
// they read as zeros instead of raising SIGBUS, and the reading ends with the cut named.
TEST(LogCommon, ReadForwardSurvivesACutInsideTheSpanBeingParsed) {
  ::plumb::testing::TempDir dir;
  const std::vector<std::uint8_t> file = Pattern(std::size_t{12} << 20);
  const std::string path = WriteFile(dir, file);
  constexpr std::size_t kCut = std::size_t{1} << 20;
  int last_byte = -1;
  try {
    ReadForward(path, "test log", 16,
                [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
                  if (offset == 0) {
                    std::filesystem::resize_file(path, kCut);
                    last_byte = *static_cast<const volatile std::uint8_t*>(data + n - 1);
                  }
                  return at_end ? offset + n : offset + n - 16;
                });
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path + ": the file was cut short or replaced while plumb read it (it had " +
                        std::to_string(file.size()) + " bytes when opened"),
              std::string::npos)
        << what;
  }
  EXPECT_EQ(last_byte, 0) << "the page past the cut reads as zeros";
}

// The same for a whole file mapped at once (the tlog reader's LogFile): the pages past the
// cut read as zeros, and ThrowIfCut names the cut; an intact file passes it.
TEST(LogCommon, LogFileSurvivesACutAndSaysSo) {
  ::plumb::testing::TempDir dir;
  const std::vector<std::uint8_t> bytes = Pattern(std::size_t{1} << 20);
  const std::string path = WriteFile(dir, bytes);
  {
    const LogFile intact(path, "test log");
    EXPECT_EQ(intact.data()[bytes.size() - 1], bytes.back());
    EXPECT_NO_THROW(intact.ThrowIfCut());
  }
  const LogFile file(path, "test log");
  std::filesystem::resize_file(path, 4096);
  EXPECT_EQ(*static_cast<const volatile std::uint8_t*>(file.data() + bytes.size() - 1), 0);
  try {
    file.ThrowIfCut();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cut short or replaced"), std::string::npos) << e.what();
  }
}

// A large decoded buffer is reserved to fill whole 2 MiB pages with its allocator's header,
// so that it can start on a huge page; a small one is reserved as asked.
TEST(LogCommon, HugePageCapacityFillsWholeHugePages) {
  constexpr std::size_t kHuge = std::size_t{2} << 20;
  EXPECT_EQ(HugePageCapacity(1000, sizeof(double)), 1000u);
  EXPECT_EQ(HugePageCapacity(kHuge / 8 - 1, 8), kHuge / 8 - 1);
  for (const std::size_t element : {std::size_t{4}, std::size_t{8}, std::size_t{12}}) {
    for (const std::size_t n : {kHuge / element + 1, std::size_t{3000000}, std::size_t{5555555}}) {
      const std::size_t capacity = HugePageCapacity(n, element);
      EXPECT_GE(capacity, n);
      const std::size_t bytes = capacity * element + 64;  // with the allocator's bookkeeping
      const std::size_t whole = (bytes + kHuge - 1) / kHuge * kHuge;
      EXPECT_LT(whole - bytes, element) << n << " of " << element;  // short of no element
      EXPECT_LE(capacity * element, n * element + kHuge);  // never a whole huge page more
    }
  }
  std::vector<float> v{1.0F, 2.0F};
  ReserveHugePages(v, 3000000);
  EXPECT_GE(v.capacity(), 3000000u);
  EXPECT_EQ(v, (std::vector<float>{1.0F, 2.0F}));  // the contents stay
}

TEST(LogCommon, ReadForwardNamesAMissingFile) {
  try {
    ReadForward("/nonexistent/plumb/log.bin", "test log", 1,
                [](const std::uint8_t*, std::size_t n, std::size_t offset, bool) {
                  return offset + n;
                });
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/plumb/log.bin"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("cannot open the test log"), std::string::npos);
  }
}

}  // namespace
}  // namespace plumb::io

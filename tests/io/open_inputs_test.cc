// Every input form behind one call (io/input/open_inputs.h): native CSV by its header, text
// tables with units, scales, offsets and the axis map, the two-file form, flight logs by
// content, joining with the clock shifted, the "counts" units, and the before_read hook.
#include "plumb/io/input/open_inputs.h"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "io_test_util.h"
#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb::io {
namespace {

using testing::ExpectInputError;
using testing::TempDir;

const char kNative[] =
    "time_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n"
    "0.0,0.1,0.2,-9.8,0.01,0.02,0.03\n"
    "0.1,0.1,0.2,-9.8,0.01,0.02,0.03\n"
    "0.2,0.1,0.2,-9.8,0.01,0.02,0.03\n";

// The memory estimate: 20 MiB + a factor per format (recognised by content, not name) times
// the file size; 0 for what is not a file.
TEST(OpenInputs, MemoryEstimateFromSizeAndFormat) {
  TempDir dir;
  std::string csv = "time_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n";
  for (int k = 0; k < 1000; ++k) csv += std::to_string(k) + ",0,0,-9.8,0,0,0\n";
  const std::string table = dir.Write("x.bin", csv);  // a text table whatever its name
  EXPECT_EQ(EstimateReadMemory(table),
            kReadMemoryBaseBytes +
                static_cast<std::uint64_t>(kTableMemoryFactor * static_cast<double>(csv.size())));
  // A DataFlash start (by its bytes, whatever the name) whose 1 MB hold one FMT record and
  // nothing a session keeps: the estimate is the base and that record's body.
  std::string bin = "\xA3\x95\x80";
  bin.resize(1000000, '\0');
  const std::string log = dir.Write("x.csv", bin);
  EXPECT_GT(EstimateReadMemory(log), kReadMemoryBaseBytes);
  EXPECT_LT(EstimateReadMemory(log), kReadMemoryBaseBytes + 1000u);
  EXPECT_EQ(EstimateReadMemory(dir.File("absent")), 0u);
  EXPECT_EQ(EstimateReadMemory(dir.File("")), 0u);  // the folder
}

// A FIFO gives its bytes once: it is read whole into memory (StreamSpool) before its format is
// sniffed, so the session is the file's; the copy is named by OpenPath only while held, and
// one longer than the bound is refused with the byte where it stopped.
TEST(OpenInputs, AFifoIsReadWholeBeforeItsFormatIsSniffed) {
  TempDir dir;
  const std::string fifo = dir.File("samples.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto feed = [&](const std::string& text) {
    return std::thread([fifo, text] { std::ofstream(fifo, std::ios::binary) << text; });
  };
  std::thread writer = feed(kNative);
  const Session s = OpenInputs({fifo});
  writer.join();
  ASSERT_EQ(s.series.size(), 3u);
  EXPECT_FLOAT_EQ(static_cast<float>(s.series.acc[2].z()), -9.8f);
  EXPECT_EQ(s.source, fifo);
  EXPECT_EQ(OpenPath(fifo), fifo);  // released with the read
  EXPECT_EQ(SpooledBytes(fifo), 0u);

  writer = feed(kNative);
  {
    const StreamSpool spool({fifo}, 1000);
    EXPECT_NE(OpenPath(fifo), fifo);
    EXPECT_EQ(SpooledBytes(fifo), std::string(kNative).size());
    EXPECT_EQ(OpenInputs({fifo}).series.size(), 3u);  // the copy, read twice
    EXPECT_EQ(OpenInputs({fifo}).series.size(), 3u);
  }
  writer.join();

  writer = feed(kNative);
  ExpectInputError([&] { const StreamSpool spool({fifo}, 20); }, fifo, "byte 20",
                   {"the stream goes on past 20 bytes (2e-05 MB), the memory allowed for reading "
                    "inputs, before its end"});
  writer.join();
}

TEST(OpenInputs, NativeCsvByItsHeader) {
  TempDir dir;
  const std::string path = dir.Write("a.csv", kNative);
  const Session s = OpenInputs({path});
  EXPECT_EQ(s.source, path);
  ASSERT_EQ(s.series.size(), 3u);
  EXPECT_FLOAT_EQ(s.series.acc[0].z(), -9.8f);
  EXPECT_EQ(s.series.acc_unit, "m/s^2");
}

TEST(OpenInputs, NotNativeEndsWithTheHint) {
  TempDir dir;
  const std::string path = dir.Write("t.txt", "1 2 3\n4 5 6\n");
  InputOptions o;
  o.not_native_hint = "say which column is which";
  ExpectInputError([&] { OpenInputs({path}, o); }, path, "",
                   {"not plumb's native CSV", "found '1 2 3'", "; say which column is which"});
}

TEST(OpenInputs, TableWithUnitsScalesOffsetsAndAxisMap) {
  TempDir dir;
  // Counts at +-2 g (16384 per g) and +-250 deg/s (131 per deg/s), offset 10, no time, 50 Hz.
  const std::string path = dir.Write("m.txt",
                                     "16394,10,-16374,141,10,-121\n"
                                     "16394,10,-16374,141,10,-121\n");
  InputOptions o;
  o.format = InputFormat::kTable;
  o.rate_hz = 50;
  o.columns.acc = {0, 1, 2};
  o.columns.gyr = {3, 4, 5};
  o.acc = {AccUnit::kStandardGravity, 1.0 / 16384, 10.0};
  o.gyr = {GyrUnit::kDegreesPerSecond, 1.0 / 131, 10.0};
  o.axis_map = {1, -2, -3};
  const Session s = OpenInputs({path}, o);
  ASSERT_EQ(s.series.size(), 2u);
  EXPECT_DOUBLE_EQ(s.series.t_s[1], 0.02);
  EXPECT_NEAR(s.series.acc[0].x(), units::kStandardGravity, 1e-5);
  EXPECT_NEAR(s.series.acc[0].z(), units::kStandardGravity, 1e-5);  // -1 g, z flipped
  EXPECT_NEAR(s.series.gyr[0].x(), units::kRadPerDeg, 1e-6);
  EXPECT_NEAR(s.series.gyr[0].z(), units::kRadPerDeg, 1e-6);  // -1 deg/s, z flipped
  EXPECT_EQ(s.series.acc_unit, "m/s^2");
}

// Issue 35 item 7: --from/--to work on every input with times, not on flight logs alone (they
// were silently ignored on CSV).
TEST(OpenInputs, TheTimeWindowKeepsATablesSamplesByItsOwnTimes) {
  TempDir dir;
  const std::string path = dir.Write("a.csv", kNative);
  InputOptions o;
  o.flight_log.from_s = 0.05;
  const Session s = OpenInputs({path}, o);
  ASSERT_EQ(s.series.size(), 2u);
  EXPECT_DOUBLE_EQ(s.series.t_s.front(), 0.1);
  const std::string acc = dir.Write("acc.txt", "0 1 2 3\n1 1 2 3\n2 1 2 3\n3 1 2 3\n");
  const std::string gyr = dir.Write("gyr.txt", "0 4 5 6\n1 4 5 6\n2 4 5 6\n3 4 5 6\n");
  InputOptions two;
  two.flight_log.to_s = 1.0;
  EXPECT_EQ(OpenInputs({{acc, gyr}}, two).series.size(), 2u);
  o.flight_log.from_s = 0.15;  // one sample left
  ExpectInputError([&] { OpenInputs({path}, o); }, path, "",
                   {"fewer than 2 samples in the time window 0.15 s .. end; the stream spans 0 .."});
}

TEST(OpenInputs, TwoFileFormAndCountsUnits) {
  TempDir dir;
  const std::string acc = dir.Write("acc.txt", "0 1 2 3\n1 1 2 3\n2 1 2 3\n");
  const std::string gyr = dir.Write("gyr.txt", "0 4 5 6\n1 4 5 6\n2 4 5 6\n");
  InputOptions o;
  o.acc.unit = AccUnit::kCounts;
  o.gyr.unit = GyrUnit::kCounts;
  const Session s = OpenInputs({{acc, gyr}}, o);
  ASSERT_EQ(s.series.size(), 3u);
  EXPECT_FLOAT_EQ(s.series.acc[2].y(), 2.0f);
  EXPECT_FLOAT_EQ(s.series.gyr[2].z(), 6.0f);
  EXPECT_EQ(s.series.acc_unit, "counts");
  EXPECT_EQ(s.series.gyr_unit, "counts");
  o.format = InputFormat::kNative;
  EXPECT_THROW(OpenInputs({{acc, gyr}}, o), Error);
}

TEST(OpenInputs, JoinsShiftingAnOverlappingClock) {
  TempDir dir;
  const std::string a = dir.Write("a.csv", kNative);
  const std::string b = dir.Write("b.csv", kNative);
  const Session s = OpenInputs({a, b});
  ASSERT_EQ(s.series.size(), 6u);
  EXPECT_DOUBLE_EQ(s.series.t_s[3], 0.2 + 1000.0);
  EXPECT_EQ(s.source, a + " " + b);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].message.find("shifted by 1000.200000 s"), std::string::npos)
      << s.warnings[0].message;
  EXPECT_EQ(s.warnings[0].code, "inputs_overlap");
}

TEST(OpenInputs, RefusesToJoinDifferentSensors) {
  TempDir dir;
  const std::string a = dir.Write("a.csv", kNative);
  const std::string b = dir.Write("b.csv", "time_s,acc_x,acc_y,acc_z\n5,0,0,-9.8\n6,0,0,-9.8\n");
  EXPECT_THROW(OpenInputs({a, b}), Error);
}

TEST(OpenInputs, BeforeReadSeesEveryKindInOrderAndMayRefuse) {
  TempDir dir;
  const std::string a = dir.Write("a.csv", kNative);
  const std::string acc = dir.Write("acc.txt", "0 1 2 3\n1 1 2 3\n");
  const std::string gyr = dir.Write("gyr.txt", "0 4 5 6\n1 4 5 6\n");
  std::vector<std::pair<std::size_t, InputKind>> seen;
  InputOptions o;
  o.before_read = [&](std::size_t i, InputKind kind) { seen.emplace_back(i, kind); };
  OpenInputs({a, {acc, gyr}}, o);
  const std::vector<std::pair<std::size_t, InputKind>> expected = {
      {0, InputKind::kNativeCsv}, {1, InputKind::kTwoTables}};
  EXPECT_EQ(seen, expected);
  o.before_read = [](std::size_t, InputKind kind) {
    if (kind == InputKind::kTwoTables) throw std::runtime_error("no pairs here");
  };
  EXPECT_THROW(OpenInputs({a, {acc, gyr}}, o), std::runtime_error);
}

TEST(OpenInputs, FlightLogByContent) {
  const std::string path = testing::SharedLogPath("ardupilot", "plane408_centre_point.BIN");
  PLUMB_SKIP_IF_ABSENT(path);
  InputOptions o;
  InputKind kind = InputKind::kNativeCsv;
  o.before_read = [&](std::size_t, InputKind k) { kind = k; };
  o.flight_log.imu = 1;
  o.flight_log.to_s = 20.0;
  const Session s = OpenInputs({path}, o);
  EXPECT_EQ(kind, InputKind::kFlightLog);
  EXPECT_NE(s.source.find("IMU2"), std::string::npos) << s.source;
  EXPECT_LE(s.series.t_s.back(), 20.0);
  EXPECT_TRUE(s.site.has_value());
}

TEST(OpenInputs, NoInputIsAnError) { EXPECT_THROW(OpenInputs({}), Error); }

}  // namespace
}  // namespace plumb::io

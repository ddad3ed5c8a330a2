// RecordFilter: a reader that keeps only the bodies of the messages a session reads gives the
// same session, the same counts and the same warnings as one that keeps every body, on every
// shared .bin, .log and .ulg; a value asked of a message left out is an error, not garbage.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "plumb/core/error.h"
#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/px4/px4_session.h"
#include "plumb/io/px4/ulog.h"

namespace plumb::io {
namespace {

std::string SharedFile(const std::string& relative) {
  return std::string(PLUMB_SHARED_DATA_DIR) + "/" + relative;
}

void ExpectSameSeries(const ImuSeries& a, const ImuSeries& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.t_s, b.t_s);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.acc[i], b.acc[i]) << i;
    if (a.has_gyro()) ASSERT_EQ(a.gyr[i], b.gyr[i]) << i;
  }
  EXPECT_EQ(a.temp_c, b.temp_c);
}

/// Kept and filtered reads of a DataFlash log: same counts, warnings, parameters and session.
void CheckDataflash(const DataflashLog& all, const DataflashLog& kept) {
  EXPECT_EQ(all.MessageCounts(), kept.MessageCounts());
  EXPECT_EQ(all.warnings.Describe(), kept.warnings.Describe());
  ASSERT_EQ(all.params.size(), kept.params.size());
  for (const auto& [name, value] : all.params) {
    const double other = kept.params.at(name);
    EXPECT_TRUE(value == other || (std::isnan(value) && std::isnan(other))) << name;  // nan.log
  }
  std::size_t all_bytes = 0, kept_bytes = 0, left_out = 0;
  for (std::size_t k = 0; k < kept.types.size(); ++k) {
    all_bytes += all.types[k].bodies.size();
    kept_bytes += kept.types[k].bodies.size();
    const DataflashType& t = kept.types[k];
    if (!t.bodies_kept && t.rows > 0 && !t.columns.empty()) {
      ++left_out;
      EXPECT_THROW(t.Value(0, 0), Error) << t.name;
    }
  }
  EXPECT_GT(left_out, 0u);
  EXPECT_LT(kept_bytes, all_bytes);
  const Session a = ArdupilotSession(all, FlightLogSelection{});
  const Session b = ArdupilotSession(kept, FlightLogSelection{});
  ExpectSameSeries(a.series, b.series);
  EXPECT_EQ(a.warnings, b.warnings);
}

TEST(RecordFilter, DataflashBinaryKeepsWhatSessionsRead) {
  for (const char* name : {"copter36_chibios.bin", "copter364_fmuv5.bin", "plane408_centre_point.BIN",
                           "copter344_pixhawk1_oldformat.bin"}) {
    const std::string path = SharedFile(std::string("ardupilot/") + name);
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
    SCOPED_TRACE(name);
    CheckDataflash(ReadDataflash(path), ReadDataflash(path, ArdupilotSessionRecords()));
  }
}

TEST(RecordFilter, DataflashTextKeepsWhatSessionsRead) {
  const std::string path = SharedFile("ardupilot/copter311_nan.log");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  CheckDataflash(ReadDataflashText(path), ReadDataflashText(path, ArdupilotSessionRecords()));
}

TEST(RecordFilter, ULogKeepsWhatSessionsRead) {
  for (const char* name : {"sample.ulg", "sample_log_small.ulg", "sample_appended_multiple.ulg"}) {
    const std::string path = SharedFile(std::string("px4/") + name);
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
    SCOPED_TRACE(name);
    const ULog all = ReadULog(path);
    const ULog kept = ReadULog(path, Px4SessionTopics());
    EXPECT_EQ(all.MessageCounts(), kept.MessageCounts());
    EXPECT_EQ(all.param_changes.size(), kept.param_changes.size());
    for (std::size_t k = 0; k < all.param_changes.size(); ++k) {
      EXPECT_EQ(all.param_changes[k].timestamp_us, kept.param_changes[k].timestamp_us);
    }
    std::size_t left_out = 0;
    for (const ULogTopic& t : kept.topics) {
      if (!t.bodies_kept && t.rows > 0 && !t.columns.empty()) {
        ++left_out;
        EXPECT_THROW(t.Value(0, 0), Error) << t.name;
      }
    }
    EXPECT_GT(left_out, 0u);
    const Session a = ULogSession(all, FlightLogSelection{});
    const Session b = ULogSession(kept, FlightLogSelection{});
    ExpectSameSeries(a.series, b.series);
    EXPECT_EQ(a.warnings, b.warnings);
  }
}

}  // namespace
}  // namespace plumb::io

// RecordFilter: a reader that keeps only the bodies of the messages a session reads gives the
// same session, the same counts and the same warnings as one that keeps every body, on every
// shared .bin, .log and .ulg; a value asked of a message left out is an error, not garbage.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "plumb/core/error.h"
#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "dataflash_builder.h"
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

/// The IMU samples decoded in the reader's pass (`kept`, ArdupilotSessionRecords) against the
/// ones decoded from every stored body (`all`): the same instances, samples, errors, streams.
void CheckDecodedImu(const DataflashLog& all, const DataflashLog& kept) {
  const std::vector<DataflashImuInfo> a = DataflashImuInstances(all);
  const std::vector<DataflashImuInfo> b = DataflashImuInstances(kept);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].instance, b[k].instance);
    EXPECT_EQ(a[k].message, b[k].message);
    EXPECT_EQ(a[k].samples, b[k].samples);
    EXPECT_EQ(a[k].rate_hz, b[k].rate_hz);
    EXPECT_EQ(a[k].has_temperature, b[k].has_temperature);
  }
  for (int instance : {0, 1, 2, 3, 255, 256}) {
    SCOPED_TRACE(instance);
    std::string error_all, error_kept;
    ImuSeries sa, sb;
    try {
      sa = ImuFromDataflash(all, instance);
    } catch (const InputError& e) {
      error_all = e.what();
    }
    try {
      sb = ImuFromDataflash(kept, instance);
    } catch (const InputError& e) {
      error_kept = e.what();
    }
    EXPECT_EQ(error_all, error_kept);
    ExpectSameSeries(sa, sb);
  }
  const std::vector<ImuStreamInfo> sa = DataflashImuStreams(all);
  const std::vector<ImuStreamInfo> sb = DataflashImuStreams(kept);
  ASSERT_EQ(sa.size(), sb.size());
  for (std::size_t k = 0; k < sa.size(); ++k) {
    EXPECT_EQ(sa[k].name, sb[k].name);
    EXPECT_EQ(sa[k].instance, sb[k].instance);
    EXPECT_EQ(sa[k].samples, sb[k].samples);
    EXPECT_EQ(sa[k].rate_hz, sb[k].rate_hz);
    EXPECT_EQ(sa[k].t_start_s, sb[k].t_start_s);
    EXPECT_EQ(sa[k].t_end_s, sb[k].t_end_s);
    EXPECT_EQ(sa[k].has_temperature, sb[k].has_temperature);
  }
}

TEST(RecordFilter, DataflashImuDecodedInThePassAsFromBodies) {
  for (const char* name : {"copter36_chibios.bin", "copter364_fmuv5.bin", "plane408_centre_point.BIN",
                           "plane408_pilot_pos.BIN", "plane382_pymavlink_test.BIN",
                           "copter462_truncated_isbd.bin", "copter344_pixhawk1_oldformat.bin"}) {
    const std::string path = SharedFile(std::string("ardupilot/") + name);
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
    SCOPED_TRACE(name);
    const DataflashLog kept = ReadDataflash(path, ArdupilotSessionRecords());
    std::size_t decoded = 0;
    for (const DataflashType& t : kept.types) decoded += t.imu_decoded ? 1 : 0;
    EXPECT_GT(decoded, 0u);
    CheckDecodedImu(ReadDataflash(path), kept);
  }
}

/// A log whose IMU has a float I column (whole, fractional, out-of-range and NaN instances),
/// times that go back, a spike and repeats, and a truncated last record.
TEST(RecordFilter, DataflashImuDecodedKeepsTheTimeRuleAndInstances) {
  using testing::Append;
  using testing::Bytes;
  using testing::Put;
  // TimeUS Q, I f, GyrX..Z fff, AccX..Z fff, T h: 3 + 8 + 4 + 24 + 2 = 41 bytes.
  Bytes log = testing::FmtRecord(128, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns");
  Append(&log, testing::FmtRecord(20, 41, "IMU", "QfffffffH", "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,T"));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float instances[] = {0.0f, 1.0f, 1.5f, 300.0f, -1.0f, nan, 2.0f};
  const std::uint64_t times[] = {1000, 2000, 1500, 3000, 3000, 90000000, 4000, 5000, 6000, 7000};
  std::size_t n = 0;
  for (std::uint64_t t : times) {
    for (float instance : instances) {
      Bytes r = {0xA3, 0x95, 20};
      Put(&r, t + static_cast<std::uint64_t>(n % 3));
      Put(&r, instance);
      for (int k = 0; k < 6; ++k) Put(&r, 0.25f * static_cast<float>(n + k));
      Put(&r, static_cast<std::uint16_t>(n));
      Append(&log, r);
      ++n;
    }
  }
  log.resize(log.size() - 7);  // the last record cut
  const DataflashLog all = ParseDataflash(log.data(), log.size(), "decoded.bin");
  const DataflashLog kept =
      ParseDataflash(log.data(), log.size(), "decoded.bin", ArdupilotSessionRecords());
  ASSERT_TRUE(kept.Find("IMU")->imu_decoded);
  EXPECT_FALSE(kept.Find("IMU")->bodies_kept);
  EXPECT_EQ(all.MessageCounts(), kept.MessageCounts());
  EXPECT_EQ(all.warnings.Describe(), kept.warnings.Describe());
  CheckDecodedImu(all, kept);
  EXPECT_LT(ImuFromDataflash(kept, 0).size(), std::size(times));  // the rule dropped some
  EXPECT_GT(ImuFromDataflash(kept, 0).size(), 3u);
  // Issue 35 item 7: the records left out are counted (they went without a word), the same
  // from the reader's pass as from the bodies.
  for (const DataflashLog* log : {&all, &kept}) {
    const std::size_t samples = ImuFromDataflash(*log, 0).size();
    EXPECT_EQ(DataflashImuRecords(*log, 0), std::size(times));
    const Session s = ArdupilotSession(*log, FlightLogSelection{});
    // Instance 0's records: times + n % 3 with n = 7 k: 1000, 2001, 1502, 3000, 3001, ...;
    // 2001 is the first left out (the record after it goes back).
    ASSERT_TRUE(DataflashImuFirstDropped(*log, 0).has_value());
    EXPECT_DOUBLE_EQ(*DataflashImuFirstDropped(*log, 0), 2001 * 1e-6);
    const std::string said = "decoded.bin: IMU of IMU instance 0: left out " +
                             std::to_string(std::size(times) - samples) + " of " +
                             std::to_string(std::size(times)) +
                             " records by their time (not finite, not above the last kept one, "
                             "or a spike above the next record's: a corrupt or backwards time "
                             "stamp); the first with time 0.002001 s";
    EXPECT_EQ(std::count_if(s.warnings.begin(), s.warnings.end(),
                            [&](const Notice& w) { return w.message.rfind(said, 0) == 0; }),
              1)
        << ::testing::PrintToString(Messages(s.warnings));
  }
}

/// The layout ArduPilot writes (TimeUS Q, I B, the axes and T f: the decoder's UsualColumns),
/// with times that go back, a spike, repeats and an instance no other record has, decoded in
/// the pass as from the bodies; and as the same bytes declared with other format characters of
/// the same values (q, b: the decoder's AnyColumns).
TEST(RecordFilter, DataflashImuDecodedInArduPilotsLayoutAsInAnyOther) {
  using testing::Append;
  using testing::Bytes;
  using testing::Put;
  const std::string columns = "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz";
  const auto build = [&](const std::string& format) {
    // 3 + 8 + 1 + 24 + 4 + 4 + 4 + 1 + 1 + 2 + 2 = 54 bytes.
    Bytes log = testing::FmtRecord(128, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns");
    Append(&log, testing::FmtRecord(21, 54, "IMU", format, columns));
    const std::uint8_t instances[] = {0, 1, 2, 100, 1};  // below 128: the same as int8 (b)
    const std::uint64_t times[] = {1000, 2000, 1500, 3000, 3000, 90000000, 4000, 5000, 6000};
    std::size_t n = 0;
    for (std::uint64_t t : times) {
      for (std::uint8_t instance : instances) {
        Bytes r = {0xA3, 0x95, 21};
        Put(&r, t + static_cast<std::uint64_t>(n % 3));
        Put(&r, instance);
        for (int k = 0; k < 6; ++k) Put(&r, 0.25f * static_cast<float>(n + k) - 3.0f);
        Put(&r, std::uint32_t{0});
        Put(&r, std::uint32_t{0});
        Put(&r, 20.0f + 0.125f * static_cast<float>(n));
        for (int k = 0; k < 6; ++k) r.push_back(0);
        Append(&log, r);
        ++n;
      }
    }
    return log;
  };
  const Bytes usual = build("QBffffffIIfBBHH");
  const Bytes other = build("qbffffffIIfBBHH");
  ASSERT_EQ(usual.size(), other.size());
  const DataflashLog all = ParseDataflash(usual.data(), usual.size(), "usual.bin");
  const DataflashLog kept =
      ParseDataflash(usual.data(), usual.size(), "usual.bin", ArdupilotSessionRecords());
  const DataflashLog kept_other =
      ParseDataflash(other.data(), other.size(), "usual.bin", ArdupilotSessionRecords());
  ASSERT_TRUE(kept.Find("IMU")->imu_decoded);
  ASSERT_TRUE(kept_other.Find("IMU")->imu_decoded);
  EXPECT_EQ(all.MessageCounts(), kept.MessageCounts());
  CheckDecodedImu(all, kept);
  CheckDecodedImu(all, kept_other);
  const ImuSeries s = ImuFromDataflash(kept, 1);
  EXPECT_LT(s.size(), 2 * 9u);  // the rule dropped some
  EXPECT_GT(s.size(), 3u);
  EXPECT_TRUE(s.has_temperature());
  EXPECT_EQ(ImuFromDataflash(kept, 100).size(), ImuFromDataflash(kept_other, 100).size());
}

/// Everything the IMU side of a log gives (streams, every instance's samples and sessions, or
/// the error each throws) as text, the sums of the samples in hexadecimal floating point.
std::string SeriesText(const ImuSeries& s) {
  double sum = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    sum += s.t_s[i] + s.acc[i].sum() + (s.has_gyro() ? s.gyr[i].sum() : 0.0f) +
           (s.has_temperature() ? s.temp_c[i] : 0.0f);
  }
  char text[64];
  std::snprintf(text, sizeof text, "%zu:%a", s.size(), sum);
  return text;
}

template <typename Log, typename Streams, typename Select>
std::string ImuText(const Log& log, Streams streams, Select select) {
  std::ostringstream out;
  try {
    for (const ImuStreamInfo& info : streams(log)) {
      out << info.name << "/" << info.instance << " " << info.samples << " " << info.rate_hz
          << " " << info.t_start_s << " " << info.t_end_s << ": ";
      FlightLogSelection pick;
      pick.imu = info.instance;
      pick.stream = info.name;
      try {
        out << SeriesText(select(log, pick).series) << "\n";
      } catch (const Error& e) {
        out << e.what() << "\n";
      }
    }
  } catch (const Error& e) {
    out << "streams: " << e.what();
  }
  return out.str();
}

std::vector<std::uint8_t> FileStart(const std::string& path, std::size_t bytes) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::uint8_t> out((std::istreambuf_iterator<char>(in)), {});
  if (out.size() > bytes) out.resize(bytes);
  return out;
}

/// The start of `bytes` damaged the `variant`-th way: bytes flipped at a fixed stride, and for
/// odd variants the end cut (deterministic).
std::vector<std::uint8_t> Damaged(std::vector<std::uint8_t> bytes, int variant) {
  const std::size_t stride = 997 + 101 * static_cast<std::size_t>(variant);
  for (std::size_t k = 13 * static_cast<std::size_t>(variant) + 20; k < bytes.size(); k += stride) {
    bytes[k] = static_cast<std::uint8_t>(bytes[k] ^ (0x5A + variant));
  }
  if (variant % 2 == 1) bytes.resize(bytes.size() - 1000 * static_cast<std::size_t>(variant));
  return bytes;
}

/// On damaged logs (flipped bytes, cut ends) the samples decoded in the pass still equal the
/// ones decoded from bodies, stream by stream and session by session, errors included.
TEST(RecordFilter, DecodedInThePassAsFromBodiesOnDamagedLogs) {
  for (const char* name : {"ardupilot/copter36_chibios.bin", "ardupilot/plane408_centre_point.BIN",
                           "ardupilot/copter364_fmuv5.bin", "px4/sample.ulg"}) {
    const std::string path = SharedFile(name);
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
    const std::vector<std::uint8_t> start = FileStart(path, std::size_t{1} << 20);
    for (int variant = 0; variant < 6; ++variant) {
      SCOPED_TRACE(std::string(name) + " variant " + std::to_string(variant));
      const std::vector<std::uint8_t> b = Damaged(start, variant);
      if (std::string(name).rfind("px4/", 0) == 0) {
        const ULog all = ParseULog(b.data(), b.size(), "damaged");
        const ULog kept = ParseULog(b.data(), b.size(), "damaged", Px4SessionTopics());
        EXPECT_EQ(all.MessageCounts(), kept.MessageCounts());
        EXPECT_EQ(all.warnings.Describe(), kept.warnings.Describe());
        const auto session = [](const ULog& log, const FlightLogSelection& pick) {
          return ULogSession(log, pick);
        };
        EXPECT_EQ(ImuText(all, ULogImuStreams, session), ImuText(kept, ULogImuStreams, session));
      } else {
        const DataflashLog all = ParseDataflash(b.data(), b.size(), "damaged");
        const DataflashLog kept =
            ParseDataflash(b.data(), b.size(), "damaged", ArdupilotSessionRecords());
        EXPECT_EQ(all.MessageCounts(), kept.MessageCounts());
        EXPECT_EQ(all.warnings.Describe(), kept.warnings.Describe());
        const auto session = [](const DataflashLog& log, const FlightLogSelection& pick) {
          return ArdupilotSession(log, pick);
        };
        const std::string text = ImuText(all, DataflashImuStreams, session);
        EXPECT_EQ(text, ImuText(kept, DataflashImuStreams, session));
        EXPECT_NE(text.find("IMU"), std::string::npos);
      }
    }
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

/// Every stream of every shared .ulg: the samples sensor_combined's reader decoded in its pass
/// (Px4SessionTopics) equal the ones decoded from its stored bodies, as listed and as sessions.
TEST(RecordFilter, ULogSensorCombinedDecodedInThePassAsFromBodies) {
  std::size_t decoded = 0;
  for (const char* name : {"sample.ulg", "sample_log_small.ulg", "sample_appended_multiple.ulg",
                           "sample_logging_tagged_and_default_params.ulg",
                           "sample_px4_events.ulg"}) {
    const std::string path = SharedFile(std::string("px4/") + name);
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
    SCOPED_TRACE(name);
    const ULog all = ReadULog(path);
    const ULog kept = ReadULog(path, Px4SessionTopics());
    if (const ULogTopic* t = kept.Find("sensor_combined"); t != nullptr && t->imu_decoded) {
      ++decoded;
      EXPECT_FALSE(t->bodies_kept);
      EXPECT_EQ(t->KeptBytes(), all.Find("sensor_combined")->bodies.size());
    }
    const std::vector<ImuStreamInfo> a = ULogImuStreams(all);
    const std::vector<ImuStreamInfo> b = ULogImuStreams(kept);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].name, b[k].name);
      EXPECT_EQ(a[k].instance, b[k].instance);
      EXPECT_EQ(a[k].samples, b[k].samples);
      EXPECT_EQ(a[k].t_start_s, b[k].t_start_s);
      EXPECT_EQ(a[k].t_end_s, b[k].t_end_s);
      EXPECT_EQ(a[k].rate_hz, b[k].rate_hz);
      FlightLogSelection pick;
      pick.imu = a[k].instance;
      pick.stream = a[k].name;
      ExpectSameSeries(ULogSession(all, pick).series, ULogSession(kept, pick).series);
    }
  }
  EXPECT_GT(decoded, 0u);
}

}  // namespace
}  // namespace plumb::io

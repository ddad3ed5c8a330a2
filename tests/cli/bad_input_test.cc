// The bad-input battery: every command that reads a file runs on empty, garbage, truncated,
// byte-flipped and NaN versions of each kind of input plumb reads (native CSV; ArduPilot .bin
// and text .log, PX4 .ulg, MAVLink .tlog and a ROS bag from ../shared/data when present; calibration,
// truth and study JSON). For every run: the process exits by itself with a code below 128 (no
// abort, no signal), a failure's message names the damaged file and holds no NUL or raw
// binary byte, and no input file is changed. The damage is drawn from fixed seeds, so every
// run of the battery is the same.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using testing::Contains;
using testing::Plumb;
using testing::ReadAll;
using testing::TempDir;
using testing::ToolRun;
namespace fs = std::filesystem;

void Write(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

/// The damaged versions of `good`, by name: empty, garbage (random bytes), truncated (a third
/// and a few bytes), flipped (one bit in every 500 bytes of the first 200 kB), each drawn from
/// `seed`.
std::map<std::string, std::string> Damaged(const std::string& good, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255), bit(0, 7);
  std::map<std::string, std::string> out;
  out["empty"] = "";
  std::string garbage(4096, '\0');
  for (char& c : garbage) c = static_cast<char>(byte(rng));
  out["garbage"] = garbage;
  out["truncated"] = good.substr(0, good.size() / 3 + 7);
  std::string flipped = good.substr(0, 200000);
  std::uniform_int_distribution<std::size_t> at(0, flipped.size() - 1);
  for (std::size_t k = 0; k < flipped.size() / 500 + 1; ++k) {
    flipped[at(rng)] ^= static_cast<char>(1 << bit(rng));
  }
  out["flipped"] = flipped;
  return out;
}

/// True when `text` holds a NUL or a byte that is not part of valid UTF-8.
bool HasRawBytes(const std::string& text) {
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == 0) return true;
    std::size_t n = c < 0x80 ? 1 : c >= 0xf0 ? 4 : c >= 0xe0 ? 3 : c >= 0xc2 ? 2 : 0;
    if (n == 0 || i + n > text.size()) return true;
    for (std::size_t k = 1; k < n; ++k) {
      if ((static_cast<unsigned char>(text[i + k]) & 0xc0) != 0x80) return true;
    }
    i += n;
  }
  return false;
}

class BadInput : public ::testing::Test {
 protected:
  /// A small simulated session, its calibration and its truth, once per test.
  void SetUp() override {
    session_ = dir_.File("good.csv");
    truth_ = dir_.File("good.truth.json");
    const ToolRun sim = Plumb({"simulate", "--out", session_, "--poses", "9", "--rate", "50",
                               "--seed", "5", "--truth-json", truth_}, dir_);
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
    calibration_ = dir_.File("good.cal.json");
    const ToolRun cal = Plumb({"calibrate", session_, "--json", calibration_}, dir_);
    ASSERT_EQ(cal.exit_code, 0) << cal.err;
  }

  /// Runs `args`; checks the exit, that a failure names `damaged` in clean text, and that no
  /// file of the folder changed.
  void Check(const std::vector<std::string>& args, const std::string& damaged) {
    std::map<std::string, std::string> before;
    for (const auto& e : fs::directory_iterator(dir_.path())) {
      if (e.is_regular_file() && e.path().filename().string()[0] != '.') {
        before[e.path().string()] = ReadAll(e.path().string());
      }
    }
    const ToolRun run = Plumb(args, dir_);
    std::string line = "plumb";
    for (const std::string& a : args) line += " " + fs::path(a).filename().string();
    ++runs_;
    EXPECT_GE(run.exit_code, 0) << line << ": killed by a signal\n" << run.err;
    EXPECT_LT(run.exit_code, 128) << line << "\n" << run.err;
    if (run.exit_code != 0) {
      EXPECT_TRUE(Contains(run.err, damaged)) << line << ": the message does not name "
                                              << damaged << "\n" << run.err;
      EXPECT_FALSE(HasRawBytes(run.err)) << line << "\n" << run.err;
    }
    for (const auto& [path, bytes] : before) {
      EXPECT_EQ(ReadAll(path), bytes) << path << " changed by: " << line;
    }
  }

  /// Every command that reads a session, on `input`.
  void EveryCommandOn(const std::string& input) {
    const std::string out = dir_.File("out");
    fs::remove_all(out);
    fs::create_directories(out);
    Check({"info", input}, input);
    Check({"allan", input}, input);
    Check({"calibrate", input, "--json", out + "/c.json"}, input);
    Check({"diagnose", input, "--confirm", "0", "--json", out + "/d.json"}, input);
    Check({"report", input, "--out", out + "/page"}, input);
    Check({"apply", calibration_, input, "--out", out + "/a.csv"}, input);
    Check({"paper", input, "--static", input, "--lat", "50", "--lon", "8", "--out",
           out + "/paper"}, input);
  }

  /// The damaged versions of `good` (and those in `extra`) as files NAME.EXT, each run
  /// through every command.
  void Battery(const std::string& good, const std::string& ext, std::uint32_t seed,
               std::map<std::string, std::string> extra = {}) {
    std::map<std::string, std::string> cases = Damaged(good, seed);
    cases.insert(extra.begin(), extra.end());
    for (const auto& [name, bytes] : cases) {
      const std::string path = dir_.File(name + "." + ext);
      Write(path, bytes);
      EveryCommandOn(path);
      fs::remove(path);
    }
    EXPECT_GE(runs_, 7 * cases.size());
  }

  /// A log from ../shared/data, or "" (the test then skips).
  static std::string SharedLog(const std::string& relative) {
    const std::string path = std::string(PLUMB_SHARED_DATA_DIR) + "/" + relative;
    return fs::exists(path) ? ReadAll(path) : std::string();
  }

  TempDir dir_;
  std::string session_, truth_, calibration_;
  std::size_t runs_ = 0;
};

TEST_F(BadInput, NativeCsv) {
  const std::string good = ReadAll(session_);
  // Every 97th row's acc_y replaced by nan: finite numbers expected (or --drop-nan).
  std::istringstream rows(good);
  std::string nan, row;
  for (int k = 0; std::getline(rows, row); ++k) {
    const auto first = row.find(','), second = row.find(',', first + 1),
               third = row.find(',', second + 1);
    if (k > 0 && k % 97 == 0 && third != std::string::npos) {
      row.replace(second + 1, third - second - 1, "nan");
    }
    nan += row + "\n";
  }
  std::string nul = good;
  nul.insert(1000, std::string("\0abc", 4));
  Battery(good, "csv", 1, {{"nan", nan}, {"nul", nul}});
}

TEST_F(BadInput, ArduPilotBin) {
  const std::string good = SharedLog("ardupilot/plane382_pymavlink_test.BIN");
  if (good.empty()) GTEST_SKIP() << "shared data absent: " << PLUMB_SHARED_DATA_DIR;
  Battery(good, "bin", 2);
}

TEST_F(BadInput, ArduPilotTextLog) {
  const std::string good = SharedLog("ardupilot/copter311_nan.log");
  if (good.empty()) GTEST_SKIP() << "shared data absent: " << PLUMB_SHARED_DATA_DIR;
  Battery(good, "log", 3);
}

TEST_F(BadInput, Px4ULog) {
  const std::string good = SharedLog("px4/sample_log_small.ulg");
  if (good.empty()) GTEST_SKIP() << "shared data absent: " << PLUMB_SHARED_DATA_DIR;
  Battery(good, "ulg", 4);
}

TEST_F(BadInput, MavlinkTlog) {
  const std::string good = SharedLog("mavlink/plane385_disarmed.tlog");
  if (good.empty()) GTEST_SKIP() << "shared data absent: " << PLUMB_SHARED_DATA_DIR;
  Battery(good, "tlog", 5);
}

TEST_F(BadInput, RosBag) {
  const std::string good = SharedLog("ros/ardrone_imu.bag");
  if (good.empty()) GTEST_SKIP() << "shared data absent: " << PLUMB_SHARED_DATA_DIR;
  // Besides the battery: the magic and then garbage, another bag version, and the bag with its
  // first chunk's stated size made wrong (bytes 4129..: the ardrone bag's first chunk header).
  std::string garbage(4096, '\x5a');
  std::string wrong_size = good;
  const std::size_t size_field = wrong_size.find("size=", 4096 + 13);
  if (size_field != std::string::npos) wrong_size[size_field + 6] ^= 0x40;
  Battery(good, "bag", 6,
          {{"after_magic", "#ROSBAG V2.0\n" + garbage}, {"version12", "#ROSBAG V1.2\n" + garbage},
           {"wrong_size", wrong_size}});
}

// ROS 2 bags: the small MCAP (zstd chunks) and .db3 seeds of tests/fuzz (60 messages of a real
// recording, written by an independent writer), through the battery; besides: the magic and
// then garbage, another MCAP version, and the SQLite header and then garbage.
TEST_F(BadInput, Ros2Mcap) {
  const std::string good =
      ReadAll(std::string(PLUMB_SOURCE_DIR) + "/tests/fuzz/seeds/mcap/phidgets_60_zstd.mcap");
  ASSERT_FALSE(good.empty());
  const std::string garbage(4096, '\x5a');
  Battery(good, "mcap", 7,
          {{"after_magic", std::string("\x89MCAP0\r\n", 8) + garbage},
           {"version1", std::string("\x89MCAP1\r\n", 8) + garbage}});
}

/// `mcap` with one bit flipped in the middle of its first chunk's records (opcode 0x06 after
/// the magic; uncompressed, so the messages still decode); `chunk_at` the chunk's offset.
std::string FlipInFirstChunk(std::string mcap, std::size_t* chunk_at) {
  std::size_t at = 8;
  std::uint64_t len = 0;
  while (at + 9 <= mcap.size()) {
    std::memcpy(&len, mcap.data() + at + 1, sizeof len);
    if (mcap[at] == 0x06) break;
    at += 9 + static_cast<std::size_t>(len);
  }
  mcap[at + 9 + static_cast<std::size_t>(len) * 3 / 4] ^= 0x04;
  *chunk_at = at;
  return mcap;
}

// A chunk not matching its CRC-32 (stated by @mcap/core): exit 1, the message naming the file,
// the chunk's byte offset and the CRC; and through the battery.
TEST_F(BadInput, Ros2McapChunkCrc) {
  std::size_t at = 0;
  const std::string flipped = FlipInFirstChunk(
      ReadAll(std::string(PLUMB_SOURCE_DIR) + "/tests/fuzz/seeds/mcap/phidgets_60.mcap"), &at);
  const std::string path = dir_.File("crc.mcap");
  Write(path, flipped);
  const ToolRun run = Plumb({"info", path}, dir_);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_TRUE(Contains(run.err, path + ":byte " + std::to_string(at) + ": ")) << run.err;
  EXPECT_TRUE(Contains(run.err, "uncompressed_crc")) << run.err;
  fs::remove(path);
  Battery(ReadAll(std::string(PLUMB_SOURCE_DIR) + "/tests/fuzz/seeds/mcap/phidgets_60.mcap"),
          "mcap", 9, {{"crc", flipped}});
}

TEST_F(BadInput, Ros2Db3) {
  const std::string good =
      ReadAll(std::string(PLUMB_SOURCE_DIR) + "/tests/fuzz/seeds/db3/phidgets_60.db3");
  ASSERT_FALSE(good.empty());
  const std::string garbage(4096, '\x5a');
  Battery(good, "db3", 8, {{"after_header", std::string("SQLite format 3\0", 16) + garbage}});
}

TEST_F(BadInput, CalibrationTruthAndStudyFiles) {
  // JSON files other commands read: a calibration (apply, compare), a truth (compare --truth),
  // a study (sweep); damaged, and with a NaN where a number belongs.
  const std::string study = R"({"name": "t", "runs": 1, "factors": [{"name": "poses", "levels": [9]}]})";
  std::string nan_cal = ReadAll(calibration_);
  nan_cal.replace(nan_cal.find("\"bias\": [") + 9, 0, "NaN, ");
  const std::map<std::string, std::string> goods = {
      {"cal", ReadAll(calibration_)}, {"truth", ReadAll(truth_)}, {"study", study}};
  std::uint32_t seed = 10;
  for (const auto& [kind, good] : goods) {
    std::map<std::string, std::string> cases = Damaged(good, ++seed);
    if (kind == "cal") cases["nan"] = nan_cal;
    for (const auto& [name, bytes] : cases) {
      const std::string path = dir_.File(kind + "_" + name + ".json");
      Write(path, bytes);
      const std::string out = dir_.File("out");
      fs::remove_all(out);
      if (kind == "cal") {
        Check({"apply", path, session_, "--out", out + ".csv"}, path);
        Check({"compare", path, "--truth", truth_}, path);
      } else if (kind == "truth") {
        Check({"compare", calibration_, "--truth", path}, path);
      } else {
        Check({"sweep", path, "--out", out}, path);
      }
      fs::remove(path);
      fs::remove(out + ".csv");
    }
  }
  EXPECT_GE(runs_, 12u);
}

// Issue 35 item 5: calibrations no sensor has, well-formed JSON all: apply and compare refuse
// each, naming the file and the key (they used to write NaN and inf columns with exit 0, take
// the second of two values, print a sigma of -1). Both read the document with its one reader
// (document/calibration_document.h), so each refuses what the other does.
TEST_F(BadInput, CalibrationsNoSensorHasAreRefusedWithTheKey) {
  using nlohmann::json;
  const json good = json::parse(ReadAll(calibration_));
  const auto index = [&](const std::string& name) {
    for (std::size_t k = 0; k < good["parameters"].size(); ++k) {
      if (good["parameters"][k]["name"] == name) return k;
    }
    return std::size_t{0};
  };
  std::map<std::string, std::pair<json, std::string>> cases;  // name: document, key named
  json twice = good;
  twice["parameters"].push_back(good["parameters"][index("accel.bias.x")]);
  cases["twice"] = {twice, "].name': 'accel.bias.x' given twice"};
  json huge = good;
  huge["parameters"][index("accel.bias.y")]["value"] = 1.7e308;
  huge["accel"]["bias"][1] = 1.7e308;
  cases["huge"] = {huge, "'accel.bias.y' = 1.7e+308 is no sensor's"};
  json singular = good;
  for (const char* name : {"accel.matrix.xx", "accel.matrix.xy", "accel.matrix.xz"}) {
    singular["parameters"][index(name)]["value"] = 0.0;
  }
  singular["accel"]["matrix"][0] = {0.0, 0.0, 0.0};
  cases["singular"] = {singular, "matrix is singular (it maps some input to zero)"};
  json negative = good;
  negative["covariance"]["matrix"][0][0] = -1e-6;
  negative["parameters"][0]["sigma"] = -1e-3;
  cases["negative"] = {negative, "negative"};
  // A sigma column edited apart from the covariance (compare showed a row 25586 sigma off and
  // an NEES inside its band): refused (apply too, though it reads no sigma column: the file
  // was edited).
  json edited_sigma = good;
  edited_sigma["parameters"][index("accel.bias.x")]["sigma"] =
      good["parameters"][index("accel.bias.x")]["sigma"].get<double>() * 1e-4;
  cases["edited_sigma"] = {edited_sigma, "'accel.bias.x' has sigma "};
  for (const auto& [name, c] : cases) {
    const std::string path = dir_.File("cal_" + name + ".json");
    Write(path, c.first.dump(1));
    const std::string out = dir_.File("applied_" + name + ".csv");
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"apply", path, session_, "--out", out},
          std::vector<std::string>{"compare", path, "--truth", truth_}}) {
      const ToolRun run = Plumb(args, dir_);
      EXPECT_EQ(run.exit_code, 1) << args[0] << " " << name << "\n" << run.out << run.err;
      EXPECT_TRUE(Contains(run.err, "plumb: error: " + path + ":key '"))
          << args[0] << " " << name << "\n" << run.err;
      EXPECT_TRUE(Contains(run.err, c.second)) << args[0] << " " << name << "\n" << run.err;
      EXPECT_FALSE(fs::exists(out)) << name;
    }
  }
  // A sample no sensor gives (1e308, read as an infinite float): apply names it, writes nothing.
  std::string rows = ReadAll(session_);
  const std::size_t third = [&] {
    std::size_t at = 0;
    for (int k = 0; k < 2; ++k) at = rows.find('\n', at) + 1;
    return at;
  }();
  rows.replace(rows.find(',', third) + 1, rows.find(',', rows.find(',', third) + 1) - rows.find(',', third) - 1,
               "1e308");
  const std::string samples = dir_.File("huge_sample.csv");
  Write(samples, rows);
  const std::string out = dir_.File("applied_sample.csv");
  const ToolRun run = Plumb({"apply", calibration_, samples, "--out", out}, dir_);
  EXPECT_EQ(run.exit_code, 1) << run.out << run.err;
  EXPECT_TRUE(Contains(run.err, samples + ": sample 1 (t = 0.020000 s) corrects to a value that "
                                          "is not finite"))
      << run.err;
  EXPECT_FALSE(fs::exists(out));
  // A number no double holds, in the calibration: the calibration is named (nlohmann's text
  // blamed the samples file), by every command that reads one.
  std::string text = ReadAll(calibration_);
  const std::string key = "\"value\": ";
  const std::size_t value_at = text.find(key) + key.size();
  text.replace(value_at, text.find_first_of(",\n}", value_at) - value_at, "1e400");
  const std::string overflow = dir_.File("cal_overflow.json");
  Write(overflow, text);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"apply", overflow, session_, "--out", out},
        std::vector<std::string>{"compare", overflow, "--truth", truth_}}) {
    const ToolRun bad = Plumb(args, dir_);
    EXPECT_EQ(bad.exit_code, 1) << bad.err;
    EXPECT_EQ(bad.err, "plumb: error: " + overflow +
                           ": a number beyond the range of a double ('1e400'): not valid here; "
                           "fix or remove that value\n");
  }
}

}  // namespace
}  // namespace plumb::cli

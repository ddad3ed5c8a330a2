// The gates (SPEC section 3, docs/reference/cli.md "Gates") as a user meets them: the exact
// line each failure prints, the headline that never says "consistent with the noise" then,
// --strict exiting 3 with nothing written, --export refused unless --export-anyway; and the
// covariance in --json (SPEC section 6).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "run_tool.h"

namespace plumb::cli {
namespace {

/// True when `text` ends with `tail` (an error line after the warnings on standard error).
bool EndsWith(const std::string& text, const std::string& tail) {
  return text.size() >= tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

using nlohmann::json;
using testing::Contains;
using testing::LineStarting;
using testing::Plumb;
using testing::ReadAll;
using testing::ReadJson;
using testing::TempDir;
using testing::ToolRun;

const std::vector<std::string> kSite = {"--lat", "51.64", "--lon", "-1.2", "--height", "100"};

std::string Mikoff() { return std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log"; }

/// 12 poses of 4 s joined by 1.5 s turns at 100 Hz, white noise, at the site: the first pose
/// is samples [0, 400), the first turn [400, 550).
std::string Simulate(const TempDir& dir, const std::vector<std::string>& extra = {}) {
  const std::string csv = dir.File("session.csv");
  std::vector<std::string> args = {"simulate", "--out", csv, "--poses", "12", "--still", "4",
                                   "--turn", "1.5", "--rate", "100", "--accel-rw", "0",
                                   "--gyro-rw", "0", "--accel-bi", "0", "--gyro-bi", "0",
                                   "--no-temperature", "--seed", "1"};
  args.insert(args.end(), kSite.begin(), kSite.end());
  args.insert(args.end(), extra.begin(), extra.end());
  const ToolRun run = Plumb(args, dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  return csv;
}

ToolRun Calibrate(const std::string& input, const std::vector<std::string>& extra,
                  const TempDir& dir) {
  // The sessions have white noise only: one constant bias is the matching fit.
  std::vector<std::string> args = {"calibrate", input, "--constant-bias"};
  args.insert(args.end(), kSite.begin(), kSite.end());
  args.insert(args.end(), extra.begin(), extra.end());
  return Plumb(args, dir);
}

/// A copy of native CSV `csv` as `name`, `edit` applied to the fields of every data row
/// (row 0 is sample 0).
std::string EditRows(const TempDir& dir, const std::string& csv, const std::string& name,
                     const std::function<void(std::size_t, std::vector<std::string>&)>& edit) {
  std::ifstream in(csv);
  std::ostringstream out;
  std::string line;
  std::getline(in, line);
  out << line << "\n";
  for (std::size_t row = 0; std::getline(in, line); ++row) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    edit(row, f);
    for (std::size_t i = 0; i < f.size(); ++i) out << (i ? "," : "") << f[i];
    out << "\n";
  }
  return dir.Write(name, out.str());
}

/// The second line of calibrate's header: the verdict.
std::string Verdict(const std::string& out) {
  const auto at = out.find("calibrate: method");
  if (at == std::string::npos) return "";
  const auto begin = out.find('\n', at) + 1;
  return out.substr(begin, out.find('\n', begin) - begin);
}

TEST(GatesCli, NotConvergedIsShownStrictExitsThreeAndExportIsRefused) {
  TempDir dir;
  const std::string csv = Simulate(dir);
  const std::string out = dir.File("cal.json"), yaml = dir.File("imu.yaml");
  const ToolRun run = Calibrate(csv, {"--max-iterations", "1", "--json", out}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(LineStarting(run.out, "gate failed: "),
            "gate failed: not_converged: " + csv +
                ": the solver did not converge: its last solve stopped after 2 iterations (4 "
                "over its 2 solves; Termination: NO_CONVERGENCE); the values, sigmas and chi2 are not those of a minimum. Check "
                "the segments and the input's units and rate (the other gates), or allow more "
                "iterations (--max-iterations)")
      << run.out;
  EXPECT_EQ(Verdict(run.out),
            "chi2/dof 0.83, but the fit failed a gate (not_converged): not to be trusted as it "
            "stands");
  // One count of iterations: the JSON's solver line is the last solve's, as the gate says.
  const json fit = ReadJson(out).at("fit");
  EXPECT_EQ(fit.at("solves"), 2);
  EXPECT_EQ(fit.at("last_solve_iterations"), 2);
  EXPECT_EQ(fit.at("iterations"), 4);
  EXPECT_TRUE(Contains(fit.at("solver").get<std::string>(), "Iterations: 2,")) << fit;
  EXPECT_FALSE(Contains(run.out, "consistent with the noise")) << run.out;
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["fit"]["converged"], false);
  ASSERT_EQ(doc["gates"].size(), 1u);
  EXPECT_EQ(doc["gates"][0]["name"], "not_converged");

  const std::string strict_json = dir.File("strict.json");
  const ToolRun strict = Calibrate(csv, {"--max-iterations", "1", "--strict", "--json", strict_json}, dir);
  EXPECT_EQ(strict.exit_code, 3) << strict.err;
  EXPECT_PRED2(EndsWith, strict.err, "plumb: error: the fit of " + csv +
                            " failed a gate (not_converged) under --strict (see 'gate failed' "
                            "above); nothing written\n");
  EXPECT_FALSE(std::filesystem::exists(strict_json));

  const ToolRun refused = Calibrate(csv, {"--max-iterations", "1", "--export", "kalibr=" + yaml}, dir);
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  EXPECT_PRED2(EndsWith, refused.err, "plumb: error: --export refused: the fit of " + csv +
                             " failed a gate (not_converged) (see 'gate failed' above), so its "
                             "parameters would replace the vehicle's with numbers not to be "
                             "trusted; nothing written. Fix the input, or give --export-anyway "
                             "to write them regardless\n");
  EXPECT_FALSE(std::filesystem::exists(yaml));
  const ToolRun forced = Calibrate(
      csv, {"--max-iterations", "1", "--export", "kalibr=" + yaml, "--export-anyway"}, dir);
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_TRUE(std::filesystem::exists(yaml));
}

TEST(GatesCli, SegmentsCutOutOfOnePoseAreOnePose) {
  TempDir dir;
  const std::string csv = Simulate(dir);
  std::string rows = "start,end\n";
  for (int k = 0; k < 12; ++k) {
    rows += std::to_string(10 + 32 * k) + "," + std::to_string(40 + 32 * k) + "\n";
  }
  const std::string pieces = dir.Write("pieces.csv", rows);
  const ToolRun run = Calibrate(csv, {"--segments", pieces}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // The user's case: pieces of one pose once gave full rank (56 of 56); the differences
  // between them place 21 combinations no better than three times their typical size, held
  // where the fit starts.
  EXPECT_TRUE(Contains(run.out, "rank 35 of 56 unknowns")) << run.out;
  EXPECT_TRUE(Contains(run.out, "21 weakly determined combinations held")) << run.out;
  EXPECT_EQ(LineStarting(run.out, "gate failed: one_pose"),
            "gate failed: one_pose: " + csv +
                ": the 12 still segments lie in 1 distinct pose (segments 1-12 have the same "
                "gravity direction within the noise and no turn between them): the rank (35 of "
                "56) and the sigmas rest on 1 pose, and the differences between pieces of one "
                "pose are noise, not information; the accelerometer's 9 free parameters need at "
                "least 9 distinct poses. Record more poses, or give one segment per pose")
      << run.out;
  EXPECT_FALSE(Contains(run.out, "consistent with the noise")) << run.out;
  // Under --strict what one pose cannot determine is refused first (exit 1), saying why.
  const ToolRun strict = Calibrate(csv, {"--segments", pieces, "--strict"}, dir);
  EXPECT_EQ(strict.exit_code, 1) << strict.err;
  EXPECT_TRUE(Contains(strict.err, "the data cannot determine")) << strict.err;
  EXPECT_TRUE(Contains(strict.err, "at least 9 distinct orientations")) << strict.err;
}

// Issue 34 item 4: a "still" segment that holds motion (here a turn given as still, as a
// flight taken for a still pose) fails not_still with its figures; the real poses do not.
TEST(GatesCli, ASegmentThatMovesIsNotStill) {
  TempDir dir;
  const std::string csv = Simulate(dir);
  // The first pose is samples [0, 400), the first turn [400, 550); then poses every 550.
  std::string rows = "start,end,label\n";
  for (int k = 0; k < 12; ++k) {
    rows += std::to_string(20 + 550 * k) + "," + std::to_string(380 + 550 * k) + ",pose " +
            std::to_string(k + 1) + "\n";
    if (k == 0) rows += "400,550,the first turn\n";
  }
  const std::string segments = dir.Write("segments.csv", rows);
  const ToolRun run = Calibrate(csv, {"--segments", segments}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string line = LineStarting(run.out, "gate failed: not_still");
  EXPECT_TRUE(Contains(line, "gate failed: not_still: " + csv +
                                 ": 1 of 13 still segments scatter far beyond an IMU at rest, "
                                 "per sample: 'the first turn' (4.0-5.5 s): "))
      << run.out;
  EXPECT_TRUE(Contains(line, "above 0.1 rad/s")) << line;
  EXPECT_FALSE(Contains(run.out, "consistent with the noise")) << run.out;
  // The poses alone pass.
  std::string poses = "start,end\n";
  for (int k = 0; k < 12; ++k) {
    poses += std::to_string(20 + 550 * k) + "," + std::to_string(380 + 550 * k) + "\n";
  }
  const ToolRun clean = Calibrate(csv, {"--segments", dir.Write("poses.csv", poses)}, dir);
  ASSERT_EQ(clean.exit_code, 0) << clean.err;
  EXPECT_FALSE(Contains(clean.out, "not_still")) << clean.out;
}

// Issue 34 item 4: poses are counted by one function; the advice's "found N", the JSON's
// distinct_poses and the one_pose gate say the same number (a single hold cut in three).
TEST(GatesCli, TheAdviceTheJsonAndTheGateCountTheSamePoses) {
  TempDir dir;
  const std::string csv = dir.File("static.csv");
  ASSERT_EQ(Plumb({"simulate", "--schedule", "paper-static", "--out", csv, "--random-truth", "1",
                   "--accel-rw", "0", "--gyro-rw", "0", "--accel-bi", "0", "--gyro-bi", "0",
                   "--seed", "5"},
                  dir).exit_code, 0);
  const std::string pieces = dir.Write("pieces.csv", "start,end\n100,3000\n3100,6000\n6100,9000\n");
  const ToolRun run = Plumb({"calibrate", csv, "--segments", pieces, "--json", dir.File("c.json")}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json c = ReadJson(dir.File("c.json"));
  const int poses = c.at("fit").at("distinct_poses").get<int>();
  EXPECT_EQ(poses, 1);
  EXPECT_TRUE(Contains(run.err, "distinct orientations (fewer when attitudes are known); found " +
                                    std::to_string(poses) + ";"))
      << run.err;
  EXPECT_TRUE(Contains(LineStarting(run.out, "gate failed: one_pose"),
                       "the 3 still segments lie in " + std::to_string(poses) + " distinct pose "))
      << run.out;
}

TEST(GatesCli, SamplesOutOfRangeAreNamedWithTheFirstTimeAndTheCount) {
  TempDir dir;
  const std::string csv = Simulate(dir);
  const std::string bad = EditRows(dir, csv, "bad.csv", [](std::size_t row, auto& f) {
    if (row == 1000) f[3] = "4.7e21";  // acc_z of one sample in a turn
  });
  const ToolRun run = Calibrate(bad, {}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(LineStarting(run.out, "gate failed: out_of_range"),
            "gate failed: out_of_range: " + bad +
                ": 1 sample outside any IMU's range (an axis beyond 313.8 m/s^2 (32 g) or 69.81 "
                "rad/s (4000 deg/s), or not finite), 0 of them inside the still segments; the "
                "first at t = 10 s (sample 1000): accel (-9.265, -2.522, 4.7e+21) m/s^2, gyro "
                "(1.221, 1.222, -1.202) rad/s. A corrupt log (flipped bytes, a bad record) or a "
                "wrong unit: cut them out (--from/--to, --segments) or fix the input before "
                "trusting this fit")
      << run.out;
  // One corrupt sample in a turn leaves misalignments weakly determined: under --strict that
  // is refused first (exit 1), naming what the data cannot determine.
  const ToolRun strict = Calibrate(bad, {"--strict"}, dir);
  EXPECT_EQ(strict.exit_code, 1) << strict.err;
  EXPECT_TRUE(Contains(strict.err, "the data cannot determine")) << strict.err;
}

/// Reverses the bytes of AccZ in IMU records 2001-2040 of a DataFlash .bin (a corrupt log:
/// -9.7 m/s^2 reads as 4.7e21 in some of them).
std::string FlipImuBytes(const std::string& bin, const TempDir& dir) {
  std::string data = ReadAll(bin);
  std::map<int, std::pair<int, std::string>> formats;  // type -> length, name
  int imu = -1, offset = 3;
  for (std::size_t i = 0; i + 89 <= data.size(); ++i) {
    if (static_cast<unsigned char>(data[i]) != 0xA3 || static_cast<unsigned char>(data[i + 1]) != 0x95 ||
        static_cast<unsigned char>(data[i + 2]) != 128) {
      continue;
    }
    const std::string name = data.substr(i + 5, 4).c_str();
    if (name != "IMU") continue;
    imu = static_cast<unsigned char>(data[i + 3]);
    const std::string format = data.substr(i + 9, 16).c_str();
    std::string labels = data.substr(i + 25, 64).c_str();
    std::stringstream ss(labels);
    const std::map<char, int> size = {{'Q', 8}, {'f', 4}, {'I', 4}, {'B', 1}, {'H', 2}};
    std::size_t k = 0;
    for (std::string label; std::getline(ss, label, ',') && label != "AccZ"; ++k) {
      offset += size.at(format[k]);
    }
    formats[imu] = {static_cast<unsigned char>(data[i + 4]), name};
    break;
  }
  EXPECT_GE(imu, 0);
  const int length = formats[imu].first;
  int seen = 0;
  for (std::size_t i = 0; i + static_cast<std::size_t>(length) <= data.size(); ++i) {
    if (static_cast<unsigned char>(data[i]) == 0xA3 && static_cast<unsigned char>(data[i + 1]) == 0x95 &&
        static_cast<unsigned char>(data[i + 2]) == imu) {
      ++seen;
      if (seen > 2000 && seen <= 2040) {
        std::reverse(data.begin() + static_cast<std::ptrdiff_t>(i) + offset,
                     data.begin() + static_cast<std::ptrdiff_t>(i) + offset + 4);
      }
      i += static_cast<std::size_t>(length) - 1;
    }
  }
  return dir.Write("flipped.BIN", data);
}

TEST(GatesCli, FlippedBytesInABinLogAreOutOfRange) {
  const std::string log = std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/plane408_centre_point.BIN";
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const std::string flipped = FlipImuBytes(log, dir);  // the original is never written
  const ToolRun run = Plumb({"calibrate", flipped}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "gate failed: out_of_range: " + flipped +
                                    " IMU (IMU instance 0): 16 samples outside any IMU's range "
                                    "(an axis beyond 313.8 m/s^2 (32 g) or 69.81 rad/s (4000 "
                                    "deg/s), or not finite), 0 of them inside the still "
                                    "segments; the first at t = 44.57 s (sample 2001): accel "
                                    "(1.45, 0.593, 4.775e+21) m/s^2"))
      << run.out;
  EXPECT_FALSE(Contains(run.out, "consistent with the noise")) << run.out;
}

TEST(GatesCli, AWrongRateIsNamedAndStrictExportWritesNothing) {
  if (!std::filesystem::exists(Mikoff())) GTEST_SKIP() << "bundled data absent: " << Mikoff();
  TempDir dir;
  const std::vector<std::string> wrong = {"calibrate", Mikoff(), "--columns", "ax,ay,az,gx,gy,gz",
                                          "--rate", "10"};
  const ToolRun run = Plumb(wrong, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // At a tenth of its rate the detector's windows span ten times the motion, and one segment
  // takes in a turn (not_still, 63 times the quietest segment's gyroscope scatter).
  EXPECT_EQ(LineStarting(run.out, "gate failed: unit_or_rate"),
            "gate failed: unit_or_rate: " + Mikoff() +
                ": the gyroscope's scale came out 10.03 (gyro.matrix diagonal 9.987, 10.04, "
                "10.07), not about 1: the turns integrate to 10.03 times the angles the "
                "accelerometer sees between the poses, so the sample times are likely wrong by "
                "that factor: the samples are 0.1 s apart (10 Hz), the turns say about 100.3 Hz "
                "(check --rate, or the time column's unit)")
      << run.out;
  // The user's command: exit 3 and no parameter file (it used to write INS_ACCSCAL_X=141).
  const std::string param = dir.File("F.param");
  std::vector<std::string> strict = wrong;
  strict.insert(strict.end(), {"--strict", "--export", "ardupilot=" + param});
  const ToolRun refused = Plumb(strict, dir);
  EXPECT_EQ(refused.exit_code, 3) << refused.err;
  EXPECT_PRED2(EndsWith, refused.err, "plumb: error: the fit of " + Mikoff() +
                             " failed 2 gates (not_still, unit_or_rate) under --strict (see "
                             "'gate failed' above); nothing written\n");
  EXPECT_FALSE(std::filesystem::exists(param));
  // plumb report too: exit 3 before writing the page.
  const std::string page = dir.File("page");
  const ToolRun report = Plumb({"report", Mikoff(), "--columns", "ax,ay,az,gx,gy,gz", "--rate",
                                "10", "--strict", "--no-figures", "--no-diagnose", "--out", page},
                               dir);
  EXPECT_EQ(report.exit_code, 3) << report.err;
  EXPECT_TRUE(Contains(report.out, "gate failed: unit_or_rate: " + Mikoff())) << report.out;
  EXPECT_FALSE(std::filesystem::exists(page + "/index.html"));
  // The right rate passes every gate.
  const ToolRun right = Plumb({"calibrate", Mikoff(), "--columns", "ax,ay,az,gx,gy,gz", "--rate",
                               "100", "--strict", "--export", "ardupilot=" + param},
                              dir);
  EXPECT_EQ(right.exit_code, 0) << right.err;
  EXPECT_FALSE(Contains(right.out, "gate failed")) << right.out;
  EXPECT_TRUE(std::filesystem::exists(param));
}

TEST(GatesCli, AnAccelerometerInGIsNamed) {
  TempDir dir;
  const std::string csv = Simulate(dir);
  const std::string in_g = EditRows(dir, csv, "g.csv", [](std::size_t, auto& f) {
    for (int i = 1; i <= 3; ++i) f[i] = std::to_string(std::stod(f[i]) / 9.80665);
  });
  const ToolRun run = Calibrate(in_g, {}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string line = LineStarting(run.out, "gate failed: unit_or_rate");
  EXPECT_TRUE(Contains(line, "gate failed: unit_or_rate: " + in_g +
                                 ": the still accelerometer reads 1.00"))
      << run.out;
  EXPECT_TRUE(Contains(line, " m/s^2 (median norm over 12 still segments) where gravity is "
                             "9.812 m/s^2: the samples look like g, not m/s^2: give --acc-unit g"))
      << line;
}

TEST(GatesCli, AnImplausibleWalkEstimateIsAGate) {
  // White noise and a hidden g-sensitivity: --estimate-rw reads the poses' misfit as a walk
  // hundreds of times the typical one, which would make chi2/dof read "consistent".
  TempDir dir;
  const std::string csv = Simulate(dir, {"--model", "base+gyro_g_sensitivity", "--truth",
                                         "gyro_g_sensitivity.G.xz=3e-4"});
  const ToolRun run = Plumb({"calibrate", csv, "--lat", "51.64", "--lon", "-1.2", "--height",
                             "100", "--estimate-rw", "--strict"},
                            dir);
  EXPECT_EQ(run.exit_code, 3) << run.out << run.err;
  const std::string line = LineStarting(run.out, "gate failed: implausible_walk: ");
  // Which sensor's walk absorbs the misfit depends on the poses (here the accelerometer's).
  EXPECT_EQ(line.rfind("gate failed: implausible_walk: " + csv + ": the estimated accelerometer walk is ", 0), 0u)
      << run.out;
  EXPECT_TRUE(Contains(line, " times the typical MEMS walk: the differences between poses it "
                             "was read from are more likely an effect the model misses than a "
                             "walk, and a walk that large hides it from chi2; run 'plumb "
                             "diagnose' (without --estimate-rw) or give the walk "
                             "(--accel-rw/--gyro-rw)"))
      << line;
  EXPECT_FALSE(Contains(run.out, "consistent with the noise")) << run.out;
  // Without the estimate (the default, the typical walk) the misfit shows in chi2, and the
  // output says not to trust the sigmas: beside the table and in the JSON.
  const std::string json_path = dir.File("plain.json");
  const ToolRun plain = Plumb({"calibrate", csv, "--lat", "51.64", "--lon", "-1.2", "--height",
                               "100", "--json", json_path},
                              dir);
  EXPECT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_TRUE(Contains(plain.out, "residuals exceed the noise")) << plain.out;
  EXPECT_TRUE(Contains(plain.out, "the misfit is a missing effect or bad segments, not noise, and "
                                  "even the scaled sigma assumes it is random: do not trust these "
                                  "parameters to their sigma"))
      << plain.out;
  EXPECT_TRUE(ReadJson(json_path)["fit"]["misfit_beyond_noise"].get<bool>());
}

TEST(GatesCli, ASaturatedAxisIsNamed) {
  TempDir dir;
  const std::string csv = Simulate(dir);
  // Six samples of the first turn clipped at 250 deg/s, a gyroscope's full scale.
  const std::string clipped = EditRows(dir, csv, "clipped.csv", [](std::size_t row, auto& f) {
    if (row >= 470 && row < 476) f[4] = "4.363323";
  });
  const ToolRun run = Calibrate(clipped, {}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(LineStarting(run.out, "gate failed: saturated"),
            "gate failed: saturated: " + clipped +
                ": gyro x sits at 4.363323 rad/s for 6 samples in a row from t = 4.7 s (1 such "
                "run, 6 samples): the sensor's full scale (4 or more equal samples at the axis's "
                "extreme, outside the still segments): the turns or shocks there are clipped, so "
                "the motion through them is wrong; turn more slowly, or set a larger range on "
                "the sensor")
      << run.out;
  EXPECT_EQ(Calibrate(clipped, {"--strict"}, dir).exit_code, 3);
}

TEST(GatesCli, ARealSaturatedGyroscopeIsNamed) {
  const std::string csv =
      std::string(PLUMB_SHARED_DATA_DIR) + "/multipose/tomisuarez2/example_data_calibration.csv";
  if (!std::filesystem::exists(csv)) GTEST_SKIP() << "shared data absent: " << csv;
  TempDir dir;
  const ToolRun run = Plumb({"calibrate", csv, "--skip-lines", "4", "--header", "--columns",
                             "ax,ay,az,gx,gy,gz", "--rate", "100", "--acc-unit", "g",
                             "--acc-scale", "1/16384", "--gyr-unit", "deg/s", "--gyr-scale",
                             "1/131", "--init-still", "36.5"},
                            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // An MPU-6050 at +-250 deg/s: -32768 counts / 131 = -250.1 deg/s.
  EXPECT_TRUE(Contains(run.out, "gate failed: saturated: " + csv +
                                    ": gyro x sits at -4.365721 rad/s for 10 samples in a row"))
      << run.out;
}

TEST(CovarianceCli, JsonCarriesTheCovarianceWithItsParameterOrder) {
  TempDir dir;
  const std::string csv = Simulate(dir);
  const std::string out = dir.File("cal.json");
  ASSERT_EQ(Calibrate(csv, {"--json", out}, dir).exit_code, 0);
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["schema_version"], 2);
  EXPECT_TRUE(doc["gates"].empty());
  const json& cov = doc["covariance"];
  EXPECT_EQ(cov["sigma_scaled_by_chi2"], false);
  ASSERT_EQ(cov["parameters"].size(), doc["parameters"].size());  // every one free, observable
  ASSERT_EQ(cov["matrix"].size(), cov["parameters"].size());
  for (std::size_t i = 0; i < cov["parameters"].size(); ++i) {
    const json& p = doc["parameters"][i];
    EXPECT_EQ(cov["parameters"][i], p["name"]);
    EXPECT_EQ(cov["units"][i], p["unit"]);
    EXPECT_EQ(p["sigma"], p["sigma_formal"]);
    const double variance = cov["matrix"][i][i];
    EXPECT_NEAR(std::sqrt(variance), p["sigma"].get<double>(), 1e-9 * p["sigma"].get<double>());
    for (std::size_t j = 0; j < i; ++j) EXPECT_EQ(cov["matrix"][i][j], cov["matrix"][j][i]);
  }
  EXPECT_TRUE(cov["determined"]["combinations"].empty());
}

TEST(CovarianceCli, ASingularFitGivesTheDeterminedCombinationsCovariance) {
  TempDir dir;
  const std::string csv = dir.File("static.csv"), out = dir.File("static.json");
  ASSERT_EQ(Plumb({"simulate", "--out", csv, "--schedule", "paper-static", "--rate", "100",
                   "--lat", "6.67", "--lon", "-1.57", "--seed", "5"},
                  dir)
                .exit_code,
            0);
  const ToolRun run = Plumb(
      {"calibrate", csv, "--lat", "6.67", "--lon", "-1.57", "--level-north", "--json", out}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json doc = ReadJson(out);
  const json& determined = doc["observability"]["determined"];
  const json& cov = doc["covariance"]["determined"];
  ASSERT_GE(determined.size(), 3u);
  ASSERT_EQ(cov["combinations"].size(), determined.size());
  for (std::size_t i = 0; i < determined.size(); ++i) {
    EXPECT_EQ(cov["combinations"][i], determined[i]["combination"]);
    const double sigma = determined[i]["sigma"];
    EXPECT_NEAR(std::sqrt(cov["matrix"][i][i].get<double>()), sigma, 1e-6 * sigma);
  }
  // Only the observable parameters are in the parameter covariance.
  std::size_t observable = 0;
  for (const auto& p : doc["parameters"]) observable += (p["observable"] && !p["fixed"]) ? 1 : 0;
  EXPECT_EQ(doc["covariance"]["parameters"].size(), observable);
}

TEST(CovarianceCli, AnOverDispersedFitScalesTheSigmaAndSaysSo) {
  TempDir dir;
  // Simulated with a g-sensitivity that the base model lacks: chi2/dof far above its band.
  const std::string csv =
      Simulate(dir, {"--model", "base+gyro_g_sensitivity", "--truth", "gyro_g_sensitivity.G.xy=2e-4",
                     "--truth", "gyro_g_sensitivity.G.zz=3e-4"});
  const std::string out = dir.File("cal.json");
  const ToolRun run = Calibrate(csv, {"--json", out}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "is above its band (up to 1.61): the residuals exceed the noise "
                                "the fit was whitened with, so the formal sigma (from that "
                                "noise) is too small; 'scaled' is sigma * sqrt(chi2/dof)"))
      << run.out;
  EXPECT_TRUE(Contains(run.out, "The JSON's sigma and covariance are the scaled ones "
                                "(sigma_formal beside); the exported files carry values only"));
  EXPECT_TRUE(Contains(run.out, "parameter                                    value        "
                                "sigma       scaled  unit"))
      << run.out;
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["fit"]["chi2_above_band"], true);
  const json& cov = doc["covariance"];
  EXPECT_EQ(cov["sigma_scaled_by_chi2"], true);
  const double scale = cov["sigma_scale"];
  EXPECT_NEAR(scale * scale, doc["fit"]["chi2_dof"].get<double>(), 1e-9 * scale * scale);
  for (std::size_t i = 0; i < doc["parameters"].size(); ++i) {
    const json& p = doc["parameters"][i];
    const double sigma = p["sigma"], formal = p["sigma_formal"];
    EXPECT_NEAR(sigma, scale * formal, 1e-12 * sigma) << p["name"];
    EXPECT_NEAR(std::sqrt(cov["matrix"][i][i].get<double>()), sigma, 1e-9 * sigma) << p["name"];
  }
}

TEST(CovarianceCli, PaperMethodsCarryTheSchemaVersionAndTheBackendsCovariance) {
  TempDir dir;
  const std::string csv = dir.File("static.csv"), out = dir.File("paper.json");
  ASSERT_EQ(Plumb({"simulate", "--out", csv, "--schedule", "paper-static", "--rate", "100",
                   "--lat", "6.67", "--lon", "-1.57", "--seed", "5"},
                  dir)
                .exit_code,
            0);
  const ToolRun run = Plumb({"calibrate", csv, "--method", "paper-static", "--lat", "6.67",
                             "--lon", "-1.57", "--json", out},
                            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["schema_version"], 2);
  EXPECT_EQ(doc["covariance"]["source"], "backend");
  const json& backend = doc["paper-static"]["backend"];
  EXPECT_EQ(doc["covariance"]["parameters"], backend["covariance"]["parameters"]);
  EXPECT_EQ(doc["covariance"]["determined"], backend["covariance"]["determined"]);
  EXPECT_EQ(doc["gates"], backend["gates"]);
  EXPECT_TRUE(doc["gates"].is_array());
}

}  // namespace
}  // namespace plumb::cli

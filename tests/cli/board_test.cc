// The board's IMUs fitted together from the command line (issue 38, SPEC 6 --imus): a
// simulated three-IMU board's native CSV and a real ArduPilot log with IMU and IMU2, as a
// user meets them; and the inputs that cannot carry a board refused with the reason.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using nlohmann::json;
using testing::Contains;
using testing::Plumb;
using testing::ReadCsv;
using testing::ReadJson;
using testing::TempDir;
using testing::ToolRun;

/// `plumb simulate` of a three-IMU board (16 poses, white noise, a site) into `dir`: the CSV
/// and its truth.
std::pair<std::string, std::string> SimulateBoard(const TempDir& dir) {
  const std::string csv = dir.File("board.csv"), truth = dir.File("truth.json");
  const ToolRun run = Plumb({"simulate", "--out", csv, "--imus", "3", "--random-truth", "1",
                             "--poses", "16", "--rate", "100", "--seed", "5", "--accel-rw", "0",
                             "--gyro-rw", "0", "--accel-bi", "0", "--gyro-bi", "0",
                             "--truth-json", truth, "--lat", "51.64", "--lon", "-1.2",
                             "--height", "100"},
                            dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  return {csv, truth};
}

TEST(BoardCli, ASimulatedBoardsImusAreCalibratedTogether) {
  TempDir dir;
  const auto [csv, truth_path] = SimulateBoard(dir);
  const std::string out = dir.File("cal.json");
  const ToolRun run = Plumb({"calibrate", csv, "--imus", "all", "--constant-bias", "--json", out,
                             "--lat", "51.64", "--lon", "-1.2", "--height", "100"},
                            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "imu2, fitted with IMU 0")) << run.out;
  const json doc = ReadJson(out);
  const json truth = ReadJson(truth_path);
  ASSERT_EQ(doc["imus"].size(), 3u);
  ASSERT_EQ(truth["imus"].size(), 3u);
  for (std::size_t k = 1; k < 3; ++k) {
    const json& imu = doc["imus"][k];
    EXPECT_EQ(imu["instance"], static_cast<int>(k));
    // Each rotation within 4 sigma of the truth, about every axis.
    for (std::size_t a = 0; a < 3; ++a) {
      const double value = imu["rotation"]["vector"][a];
      const double sigma = imu["rotation"]["sigma"][a];
      const double true_value = truth["imus"][k]["rotation"]["vector"][a];
      EXPECT_LT(std::abs(value - true_value), 4.0 * sigma) << "imu" << k << " axis " << a;
    }
    // Its turns against IMU 0's: chi2 near one per value on a board the model fits (a few
    // unknowns absorb a little; the spread of chi2/n is sqrt(2/n), 0.04 at 1400 values).
    const json& turns = imu["turn_comparison"];
    ASSERT_GT(turns["residuals"].get<int>(), 1000) << turns.dump();
    const double per_value = turns["chi2"].get<double>() / turns["residuals"].get<double>();
    EXPECT_GT(per_value, 0.8) << turns.dump();
    EXPECT_LT(per_value, 1.2) << turns.dump();
    EXPECT_TRUE(Contains(run.out, "(their comparison with IMU 0's: chi2 ")) << run.out;
  }
  EXPECT_FALSE(doc["imus"][0].contains("turn_comparison"));
  const std::size_t n = doc["imus_covariance"]["parameters"].size();
  EXPECT_EQ(doc["imus_covariance"]["matrix"].size(), n);
  EXPECT_EQ(doc["imus_covariance"]["parameters"][n - 1], "imu2.time_offset");

  // --imus 0,2: IMU 2 alone beside IMU 0.
  const std::string two = dir.File("two.json");
  const ToolRun pair = Plumb({"calibrate", csv, "--imus", "0,2", "--constant-bias", "--json",
                              two, "--lat", "51.64", "--lon", "-1.2", "--height", "100"},
                             dir);
  ASSERT_EQ(pair.exit_code, 0) << pair.err;
  const json doc2 = ReadJson(two);
  ASSERT_EQ(doc2["imus"].size(), 2u);
  EXPECT_EQ(doc2["imus"][1]["instance"], 2);
  // Without --imus the file's other IMUs are not fitted: IMU 0 alone, as before.
  const std::string alone = dir.File("alone.json");
  ASSERT_EQ(Plumb({"calibrate", csv, "--constant-bias", "--json", alone}, dir).exit_code, 0);
  EXPECT_FALSE(ReadJson(alone).contains("imus"));
}

TEST(BoardCli, WhatCannotCarryABoardIsRefusedWithTheReason) {
  TempDir dir;
  const auto [csv, truth] = SimulateBoard(dir);
  // A native CSV's IMU 0 is its acc_x.. columns; IMU 7 is not in the file.
  ToolRun run = Plumb({"calibrate", csv, "--imus", "1,0"}, dir);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_TRUE(Contains(run.err, "list it first")) << run.err;
  run = Plumb({"calibrate", csv, "--imus", "0,7"}, dir);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_TRUE(Contains(run.err, "no IMU 7")) << run.err;
  // Not a list of instances.
  run = Plumb({"calibrate", csv, "--imus", "0,x"}, dir);
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_TRUE(Contains(run.err, "--imus 0,x")) << run.err;
  // Two inputs: the board comes from one.
  run = Plumb({"calibrate", csv, csv, "--imus", "all"}, dir);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_TRUE(Contains(run.err, "come from one input")) << run.err;
  // Commands that do not fit the board do not take the flag.
  run = Plumb({"allan", csv, "--imus", "all"}, dir);
  EXPECT_EQ(run.exit_code, 2) << run.err;
}

// apply --imus (SPEC 6): every IMU through its own calibration, into the body frame; at rest
// the IMUs then agree where their raw samples did not; one file for them all where they share
// the stamps, or one per IMU; what does not match is refused with the reason.
TEST(BoardCli, ApplyCorrectsEveryImuIntoTheBodyFrame) {
  TempDir dir;
  const auto [csv, truth_path] = SimulateBoard(dir);
  const std::string cal = dir.File("cal.json"), one = dir.File("one.csv");
  ASSERT_EQ(Plumb({"calibrate", csv, "--imus", "all", "--constant-bias", "--json", cal, "--lat",
                   "51.64", "--lon", "-1.2", "--height", "100"},
                  dir)
                .exit_code,
            0);
  const ToolRun run = Plumb({"apply", cal, csv, "--imus", "all", "--out", one, "--sigma"}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "to 3 IMUs, each in the body frame")) << run.out;
  const auto raw = ReadCsv(csv), corrected = ReadCsv(one);
  // The first pose is still: the mean of each IMU against IMU 0's over its first second.
  const auto gap = [](const std::map<std::string, std::vector<double>>& c, const std::string& k) {
    double largest = 0.0;
    for (const char* axis : {"x", "y", "z"}) {
      const std::vector<double>& a0 = c.at(std::string("acc_") + axis);
      const std::vector<double>& ak = c.at("acc" + k + "_" + axis);
      double sum = 0.0;
      for (std::size_t i = 0; i < 100; ++i) sum += ak[i] - a0[i];
      largest = std::max(largest, std::abs(sum / 100.0));
    }
    return largest;
  };
  for (const std::string k : {"1", "2"}) {
    EXPECT_GT(gap(raw, k), 0.05) << "imu" << k << " raw";           // turned 0.5-2 deg, own bias
    EXPECT_LT(gap(corrected, k), 0.01) << "imu" << k << " corrected";  // noise / 10 and sigma
    EXPECT_GT(corrected.at("acc" + k + "_y_sigma")[0], 0.0);
  }
  // One file per IMU: IMU k's file holds the one file's acc{k}_ columns in the usual ones.
  const std::vector<std::string> files = {dir.File("i0.csv"), dir.File("i1.csv"), dir.File("i2.csv")};
  ASSERT_EQ(Plumb({"apply", cal, csv, "--imus", "all", "--out", files[0], "--out", files[1],
                   "--out", files[2]},
                  dir)
                .exit_code,
            0);
  EXPECT_EQ(ReadCsv(files[2]).at("acc_z"), corrected.at("acc2_z"));
  EXPECT_EQ(ReadCsv(files[0]).at("gyr_x"), corrected.at("gyr_x"));
  // Two files for three IMUs; an IMU the calibration did not fit.
  ToolRun refused = Plumb({"apply", cal, csv, "--imus", "all", "--out", files[0], "--out",
                           files[1]},
                          dir);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_TRUE(Contains(refused.err, "2 --out given for 3 IMUs: give one per IMU, IMU 0 first, or "
                                    "one for them all (they share their stamps)"))
      << refused.err;
  const std::string pair = dir.File("pair.json");
  ASSERT_EQ(Plumb({"calibrate", csv, "--imus", "0,2", "--constant-bias", "--json", pair}, dir)
                .exit_code,
            0);
  refused = Plumb({"apply", pair, csv, "--imus", "0,1", "--out", dir.File("x.csv")}, dir);
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_TRUE(Contains(refused.err, "pair.json:key 'imus': no calibration of IMU 1 (it "
                                    "calibrates IMU 0, 2)"))
      << refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir.File("x.csv")));
}

/// The value of `name` in a Mission Planner .param text, NaN when absent; ADD_FAILURE when it
/// is written twice.
double ParamValue(const std::string& text, const std::string& name) {
  double value = std::nan("");
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(name + ",", 0) != 0) continue;
    if (!std::isnan(value)) ADD_FAILURE() << name << " written twice";
    value = std::stod(line.substr(name.size() + 1));
  }
  return value;
}

/// The true value of parameter `name` of IMU `k` in a `plumb simulate` truth file.
double TrueValue(const json& truth, std::size_t k, const std::string& name) {
  const json& parameters = k == 0 ? truth["parameters"] : truth["imus"][k]["parameters"];
  const std::string full = k == 0 ? name : "imu" + std::to_string(k) + "." + name;
  for (const json& p : parameters) {
    if (p["name"] == full) return p["value"];
  }
  ADD_FAILURE() << full << " not in the truth";
  return std::nan("");
}

// Exports of a board: every instance under the firmware's own names, in one file per format.
TEST(BoardCli, ExportsWriteEveryInstanceUnderItsOwnNames) {
  TempDir dir;
  const auto [csv, truth_path] = SimulateBoard(dir);
  const std::string out = dir.File("cal.json"), ardupilot = dir.File("imu.param"),
                    px4 = dir.File("imu.params"), kalibr = dir.File("imu.yaml");
  const ToolRun run = Plumb({"calibrate", csv, "--imus", "all", "--constant-bias", "--json", out,
                             "--lat", "51.64", "--lon", "-1.2", "--height", "100", "--export",
                             "ardupilot=" + ardupilot, "--export", "px4=" + px4, "--export",
                             "kalibr=" + kalibr},
                            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json truth = ReadJson(truth_path);
  const std::string param = testing::ReadAll(ardupilot), params = testing::ReadAll(px4);
  const char* ardupilot_stem[] = {"INS_ACC", "INS_ACC2", "INS_ACC3"};
  for (std::size_t k = 0; k < 3; ++k) {
    // ArduPilot's offsets are the accelerometer's biases (acc = (raw - OFFS) .* SCAL), each
    // IMU's under its instance's name, within a misalignment's reach of its truth (a few
    // mrad of g: the diagonal correction cannot hold the rest).
    const double offset = ParamValue(param, std::string(ardupilot_stem[k]) + "OFFS_X");
    EXPECT_NEAR(offset, TrueValue(truth, k, "accel.bias.x"), 0.05) << "IMU " << k;
    const std::string gyro = k == 0 ? "INS_GYROFFS_Z" : "INS_GYR" + std::to_string(k + 1) + "OFFS_Z";
    EXPECT_FALSE(std::isnan(ParamValue(param, gyro))) << gyro;
    EXPECT_TRUE(Contains(params, "\tCAL_ACC" + std::to_string(k) + "_XOFF\t")) << params;
    EXPECT_TRUE(Contains(params, "\tCAL_GYRO" + std::to_string(k) + "_ZOFF\t")) << params;
  }
  // Kalibr's IMU set: imu0..imu2, each T_i_b's rotation the transpose of its R_b_i.
  const std::string yaml = testing::ReadAll(kalibr);
  const json doc = ReadJson(out);
  for (std::size_t k = 0; k < 3; ++k) {
    const std::string key = "\nimu" + std::to_string(k) + ":\n  T_i_b:\n    - [";
    const auto at = yaml.find(key);
    ASSERT_NE(at, std::string::npos) << yaml;
    const double c01 = std::stod(yaml.substr(yaml.find(", ", at) + 2));
    const double r10 = doc["imus"][k]["rotation"]["matrix"][1][0];
    EXPECT_NEAR(c01, r10, 1e-15) << "imu" << k;
  }
}

/// `calibrate LOG --imus all --json` in the temporary folder `dir`: the run and its JSON
/// (null when it wrote none).
struct RealBoardRun {
  ToolRun run;
  json doc;
};
RealBoardRun CalibrateRealBoard(const std::string& log, const TempDir& dir) {
  const std::string out = dir.File("cal.json");
  RealBoardRun r{Plumb({"calibrate", log, "--imus", "all", "--json", out}, dir), json()};
  if (std::filesystem::exists(out)) r.doc = ReadJson(out);
  return r;
}

#define PLUMB_SHARED_LOG(var, relative)                                              \
  const std::string var = std::string(PLUMB_SHARED_DATA_DIR) + "/" + (relative);     \
  if (!std::filesystem::exists(var)) GTEST_SKIP() << "shared data absent: " << var

TEST(BoardCli, ARealLogsTwoImusStillInOnePose) {
  PLUMB_SHARED_LOG(log, "ardupilot/plane408_centre_point.BIN");
  TempDir dir;
  const auto [run, doc] = CalibrateRealBoard(log, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(doc["imus"].size(), 2u);
  EXPECT_EQ(doc["imus"][1]["instance"], 1);
  // One pose: gravity cannot show IMU2's turn about itself; the output says so.
  bool yaw_named = false;
  for (const auto& u : doc["observability"]["unobservable"]) {
    yaw_named = yaw_named || u.get<std::string>().find("imu1.rotation.z") != std::string::npos;
  }
  EXPECT_TRUE(yaw_named) << doc["observability"].dump();
  // The text says what the one pose determines of the mount and what it cannot show.
  EXPECT_NE(run.out.find("rotation into the body not determined by these data"), std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("imu1.rotation.z: not seen at all"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("\n  imu1.rotation.x + "), std::string::npos) << run.out;
}

// The other real logs with several IMUs (issue 38's list): each says what its data can tell.
TEST(BoardCli, ThreeMavlinkStreamsOfOneBoardConverge) {
  PLUMB_SHARED_LOG(log, "mavlink/plane385_disarmed.tlog");
  TempDir dir;
  const auto [run, doc] = CalibrateRealBoard(log, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(doc["imus"].size(), 3u);  // RAW_IMU, SCALED_IMU2, SCALED_IMU3
  // Each mount starts square (the poses share one orientation), and the fit converges there.
  EXPECT_TRUE(doc["gates"].empty()) << doc["gates"].dump();
  EXPECT_NE(run.out.find("imu2, fitted with IMU 0"), std::string::npos) << run.out;
}

TEST(BoardCli, AFlightsThreeImusAreNotTakenForStill) {
  PLUMB_SHARED_LOG(log, "px4/sample_log_small.ulg");
  TempDir dir;
  const auto [run, doc] = CalibrateRealBoard(log, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(doc["imus"].size(), 3u);  // sensor_combined, vehicle_imu 1 and 2
  bool not_still = false;
  for (const auto& g : doc["gates"]) not_still = not_still || g["name"] == "not_still";
  EXPECT_TRUE(not_still) << doc["gates"].dump();
}

// PX4 finds a sensor's calibration slot by its device id (CAL_ACCn_ID), not its instance: the
// reader carries each instance's device ids (vehicle_imu accel_device_id, gyro_device_id), and
// the export writes each IMU's values in the slot the log's parameters give that id.
TEST(BoardCli, Px4ExportsFindEachImusSlotByItsDeviceId) {
  PLUMB_SHARED_LOG(log, "px4/sample_log_small.ulg");
  TempDir dir;
  const std::string params = dir.File("board.params");
  const ToolRun run = Plumb({"calibrate", log, "--imus", "all", "--export", "px4=" + params,
                             "--export-anyway", "--export-undetermined"},
                            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string text = testing::ReadAll(params);
  // The log's slots: 0 device 2424842, 1 device 3670050, 2 device 2621474 (accel and gyro).
  const std::pair<int, const char*> slots[] = {{0, "2424842"}, {1, "3670050"}, {2, "2621474"}};
  for (const auto& [n, id] : slots) {
    const std::string k = std::to_string(n);
    EXPECT_TRUE(Contains(text, "\tCAL_ACC" + k + "_ID\t" + id + "\t6\n")) << text;
    EXPECT_TRUE(Contains(text, "\tCAL_GYRO" + k + "_ID\t" + id + "\t6\n")) << text;
    EXPECT_TRUE(Contains(text, "CAL_ACC" + k + "_ID " + id + ": the sensor's device id, which the "
                               "log's CAL_ACC" + k + "_ID holds")) << text;
  }
}

TEST(BoardCli, ALogWithoutAStillHoldSaysSo) {
  PLUMB_SHARED_LOG(log, "ardupilot/copter36_chibios.bin");
  TempDir dir;
  const auto [run, doc] = CalibrateRealBoard(log, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("no still segment"), std::string::npos) << run.err;
}

// apply --imus on the real boards: ArduPilot's IMU and IMU2 share their stamps (one file or
// two); PX4's three instances each have their own (one file each). A board whose data
// determine only combinations of a mount has no sigma to propagate, and apply says so.
TEST(BoardCli, ApplyOnTheRealBoards) {
  PLUMB_SHARED_LOG(plane, "ardupilot/plane408_centre_point.BIN");
  PLUMB_SHARED_LOG(px4, "px4/sample_log_small.ulg");
  TempDir dir;
  const auto [run, doc] = CalibrateRealBoard(plane, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string cal = dir.File("cal.json");
  const std::string a = dir.File("a.csv"), b = dir.File("b.csv"), ab = dir.File("ab.csv");
  ToolRun applied = Plumb({"apply", cal, plane, "--imus", "all", "--out", a, "--out", b}, dir);
  ASSERT_EQ(applied.exit_code, 0) << applied.err;
  EXPECT_EQ(ReadCsv(b).at("acc_x").size(), 2216u);
  applied = Plumb({"apply", cal, plane, "--imus", "all", "--out", ab}, dir);
  ASSERT_EQ(applied.exit_code, 0) << applied.err;
  EXPECT_EQ(ReadCsv(ab).at("acc1_z"), ReadCsv(b).at("acc_z"));
  applied = Plumb({"apply", cal, plane, "--imus", "all", "--out", ab, "--sigma"}, dir);
  EXPECT_EQ(applied.exit_code, 1);
  EXPECT_TRUE(Contains(applied.err, "has no covariance over its parameters to propagate"))
      << applied.err;

  TempDir px4_dir;
  const auto [px4_run, px4_doc] = CalibrateRealBoard(px4, px4_dir);
  ASSERT_EQ(px4_run.exit_code, 0) << px4_run.err;
  const std::string px4_cal = px4_dir.File("cal.json");
  applied = Plumb({"apply", px4_cal, px4, "--imus", "all", "--out", px4_dir.File("u.csv")}, px4_dir);
  EXPECT_EQ(applied.exit_code, 2);
  EXPECT_TRUE(Contains(applied.err, "they have stamps of their own")) << applied.err;
  applied = Plumb({"apply", px4_cal, px4, "--imus", "all", "--out", px4_dir.File("u0.csv"),
                   "--out", px4_dir.File("u1.csv"), "--out", px4_dir.File("u2.csv")},
                  px4_dir);
  ASSERT_EQ(applied.exit_code, 0) << applied.err;
  EXPECT_TRUE(Contains(applied.out, "u2.csv (IMU 2)")) << applied.out;
  EXPECT_FALSE(ReadCsv(px4_dir.File("u2.csv")).at("gyr_z").empty());

  // Three MAVLink streams held still in two poses: no turn determines a gyroscope's matrix.
  // apply says so, whether the value the fit left is a matrix it takes (a warning) or one no
  // sensor has (the error, naming the IMU's entry).
  PLUMB_SHARED_LOG(tlog, "mavlink/plane385_disarmed.tlog");
  TempDir tlog_dir;
  const auto [tlog_run, tlog_doc] = CalibrateRealBoard(tlog, tlog_dir);
  ASSERT_EQ(tlog_run.exit_code, 0) << tlog_run.err;
  applied = Plumb({"apply", tlog_dir.File("cal.json"), tlog, "--imus", "all", "--out",
                   tlog_dir.File("t0.csv"), "--out", tlog_dir.File("t1.csv"), "--out",
                   tlog_dir.File("t2.csv")},
                  tlog_dir);
  EXPECT_TRUE(applied.exit_code == 0 || applied.exit_code == 1) << applied.err;
  EXPECT_TRUE(Contains(applied.err, "did not determine")) << applied.err;
  EXPECT_TRUE(Contains(applied.err, "gyro.matrix")) << applied.err;
}

// diagnose --imus (issue 38, item 4): the IMU whose misfit is its own is named, with the
// effect it misses; the board refitted with that IMU's own model loses the misfit.
TEST(BoardCli, DiagnoseNamesTheImuWhoseMisfitIsItsOwnAndItsAdviceLowersTheBoardsMisfit) {
  TempDir dir;
  const std::string csv = dir.File("board.csv"), truth_path = dir.File("truth.json");
  ASSERT_EQ(Plumb({"simulate", "--out", csv, "--imus", "3", "--model", "base+gyro_g_sensitivity",
                   "--truth", "imu2.gyro_g_sensitivity.G.xy=1e-3", "--truth",
                   "imu2.gyro_g_sensitivity.G.zx=-7e-4", "--poses", "16", "--rate", "100",
                   "--seed", "7", "--accel-rw", "0", "--gyro-rw", "0", "--accel-bi", "0",
                   "--gyro-bi", "0", "--truth-json", truth_path},
                  dir)
                .exit_code,
            0);
  const std::string diagnosis = dir.File("diagnosis.json");
  const ToolRun run = Plumb({"diagnose", csv, "--imus", "all", "--candidates",
                             "gyro_g_sensitivity,accel_scale_nonlinearity", "--json", diagnosis},
                            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "IMU 1 (acc1_x.., instance 1) alone: chi2/dof")) << run.out;
  EXPECT_TRUE(Contains(run.out, "): within its noise\n  IMU 2 (acc2_x.., instance 2) alone:"))
      << run.out;
  EXPECT_TRUE(Contains(run.out, "a misfit of its own")) << run.out;
  EXPECT_TRUE(Contains(run.out, "together (IMUs 0, 1, the attitudes shared")) << run.out;
  EXPECT_TRUE(Contains(run.out, "--imu-model 2=base+gyro_g_sensitivity: chi2/dof")) << run.out;
  const json doc = ReadJson(diagnosis);
  ASSERT_EQ(doc["imus"].size(), 3u);
  EXPECT_FALSE(doc["imus"][0]["own_misfit"].get<bool>());
  EXPECT_FALSE(doc["imus"][1]["own_misfit"].get<bool>());
  EXPECT_TRUE(doc["imus"][2]["own_misfit"].get<bool>());
  EXPECT_EQ(doc["imus"][2]["recommendation"], "base+gyro_g_sensitivity");
  EXPECT_EQ(doc["board"]["rigid"]["imus"], json::array({0, 1}));
  EXPECT_TRUE(doc["board"]["rigid"]["holds"].get<bool>());
  ASSERT_TRUE(doc["board"]["next"]["advised"].get<bool>()) << doc["board"]["next"].dump();
  EXPECT_EQ(doc["board"]["next"]["flags"],
            json::array({"--imu-model", "2=base+gyro_g_sensitivity"}));

  // The advice followed: the board's chi2/dof within its band, G found within 4 sigma.
  const std::string cal = dir.File("cal.json");
  const ToolRun fit = Plumb({"calibrate", csv, "--imus", "all", "--constant-bias", "--imu-model",
                             "2=base+gyro_g_sensitivity", "--json", cal},
                            dir);
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  const json c = ReadJson(cal);
  EXPECT_LT(c["fit"]["chi2_dof"].get<double>(), 1.5) << c["fit"].dump();
  EXPECT_EQ(c["imus"][2]["model"], "base+gyro_g_sensitivity");
  EXPECT_EQ(c["imus"][1]["model"], "base");
  // G (row-major, xx..zz) of IMU 2 only: xy (1) and zx (6) as planted, within 4 sigma.
  EXPECT_FALSE(c["effects"].contains("gyro_g_sensitivity"));
  const json& g = c["imus"][2]["effects"]["gyro_g_sensitivity"];
  for (const auto& [i, truth] : {std::pair{1, 1e-3}, std::pair{6, -7e-4}}) {
    const double value = g["parameters"][i], sigma = g["sigma"][i];
    EXPECT_LT(std::abs(value - truth), 4.0 * sigma) << "G[" << i << "] " << value << " +- " << sigma;
  }

  // report --imus: the page shows the same diagnosis of each IMU and the board, and its next
  // command is the board's refit with IMU 2's advice; diagnose.json is diagnose --imus's.
  const ToolRun page = Plumb({"report", csv, "--imus", "all", "--constant-bias", "--no-figures",
                              "--out", dir.File("report")},
                             dir);
  ASSERT_EQ(page.exit_code, 0) << page.err;
  const std::string html = testing::ReadAll(dir.File("report") + "/index.html");
  EXPECT_TRUE(Contains(html, "IMU 2 (acc2_x.., instance 2) alone: chi2/dof")) << html;
  EXPECT_TRUE(Contains(html, "a misfit of its own")) << html;
  EXPECT_TRUE(Contains(html, "--imus all --constant-bias --imu-model 2=base+gyro_g_sensitivity</pre>"))
      << "the page lacks the board's next command";
  const json page_doc = ReadJson(dir.File("report") + "/diagnose.json");
  ASSERT_EQ(page_doc["imus"].size(), 3u);
  EXPECT_TRUE(page_doc["imus"][2]["own_misfit"].get<bool>());
}

// The IMUs against ArduPilot's pre-arm check (estimation/board_agreement.h), on the real boards:
// what the firmware compares before and after, and, where the poses cannot determine the
// accelerometers, that "after" matches them by construction. The report page shows it too.
TEST(BoardCli, TheRealBoardsAgainstArduPilotsPreArmCheck) {
  PLUMB_SHARED_LOG(plane385, "mavlink/plane385_disarmed.tlog");
  PLUMB_SHARED_LOG(plane408, "ardupilot/plane408_centre_point.BIN");
  TempDir dir;
  const auto [run, doc] = CalibrateRealBoard(plane385, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "imu1 (2 poses): accel 1.51 -> 0 m/s^2")) << run.out;
  EXPECT_TRUE(Contains(run.out, "outside ArduPilot's check before, within it after, at the poses "
                                "recorded, which do not determine")) << run.out;
  ASSERT_EQ(doc["board_agreement"].size(), 2u);
  const json& imu1 = doc["board_agreement"][0];
  EXPECT_FALSE(imu1["within_before"].get<bool>());
  EXPECT_TRUE(imu1["within_after"].get<bool>());
  EXPECT_TRUE(imu1["matched_by_construction"].get<bool>());
  EXPECT_GT(imu1["accel"]["before"].get<double>(), imu1["accel"]["limit"].get<double>());
  EXPECT_DOUBLE_EQ(doc["board_agreement"][1]["accel"]["limit"].get<double>(), 2.25);  // IMU3

  TempDir other;
  const auto [one, doc408] = CalibrateRealBoard(plane408, other);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_TRUE(Contains(one.out, "imu1 (1 pose): accel 0.5 -> 0 m/s^2")) << one.out;

  const ToolRun page = Plumb({"report", plane385, "--imus", "all", "--no-figures", "--out",
                              dir.File("report")},
                             dir);
  ASSERT_EQ(page.exit_code, 0) << page.err;
  const std::string html = testing::ReadAll(dir.File("report") + "/index.html");
  EXPECT_TRUE(Contains(html, "<h2 id=\"board\">The board's IMUs</h2>"));
  EXPECT_TRUE(Contains(html, "<td>imu2</td><td><code>base</code></td><td>not determined by these data"));
  EXPECT_TRUE(Contains(html, "1.5 &rarr; ")) << html.substr(html.find("id=\"board\""), 1500);
  // Each IMU's diagnosis alone, and why the board cannot be judged across: IMU 0's own misfit.
  EXPECT_TRUE(Contains(html, "IMU 0 alone: chi2/dof")) << "the page lacks the board's diagnosis";
}

// diagnose --imus on the real logs with several IMUs: what each can and cannot judge.
TEST(BoardCli, DiagnoseOnTheRealBoardsSaysWhatTheirDataCanJudge) {
  struct Case {
    const char* log;
    std::vector<std::string> said;
  };
  const std::vector<Case> cases = {
      {"mavlink/plane385_disarmed.tlog",
       {"IMU 1 (SCALED_IMU2, instance 1) alone: chi2/dof",
        "IMU 2 (SCALED_IMU3, instance 2) alone: chi2/dof",
        "together: not tested: IMU 0's fit alone failed a gate (nonlinear)"}},
      {"ardupilot/plane408_centre_point.BIN",
       {"IMU 1 (IMU2, instance 1) alone: no degrees of freedom left",
        "together: not tested: sharing the attitudes adds no constraint these data can test"}},
      {"px4/sample_log_small.ulg", {"the fit failed a gate (not_still)"}},
  };
  for (const Case& c : cases) {
    const std::string log = std::string(PLUMB_SHARED_DATA_DIR) + "/" + c.log;
    if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
    TempDir dir;
    const ToolRun run = Plumb({"diagnose", log, "--imus", "all"}, dir);
    ASSERT_EQ(run.exit_code, 0) << c.log << ": " << run.err;
    for (const std::string& s : c.said) EXPECT_TRUE(Contains(run.out, s)) << c.log << ": " << run.out;
    // No IMU of these boards is blamed, and nothing is advised for the board.
    EXPECT_FALSE(Contains(run.out, "a misfit of its own")) << c.log << ": " << run.out;
    EXPECT_FALSE(Contains(run.out, "  next: ")) << c.log << ": " << run.out;
  }
}

}  // namespace
}  // namespace plumb::cli

// plumb allan as a user runs it: a simulated still session (its noise levels recovered), the
// still segments of a simulated multi-pose session (detected or given), tomisuarez2's 449 s
// still record, the JSON document, and the mistakes it refuses.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using nlohmann::json;
using testing::Contains;
using testing::Plumb;
using testing::ReadJson;
using testing::TempDir;
using testing::ToolRun;

/// The term `symbol` of an axis of the JSON document.
const json& Term(const json& doc, const char* sensor, const char* axis, const char* symbol) {
  return doc.at(sensor).at("axes").at(axis).at("terms").at(symbol);
}

TEST(Allan, SimulatedStillSessionGivesTheSimulatedLevels) {
  TempDir dir;
  const std::string csv = dir.File("still.csv"), out = dir.File("allan.json");
  // Fifteen minutes of one level pose at 100 Hz: white noise 1e-3 m/s^2/sqrt(Hz) and
  // 7e-5 rad/s/sqrt(Hz) (the defaults), bias random walks 3e-4 m/s^3/sqrt(Hz) and
  // 1e-5 rad/s^2/sqrt(Hz), which show from sqrt(3) N / K = 6 s and 12 s on.
  const ToolRun sim = Plumb({"simulate", "--out", csv, "--schedule", "paper-static", "--still",
                             "900", "--rate", "100", "--accel-rw", "3e-4", "--gyro-rw", "1e-5",
                             "--seed", "3"},
                            dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const ToolRun run = Plumb({"allan", csv, "--whole", "--json", out}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "still segments: the whole input (--whole)")) << run.out;
  EXPECT_TRUE(Contains(run.out, "velocity random walk")) << run.out;
  EXPECT_TRUE(Contains(run.out, "deg/sqrt(h)")) << run.out;
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["schema_version"], 1);
  EXPECT_EQ(doc["still"]["method"], "whole");
  EXPECT_EQ(doc["still"]["samples"], 90000);
  EXPECT_EQ(doc["accel"]["unit"], "m/s^2");
  EXPECT_EQ(doc["gyro"]["unit"], "rad/s");
  for (const char* axis : {"x", "y", "z"}) {
    const json& n_a = Term(doc, "accel", axis, "N");
    EXPECT_TRUE(n_a["resolved"].get<bool>()) << axis;
    EXPECT_NEAR(n_a["value"].get<double>() / 1e-3, 1.0, 0.05) << axis;
    EXPECT_EQ(n_a["unit"], "m/s^2/sqrt(Hz)");
    EXPECT_EQ(n_a["datasheet"]["unit"], "ug/sqrt(Hz)");
    const json& n_g = Term(doc, "gyro", axis, "N");
    EXPECT_TRUE(n_g["resolved"].get<bool>()) << axis;
    EXPECT_NEAR(n_g["value"].get<double>() / 7e-5, 1.0, 0.05) << axis;
    // 7e-5 rad/s/sqrt(Hz) = 0.24 deg/sqrt(h).
    EXPECT_NEAR(n_g["datasheet"]["value"].get<double>(), 7e-5 * 180 / M_PI * 60, 0.02) << axis;
    // The random walks: resolved, within the spread of a quarter of an hour.
    const json& k_a = Term(doc, "accel", axis, "K");
    EXPECT_TRUE(k_a["resolved"].get<bool>()) << axis;
    EXPECT_NEAR(k_a["value"].get<double>() / 3e-4, 1.0, 0.4) << axis;
    EXPECT_LT(k_a["tau_min_s"].get<double>(), k_a["tau_max_s"].get<double>());
    EXPECT_EQ(k_a["unit"], "m/s^3/sqrt(Hz)");
    // No flicker and no quantisation were simulated: bounds only.
    EXPECT_FALSE(Term(doc, "accel", axis, "B")["resolved"].get<bool>()) << axis;
    EXPECT_FALSE(Term(doc, "gyro", axis, "Q")["resolved"].get<bool>()) << axis;
    EXPECT_FALSE(Term(doc, "gyro", axis, "R")["in_model"].get<bool>()) << axis;
  }
  // Every point has its interval around it.
  for (const json& p : doc["gyro"]["axes"]["z"]["adev"]) {
    EXPECT_LE(p["lower"].get<double>(), p["adev"].get<double>());
    EXPECT_GE(p["upper"].get<double>(), p["adev"].get<double>());
    EXPECT_GE(p["edf"].get<double>(), 1.0);
  }
  EXPECT_NEAR(doc["confidence"].get<double>(), 0.6827, 1e-4);
}

TEST(Allan, PoolsTheStillSegmentsOfAMultiPoseSession) {
  TempDir dir;
  const std::string csv = dir.File("poses.csv"), segments = dir.File("segments.csv");
  const ToolRun sim = Plumb({"simulate", "--out", csv, "--poses", "12", "--still", "30",
                             "--rate", "100", "--seed", "4", "--segments-out", segments},
                            dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  for (const bool given : {false, true}) {
    const std::string out = dir.File(given ? "given.json" : "detected.json");
    std::vector<std::string> args = {"allan", csv, "--json", out};
    if (given) args.insert(args.end(), {"--segments", segments});
    const ToolRun run = Plumb(args, dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_TRUE(Contains(run.out, "still data: 12 segments")) << run.out;
    const json doc = ReadJson(out);
    EXPECT_EQ(doc["still"]["method"], given ? "given" : "detected");
    EXPECT_EQ(doc["still"]["segments"].size(), 12u);
    // Clusters of up to half the longest segment (about 30 s): the white noise, no more.
    EXPECT_LT(doc["accel"]["axes"]["x"]["fit"]["tau_max_s"].get<double>(), 15.0);
    for (const char* axis : {"x", "y", "z"}) {
      EXPECT_NEAR(Term(doc, "accel", axis, "N")["value"].get<double>() / 1e-3, 1.0, 0.05) << axis;
      EXPECT_NEAR(Term(doc, "gyro", axis, "N")["value"].get<double>() / 7e-5, 1.0, 0.05) << axis;
      EXPECT_FALSE(Term(doc, "accel", axis, "K")["resolved"].get<bool>()) << axis;
    }
  }
}

TEST(Allan, TomisuarezStillRecord) {
  const std::string csv = std::string(PLUMB_SHARED_DATA_DIR) +
                          "/multipose/tomisuarez2/example_data_tinit_calc.csv";
  if (!std::filesystem::exists(csv)) GTEST_SKIP() << "shared data absent: " << csv;
  TempDir dir;
  const std::string out = dir.File("allan.json");
  // The MPU-6050's raw counts: +-2 g = 16384 LSB/g, +-250 deg/s = 131 LSB/(deg/s), 100 Hz.
  const ToolRun run =
      Plumb({"allan", csv, "--skip-lines", "4", "--header", "--columns", "ax,ay,az,gx,gy,gz",
             "--rate", "100", "--acc-unit", "g", "--acc-scale", "1/16384", "--gyr-unit", "deg/s",
             "--gyr-scale", "1/131", "--whole", "--json", out},
            dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["still"]["samples"], 44930);
  // White noise on every axis; the MPU-6050's datasheet says 400 ug/sqrt(Hz) and
  // 0.005 deg/s/sqrt(Hz) = 0.3 deg/sqrt(h).
  const double accel_n[3] = {0.003176, 0.002938, 0.004521};
  const double gyro_n[3] = {1.302e-4, 1.942e-4, 1.632e-4};
  for (int i = 0; i < 3; ++i) {
    const char* axis = i == 0 ? "x" : i == 1 ? "y" : "z";
    EXPECT_TRUE(Term(doc, "accel", axis, "N")["resolved"].get<bool>()) << axis;
    EXPECT_NEAR(Term(doc, "accel", axis, "N")["value"].get<double>() / accel_n[i], 1.0, 2e-3);
    EXPECT_TRUE(Term(doc, "gyro", axis, "N")["resolved"].get<bool>()) << axis;
    EXPECT_NEAR(Term(doc, "gyro", axis, "N")["value"].get<double>() / gyro_n[i], 1.0, 2e-3);
    EXPECT_FALSE(doc["accel"]["axes"][axis]["fit"]["misfit"].get<bool>()) << axis;
  }
}

TEST(Allan, JsonToStandardOutput) {
  TempDir dir;
  const std::string csv = dir.File("still.csv");
  ASSERT_EQ(Plumb({"simulate", "--out", csv, "--schedule", "paper-static", "--rate", "50"}, dir)
                .exit_code,
            0);
  const ToolRun run = Plumb({"allan", csv, "--whole", "--json", "-"}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json doc = json::parse(run.out);  // stdout holds the document alone
  EXPECT_EQ(doc["inputs"][0], csv);
  EXPECT_TRUE(Contains(run.err, "velocity random walk")) << run.err;
}

TEST(Allan, RefusesMistakesAndNamesTheInput) {
  TempDir dir;
  const std::string csv = dir.File("still.csv");
  ASSERT_EQ(Plumb({"simulate", "--out", csv, "--schedule", "paper-static", "--rate", "50"}, dir)
                .exit_code,
            0);
  const std::string segments = dir.Write("segments.csv", "0,10,a\n");
  EXPECT_EQ(Plumb({"allan", csv, "--whole", "--segments", segments}, dir).exit_code, 2);
  EXPECT_EQ(Plumb({"allan", csv, "--confidence", "1.5"}, dir).exit_code, 2);
  const ToolRun self = Plumb({"allan", csv, "--whole", "--json", csv}, dir);
  EXPECT_EQ(self.exit_code, 2);
  EXPECT_TRUE(Contains(self.err, "is the same file as the input")) << self.err;
  // Five samples: too little for any Allan deviation; the message names the file.
  const std::string tiny = dir.Write(
      "tiny.csv",
      "time_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n0,0,0,-9.8,0,0,0\n0.01,0,0,-9.8,0,0,0\n"
      "0.02,0,0,-9.8,0,0,0\n0.03,0,0,-9.8,0,0,0\n0.04,0,0,-9.8,0,0,0\n");
  const ToolRun short_run = Plumb({"allan", tiny, "--whole"}, dir);
  EXPECT_EQ(short_run.exit_code, 1);
  EXPECT_TRUE(Contains(short_run.err, "tiny.csv")) << short_run.err;
  EXPECT_TRUE(Contains(short_run.err, "still period")) << short_run.err;
}

TEST(Allan, HelpEndsWithAnExample) {
  TempDir dir;
  const ToolRun run = Plumb({"allan", "--help"}, dir);
  ASSERT_EQ(run.exit_code, 0);
  std::istringstream lines(run.out);
  std::string line, last;
  while (std::getline(lines, line)) {
    if (!line.empty()) last = line;
  }
  EXPECT_TRUE(Contains(last, "plumb allan ")) << last;
  EXPECT_TRUE(Contains(run.out, "--whole")) << run.out;
}

}  // namespace
}  // namespace plumb::cli

// One JSON contract (SPEC section 6): every `plumb calibrate --json`, the paper methods too, is
// valid against docs/reference/calibration.schema.json (checked by
// scripts/check-calibration-schema, which also checks what a schema cannot say: a square,
// symmetric covariance over free observable parameters whose diagonal is their sigma), and
// misshapen documents are rejected; `plumb apply` reads every method's document back; and
// `--json -` writes the JSON document alone on stdout for every command that has --json.
//
// The schema checks skip (with the reason) without python3-jsonschema, which scripts/setup
// installs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using nlohmann::json;
using testing::Contains;
using testing::Plumb;
using testing::ReadJson;
using testing::Run;
using testing::TempDir;
using testing::ToolRun;

const std::string kSchema = std::string(PLUMB_SOURCE_DIR) + "/docs/reference/calibration.schema.json";
const std::string kChecker = std::string(PLUMB_SOURCE_DIR) + "/scripts/check-calibration-schema";
const std::string kImu0 = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
const std::vector<std::string> kImu0Options = {"--columns", "ax,ay,az,gx,gy,gz", "--rate", "100"};
const std::vector<std::string> kSite = {"--lat", "6.67", "--lon", "-1.57"};

std::vector<std::string> Join(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

/// Runs the checker on `files` (with "--invalid" first: each must be rejected).
ToolRun Check(const std::vector<std::string>& args, const TempDir& dir) {
  return Run("/usr/bin/python3", Join({kChecker, kSchema}, args), dir);
}

/// Simulated sessions shared by the tests: a multi-pose one, the paper's benchmark schedule
/// and its one still level x-north record (one pose: a singular problem).
struct Sessions {
  TempDir dir;
  std::string multipose = dir.File("multipose.csv");
  std::string benchmark = dir.File("benchmark.csv");
  std::string still = dir.File("still.csv");
  Sessions() {
    const std::vector<std::string> quiet = {"--rate", "100", "--accel-rw", "0", "--gyro-rw", "0",
                                            "--no-temperature"};
    EXPECT_EQ(Plumb(Join({"simulate", "--out", multipose, "--seed", "3"}, quiet), dir).exit_code, 0);
    EXPECT_EQ(Plumb(Join(Join({"simulate", "--out", benchmark, "--schedule", "paper-benchmark",
                               "--still", "5", "--turn", "2", "--seed", "4"},
                              quiet),
                         kSite),
                    dir)
                  .exit_code,
              0);
    EXPECT_EQ(Plumb(Join({"simulate", "--out", still, "--schedule", "paper-static", "--rate",
                          "100", "--seed", "5"},
                         kSite),
                    dir)
                  .exit_code,
              0);
  }
};

struct Output {
  std::string what;                 ///< for messages
  std::vector<std::string> args;    ///< calibrate's arguments before --json
};

/// Every method and several models, on bundled real data and simulated sessions.
std::vector<Output> Outputs(const Sessions& s) {
  return {
      {"generalized base, real (bundled)", Join({"calibrate", kImu0}, kImu0Options)},
      {"generalized base+gyro_g_sensitivity, real, with --baseline base",
       Join({"calibrate", kImu0, "--model", "base+gyro_g_sensitivity", "--baseline", "base"},
            kImu0Options)},
      {"generalized base, real, --constant-bias, kalibr export",
       Join({"calibrate", kImu0, "--constant-bias", "--export",
             "kalibr=" + s.dir.File("imu.yaml")},
            kImu0Options)},
      {"generalized paper model, simulated, site", Join({"calibrate", s.multipose, "--model", "paper"}, kSite)},
      {"generalized base+gyro_bias_drift, simulated", {"calibrate", s.multipose, "--model", "base+gyro_bias_drift"}},
      {"generalized base, one pose (singular: covariance over determined combinations)",
       Join({"calibrate", s.still}, kSite)},
      {"paper-benchmark, simulated", {"calibrate", s.benchmark, "--method", "paper-benchmark"}},
      {"paper-static with a site (gyroscope)",
       Join({"calibrate", s.still, "--method", "paper-static"}, kSite)},
      {"paper-static without a site (accelerometer only)",
       {"calibrate", s.still, "--method", "paper-static"}},
  };
}

/// Writes each output's JSON; returns the files.
std::vector<std::string> WriteOutputs(const Sessions& s) {
  std::vector<std::string> files;
  int k = 0;
  for (const Output& o : Outputs(s)) {
    const std::string file = s.dir.File("out" + std::to_string(k++) + ".json");
    const ToolRun run = Plumb(Join(o.args, {"--json", file}), s.dir);
    EXPECT_EQ(run.exit_code, 0) << o.what << "\n" << run.err;
    files.push_back(file);
  }
  return files;
}

TEST(CalibrationSchema, EveryMethodsOutputIsValid) {
  const Sessions s;
  const std::vector<std::string> files = WriteOutputs(s);
  const ToolRun check = Check(files, s.dir);
  if (check.exit_code == 77) GTEST_SKIP() << check.out;
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
  // The headline keys of SPEC section 6 in every one, whatever the method.
  for (const std::string& f : files) {
    const json doc = ReadJson(f);
    for (const char* key : {"schema_version", "method", "model", "accel", "gyro", "effects",
                            "parameters", "covariance", "fit", "observability", "site"}) {
      EXPECT_TRUE(doc.contains(key)) << f << " lacks " << key;
    }
    EXPECT_EQ(doc["schema_version"], 2) << f;
    const std::string method = doc["method"];
    if (method != "generalized") EXPECT_TRUE(doc.contains(method)) << f;
  }
  // The singular one: its covariance is over the determined combinations.
  const json singular = ReadJson(files[5]);
  EXPECT_FALSE(singular["observability"]["unobservable"].empty());
  EXPECT_FALSE(singular["covariance"]["determined"]["combinations"].empty());
}

TEST(CalibrationSchema, RealImucalSessionOutputsAreValid) {
  const std::string dir_path = std::string(PLUMB_SHARED_DATA_DIR) + "/ferraris/imucal";
  const std::string csv = dir_path + "/example_ferraris_session.csv";
  if (!std::filesystem::exists(csv)) GTEST_SKIP() << "shared data absent: " << csv;
  TempDir dir;
  const std::vector<std::string> read = {csv, "--skip-lines", "1", "--columns",
                                         "t,gx,gy,gz,ax,ay,az", "--time-scale", "0.009765625",
                                         "--gyr-unit", "deg/s", "--gravity", "9.81"};
  const std::string bench = dir.File("bench.json"), general = dir.File("general.json");
  ASSERT_EQ(Plumb(Join(Join({"calibrate"}, read),
                       {"--segments", dir_path + "/example_ferraris_session_list.json",
                        "--method", "paper-benchmark", "--json", bench}),
                  dir)
                .exit_code,
            0);
  ASSERT_EQ(Plumb(Join(Join({"calibrate"}, read), {"--json", general}), dir).exit_code, 0);
  const ToolRun check = Check({bench, general}, dir);
  if (check.exit_code == 77) GTEST_SKIP() << check.out;
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
}

TEST(CalibrationSchema, DiagnoseFitIsCalibratesFit) {
  TempDir dir;
  const std::string out = dir.File("diagnosis.json");
  ASSERT_EQ(Plumb(Join({"diagnose", kImu0, "--json", out}, kImu0Options), dir).exit_code, 0);
  const ToolRun check = Check({"--def", "fit:fit", out}, dir);
  if (check.exit_code == 77) GTEST_SKIP() << check.out;
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
  // And a diagnosis is not mistaken for a calibration.
  EXPECT_EQ(Check({"--invalid", out}, dir).exit_code, 0);
}

/// One misshapen copy of a valid document per way the contract can be broken.
std::vector<std::pair<std::string, json>> Misshapen(const json& general, const json& paper) {
  std::vector<std::pair<std::string, json>> bad;
  auto add = [&](const std::string& name, json doc) { bad.emplace_back(name, std::move(doc)); };
  json d = general;
  d.erase("fit");
  add("no_fit", d);
  d = general;
  d["schema_version"] = 1;
  add("old_version", d);
  d = general;
  d["accel"]["matrix"].erase(2);
  add("two_rows", d);
  d = general;
  d["parameters"][0]["sigma"] = "0.1";
  add("text_sigma", d);
  d = general;
  d["parameters"][0]["name"] = "accel.bias.w";
  add("bad_name", d);
  d = general;
  d["site"]["source"] = "guess";
  add("bad_site_source", d);
  d = general;
  d["covariance"]["matrix"].erase(d["covariance"]["matrix"].size() - 1);
  add("covariance_not_square", d);
  d = general;
  d["covariance"]["matrix"][0][0] = 4.0 * d["covariance"]["matrix"][0][0].get<double>();
  add("covariance_not_sigma", d);
  d = general;
  d["covariance"]["matrix"][0][1] = 2.0 * d["covariance"]["matrix"][0][1].get<double>() + 1.0;
  add("covariance_not_symmetric", d);
  d = general;
  d["covariance"].erase("sigma_scaled_by_chi2");
  add("no_sigma_scaled_by_chi2", d);
  d = paper;
  d.erase("paper-benchmark");
  add("paper_without_detail", d);
  d = paper;
  d["paper-benchmark"]["backend"].erase("covariance");
  add("paper_backend_without_covariance", d);
  d = paper;
  d.erase("parameters");
  add("paper_without_parameters", d);
  return bad;
}

TEST(CalibrationSchema, MisshapenOutputsAreInvalid) {
  const Sessions s;
  const std::string general = s.dir.File("general.json"), paper = s.dir.File("paper.json");
  ASSERT_EQ(Plumb(Join({"calibrate", kImu0, "--json", general}, kImu0Options), s.dir).exit_code, 0);
  ASSERT_EQ(Plumb({"calibrate", s.benchmark, "--method", "paper-benchmark", "--json", paper},
                  s.dir)
                .exit_code,
            0);
  // The unchanged documents pass, so that each rejection below is the change's.
  const ToolRun good = Check({general, paper}, s.dir);
  if (good.exit_code == 77) GTEST_SKIP() << good.out;
  ASSERT_EQ(good.exit_code, 0) << good.out;
  for (const auto& [name, doc] : Misshapen(ReadJson(general), ReadJson(paper))) {
    const std::string file = s.dir.File(name + ".json");
    std::ofstream(file) << doc.dump(1);
    const ToolRun check = Check({"--invalid", file}, s.dir);
    EXPECT_EQ(check.exit_code, 0) << name << ": " << check.out << check.err;
  }
}

TEST(CalibrationSchema, ApplyReadsEveryMethodsOutput) {
  // plumb apply reads a paper method's document by its headline keys, as any other.
  const Sessions s;
  const std::vector<std::string> files = WriteOutputs(s);
  // Except a matrix no sensor has (issue 35 item 5): the paper's static method takes the
  // gyroscope's matrix from the Earth rate of one still pose, a z scale of about 0.01 here.
  const ToolRun refused =
      Plumb(Join({"apply", files[7], s.still, "--out", s.dir.File("c.csv")}, {}), s.dir);
  EXPECT_EQ(refused.exit_code, 1) << refused.err;
  EXPECT_TRUE(Contains(refused.err, files[7] + ":key 'gyro.matrix': the matrix is "
                                               "near-singular"))
      << refused.err;
  EXPECT_FALSE(std::filesystem::exists(s.dir.File("c.csv")));
  for (std::size_t k : {std::size_t{0}, std::size_t{6}, std::size_t{8}}) {
    const json doc = ReadJson(files[k]);
    const std::string input = doc["method"] == "paper-benchmark" ? s.benchmark
                              : doc["method"] == "paper-static"  ? s.still
                                                                 : kImu0;
    std::vector<std::string> args = {"apply", files[k], input, "--out", s.dir.File("c.csv")};
    if (input == kImu0) args = Join(args, kImu0Options);
    const ToolRun run = Plumb(args, s.dir);
    EXPECT_EQ(run.exit_code, 0) << files[k] << "\n" << run.err;
    EXPECT_TRUE(Contains(run.out, "(model " + doc["model"].get<std::string>() + ")")) << run.out;
  }
}

/// stdout is one JSON document, nothing before or after it.
void ExpectJsonAlone(const ToolRun& run, const std::string& what) {
  EXPECT_EQ(run.exit_code, 0) << what << "\n" << run.err;
  EXPECT_NO_THROW((void)json::parse(run.out)) << what << ": stdout is not one JSON document:\n"
                                              << run.out.substr(0, 400);
  EXPECT_FALSE(run.err.empty()) << what << ": the text report goes to stderr";
}

TEST(JsonStdout, EveryCommandWritesTheDocumentAloneOnStdout) {
  const Sessions s;
  const std::string cal = s.dir.File("cal.json"), truth = s.dir.File("truth.json");
  const std::string sim = s.dir.File("sim.csv");
  ASSERT_EQ(Plumb({"simulate", "--out", sim, "--seed", "7", "--truth-json", truth}, s.dir).exit_code, 0);
  ASSERT_EQ(Plumb({"calibrate", sim, "--json", cal}, s.dir).exit_code, 0);
  for (const Output& o : Outputs(s)) {
    const ToolRun run = Plumb(Join(o.args, {"--json", "-"}), s.dir);
    ExpectJsonAlone(run, o.what);
    if (run.exit_code == 0 && json::accept(run.out)) {
      EXPECT_TRUE(json::parse(run.out).contains("parameters")) << o.what;
    }
  }
  ExpectJsonAlone(Plumb(Join({"diagnose", kImu0, "--json", "-"}, kImu0Options), s.dir), "diagnose");
  ExpectJsonAlone(Plumb(Join({"allan", kImu0, "--json", "-"}, kImu0Options), s.dir), "allan");
  const std::string log = std::string(PLUMB_SHARED_DATA_DIR) + "/px4/sample.ulg";
  if (std::filesystem::exists(log)) {  // info reads flight logs; none is bundled
    ExpectJsonAlone(Plumb({"info", log, "--json", "-"}, s.dir), "info");
  }
  ExpectJsonAlone(Plumb({"compare", cal, "--truth", truth, "--json", "-"}, s.dir), "compare --truth");
  const ToolRun effects = Plumb({"effects", "--json", "-"}, s.dir);
  EXPECT_EQ(effects.exit_code, 0) << effects.err;
  EXPECT_NO_THROW((void)json::parse(effects.out)) << effects.out.substr(0, 400);
}

}  // namespace
}  // namespace plumb::cli

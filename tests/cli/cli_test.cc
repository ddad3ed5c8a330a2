// The plumb command as a user runs it: exit codes (0 success, 1 error, 2 usage), the text on
// stdout and stderr, and the JSON it writes (SPEC section 6).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <tuple>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using nlohmann::json;
using testing::Run;
using testing::TempDir;
using testing::ToolRun;
using testing::Plumb;
using testing::Contains;
using testing::ReadJson;


/// True when no number anywhere in `j` is NaN or infinite.
bool AllNumbersFinite(const json& j) {
  if (j.is_number_float()) return std::isfinite(j.get<double>());
  if (j.is_structured()) {
    for (const auto& item : j) {
      if (!AllNumbersFinite(item)) return false;
    }
  }
  return true;
}

/// The SPEC section 6 keys of `calibrate --json`, and the ones this command adds.
void ExpectCalibrationKeys(const json& doc) {
  for (const char* key :
       {"method", "model", "accel", "gyro", "effects", "parameters", "fit", "observability", "site",
        "noise", "segments", "motion", "segmentation", "warnings", "plumb_version", "inputs"}) {
    EXPECT_TRUE(doc.contains(key)) << key;
  }
  for (const char* key : {"matrix", "bias", "correction"}) {
    EXPECT_TRUE(doc["accel"].contains(key)) << key;
    EXPECT_TRUE(doc["gyro"].contains(key)) << key;
  }
  for (const char* key :
       {"chi2", "dof", "chi2_dof", "residual_rms", "segments", "converged", "iterations"}) {
    EXPECT_TRUE(doc["fit"].contains(key)) << key;
  }
  for (const char* key : {"rank", "unknowns", "unobservable", "determined"}) {
    EXPECT_TRUE(doc["observability"].contains(key)) << key;
  }
  for (const char* key : {"lat_deg", "lon_deg", "height_m", "gravity", "source"}) {
    EXPECT_TRUE(doc["site"].contains(key)) << key;
  }
  ASSERT_FALSE(doc["parameters"].empty());
  for (const char* key : {"name", "value", "sigma", "observable", "fixed", "unit"}) {
    EXPECT_TRUE(doc["parameters"][0].contains(key)) << key;
  }
}

/// Files of a small simulated session: 12 poses of 4 s joined by 1.5 s turns at 100 Hz
/// (64 s, 6450 samples), white noise only, at a known site, with chosen true parameters.
struct SimulatedSession {
  std::string csv, truth, segments;
};
const std::vector<std::string> kSite = {"--lat", "51.64", "--lon", "-1.2", "--height", "100"};

SimulatedSession Simulate(const TempDir& dir) {
  SimulatedSession s{dir.File("session.csv"), dir.File("truth.json"), dir.File("segments.csv")};
  std::vector<std::string> args = {"simulate",
                                   "--out",
                                   s.csv,
                                   "--poses",
                                   "12",
                                   "--still",
                                   "4",
                                   "--turn",
                                   "1.5",
                                   "--rate",
                                   "100",
                                   "--model",
                                   "base+gyro_g_sensitivity",
                                   "--truth",
                                   "accel.bias.x=0.1",
                                   "--truth",
                                   "accel.matrix.xy=0.01",
                                   "--truth",
                                   "gyro.matrix.xx=1.01",
                                   "--truth",
                                   "gyro.bias.z=0.005",
                                   "--truth",
                                   "gyro_g_sensitivity.G.xy=2e-4",
                                   "--accel-rw",
                                   "0",
                                   "--gyro-rw",
                                   "0",
                                   "--no-temperature",
                                   "--seed",
                                   "1",
                                   "--truth-json",
                                   s.truth,
                                   "--segments-out",
                                   s.segments};
  args.insert(args.end(), kSite.begin(), kSite.end());
  const ToolRun run = Plumb(args, dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  return s;
}

/// Calibrates with the simulated model at the simulated site; extra arguments appended.
ToolRun Calibrate(const std::vector<std::string>& inputs, const std::string& json_path,
                  const std::vector<std::string>& extra, const TempDir& dir) {
  std::vector<std::string> args = {"calibrate"};
  args.insert(args.end(), inputs.begin(), inputs.end());
  args.insert(args.end(), {"--model", "base+gyro_g_sensitivity", "--json", json_path});
  args.insert(args.end(), kSite.begin(), kSite.end());
  args.insert(args.end(), extra.begin(), extra.end());
  return Plumb(args, dir);
}

/// Splits the native CSV into imu_tk's two tables `t x y z` (same text, so the same numbers).
void SplitNativeCsv(const std::string& csv, const std::string& acc, const std::string& gyr) {
  std::ifstream in(csv);
  std::ofstream a(acc), g(gyr);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string item; std::getline(ss, item, ',');) f.push_back(item);
    a << f[0] << ' ' << f[1] << ' ' << f[2] << ' ' << f[3] << '\n';
    g << f[0] << ' ' << f[4] << ' ' << f[5] << ' ' << f[6] << '\n';
  }
}

TEST(Cli, CalibrateJsonIsBitForBitWhateverTheHeapLayout) {
  // ceres::Covariance orders parameter blocks by address: the backend keeps them in one
  // buffer (estimation/calibration_problem.h) so that every digit of every sigma is the same
  // however the heap is laid out. glibc's tunable without the thread cache lays it out
  // differently (before the buffer, the sigmas of this session differed in their last digits).
  TempDir dir;
  const std::string imu0 = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
  const std::vector<std::string> args = {"calibrate", imu0, "--columns", "ax,ay,az,gx,gy,gz",
                                         "--rate", "100", "--json"};
  std::vector<std::string> first = args, second = args;
  first.push_back(dir.File("a.json"));
  second.push_back(dir.File("b.json"));
  ASSERT_EQ(Plumb(first, dir).exit_code, 0);
  ::setenv("GLIBC_TUNABLES", "glibc.malloc.tcache_count=0:glibc.malloc.mmap_threshold=4096", 1);
  const ToolRun run = Plumb(second, dir);
  ::unsetenv("GLIBC_TUNABLES");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(testing::ReadAll(dir.File("a.json")), testing::ReadAll(dir.File("b.json")));
}

TEST(Cli, CalibrateJsonIsBitForBitWhereverTheThreadsRun) {
  // The command binds its OpenMP threads to CPUs unless OMP_PROC_BIND (or OMP_PLACES,
  // GOMP_CPU_AFFINITY) is set (apps/plumb/jobs.cc); on one thread, on bound threads and on
  // threads the kernel places, every job writes only its own result.
  TempDir dir;
  const std::string imu0 = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
  const std::vector<std::string> args = {"calibrate", imu0, "--columns", "ax,ay,az,gx,gy,gz",
                                         "--rate", "100", "--json"};
  const auto run = [&](const std::string& name, const std::vector<std::string>& more) {
    std::vector<std::string> a = args;
    a.push_back(dir.File(name));
    a.insert(a.end(), more.begin(), more.end());
    const ToolRun r = Plumb(a, dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return testing::ReadAll(dir.File(name));
  };
  const std::string bound = run("bound.json", {"--jobs", "2"});
  const std::string one = run("one.json", {"--jobs", "1"});
  ::setenv("OMP_PROC_BIND", "false", 1);
  const std::string placed_by_kernel = run("kernel.json", {"--jobs", "2"});
  ::unsetenv("OMP_PROC_BIND");
  EXPECT_FALSE(bound.empty());
  EXPECT_EQ(bound, one);
  EXPECT_EQ(bound, placed_by_kernel);
}

TEST(Cli, BiasWanderLevelsMustBeFiniteAndNonNegative) {
  TempDir dir;
  const std::string imu0 = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
  for (const char* flag : {"--accel-rw", "--gyro-rw", "--accel-bi", "--gyro-bi"}) {
    for (const char* value : {"nan", "inf", "-1"}) {
      const ToolRun run = Plumb({"calibrate", imu0, "--columns", "ax,ay,az,gx,gy,gz", "--rate",
                                 "100", flag, value}, dir);
      EXPECT_EQ(run.exit_code, 2) << flag << " " << value;
      EXPECT_NE(run.err.find(std::string(flag) + ": must be a finite number >= 0 (got '" +
                             value + "')"),
                std::string::npos)
          << run.err;
    }
  }
}

TEST(Cli, ConstantBiasExcludesTheWanderLevels) {
  TempDir dir;
  const std::string imu0 = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
  const ToolRun run = Plumb({"calibrate", imu0, "--columns", "ax,ay,az,gx,gy,gz", "--rate", "100",
                             "--constant-bias", "--accel-bi", "1e-3"}, dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--accel-bi excludes --constant-bias"), std::string::npos) << run.err;
  // Alone it fits one constant bias and says what that means for the sigma.
  const ToolRun constant = Plumb({"calibrate", imu0, "--columns", "ax,ay,az,gx,gy,gz", "--rate",
                                  "100", "--constant-bias"}, dir);
  EXPECT_EQ(constant.exit_code, 0) << constant.err;
  EXPECT_NE(constant.out.find("bias held constant over the session (--constant-bias): the sigma "
                              "is honest only if the noise is white"),
            std::string::npos)
      << constant.out;
  // By default the bias wanders, at the typical levels, and the output says so.
  const ToolRun wander = Plumb({"calibrate", imu0, "--columns", "ax,ay,az,gx,gy,gz", "--rate",
                                "100"}, dir);
  EXPECT_NE(wander.out.find("the bias wanders over the session; the biases below are at its start"),
            std::string::npos)
      << wander.out;
  EXPECT_NE(wander.out.find("note: bias wander levels (Allan deviation of 89 s of still data): "
                            "accel instability 0.0004 m/s^2 typical (bound 0.051..0.054 "
                            "m/s^2), accel walk 0.0001 m/s^3/sqrt(Hz) typical (bound "
                            "0.013..0.014 m/s^3/sqrt(Hz))"),
            std::string::npos)
      << wander.out;
}

TEST(Cli, WanderLevelsTakeDatasheetUnits) {
  // --gyro-bi "4 deg/h" is 4 / 206264.8 rad/s; the JSON says the level was given.
  TempDir dir;
  const std::string imu0 = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
  const std::string json_path = (dir.path() / "cal.json").string();
  const ToolRun run = Plumb({"calibrate", imu0, "--columns", "ax,ay,az,gx,gy,gz", "--rate", "100",
                             "--gyro-bi", "4 deg/h", "--accel-rw", "20ug/sqrt(s)", "--json",
                             json_path}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json doc = nlohmann::json::parse(cli::testing::ReadAll((dir.path() / "cal.json").string()));
  EXPECT_NEAR(doc["noise"]["instability_gyro"][0].get<double>(), 4.0 / 206264.806, 1e-12);
  EXPECT_NEAR(doc["noise"]["walk_accel"][2].get<double>(), 20 * 9.80665e-6, 1e-12);
  EXPECT_EQ(doc["noise"]["sources"]["instability_gyro"][1], "given");
  EXPECT_EQ(doc["noise"]["sources"]["walk_gyro"][1], "typical");
  const ToolRun bad = Plumb({"calibrate", imu0, "--columns", "ax,ay,az,gx,gy,gz", "--rate", "100",
                             "--gyro-bi", "4 deg/hour"}, dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("unit 'deg/hour' not known here; use one of rad/s, deg/s, deg/h"),
            std::string::npos)
      << bad.err;
}

TEST(Cli, NoiseFromALongStillRecordingMeasuresTheWander) {
  // A 20-minute still recording of a sensor with 3 times the typical walk: with --noise-from
  // the walks are measured (JSON sources "allan", levels near the truth); the session alone
  // only bounds them.
  TempDir dir;
  auto at = [&](const char* name) { return (dir.path() / name).string(); };
  for (const auto& [out, poses, still] : {std::tuple{"still.csv", "1", "1200"},
                                          std::tuple{"session.csv", "12", "5"}}) {
    const ToolRun sim = Plumb({"simulate", "--out", at(out), "--poses", poses, "--still", still,
                               "--rate", "100", "--accel-rw", "3e-4", "--gyro-rw", "6e-6",
                               "--seed", "5"}, dir);
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }
  const ToolRun run = Plumb({"calibrate", at("session.csv"), "--noise-from", at("still.csv"),
                             "--json", at("cal.json")}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("note: bias wander levels (Allan deviation of "), std::string::npos)
      << run.out;
  const nlohmann::json doc = nlohmann::json::parse(cli::testing::ReadAll((dir.path() / "cal.json").string()));
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_EQ(doc["noise"]["sources"]["walk_accel"][axis], "allan");
    const double K = doc["noise"]["walk_accel"][axis].get<double>();
    EXPECT_GT(K, 1.5e-4);
    EXPECT_LT(K, 6e-4);
  }
  const ToolRun missing = Plumb({"calibrate", at("session.csv"), "--noise-from", at("nothere.csv")},
                                dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("nothere.csv"), std::string::npos) << missing.err;
}

TEST(Cli, JsonDashWritesTheDocumentAloneToStdout) {
  // SPEC section 6: --json - writes to stdout (stdout parses as one JSON document); the text
  // report then goes to stderr.
  TempDir dir;
  const std::string imu0 = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
  for (const char* command : {"calibrate", "diagnose"}) {
    const ToolRun run = Plumb({command, imu0, "--columns", "ax,ay,az,gx,gy,gz", "--rate", "100",
                               "--json", "-"}, dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const json doc = json::parse(run.out);  // throws, failing the test, on anything but JSON
    EXPECT_TRUE(doc.contains("fit")) << command;
    EXPECT_TRUE(Contains(run.err, "chi2/dof")) << command << ": " << run.err;
  }
}

TEST(Cli, HelpListsTheSubcommands) {
  TempDir dir;
  const ToolRun run = Plumb({"--help"}, dir);
  EXPECT_EQ(run.exit_code, 0);
  for (const char* sub : {"calibrate", "simulate", "effects"}) {
    EXPECT_TRUE(Contains(run.out, sub)) << sub << " missing from:\n" << run.out;
  }
}

TEST(Cli, CalibrateHelpDescribesInputAndDetectorOptions) {
  TempDir dir;
  const ToolRun run = Plumb({"calibrate", "--help"}, dir);
  EXPECT_EQ(run.exit_code, 0);
  for (const char* flag : {"--columns", "--rate", "--acc-scale", "--gyr-unit", "--segments",
                           "--level-north", "--heading", "--window", "--false-alarm", "--json"}) {
    EXPECT_TRUE(Contains(run.out, flag)) << flag;
  }
}

TEST(Cli, VersionPrintsTheProjectVersion) {
  TempDir dir;
  const ToolRun run = Plumb({"--version"}, dir);
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_EQ(run.out, std::string(PLUMB_VERSION) + "\n");
}

TEST(Cli, UnknownFlagIsAUsageError) {
  TempDir dir;
  const ToolRun run = Plumb({"calibrate", "x.csv", "--no-such-flag"}, dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_TRUE(Contains(run.err, "--no-such-flag")) << run.err;
  EXPECT_TRUE(run.out.empty());
}

TEST(Cli, LatitudeWithoutLongitudeIsAUsageError) {
  TempDir dir;
  const ToolRun run = Plumb({"calibrate", "x.csv", "--lat", "51"}, dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_TRUE(Contains(run.err, "--lon")) << run.err;
}

TEST(Cli, TableOptionWithoutColumnsIsAUsageError) {
  TempDir dir;
  const std::string csv = dir.Write("a.csv", "time_s,acc_x,acc_y,acc_z\n0,0,0,-9.8\n");
  const ToolRun run = Plumb({"calibrate", csv, "--rate", "100"}, dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_TRUE(Contains(run.err, "--columns")) << run.err;
}

TEST(Cli, MissingInputFileIsAnErrorNamingIt) {
  TempDir dir;
  const std::string missing = dir.File("no_such_session.csv");
  const ToolRun run = Plumb({"calibrate", missing}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.err.rfind("plumb: error: ", 0), 0u) << run.err;
  EXPECT_TRUE(Contains(run.err, missing)) << run.err;
}

TEST(Cli, NonNativeTableSaysWhichOptionsToGive) {
  TempDir dir;
  const std::string log = dir.Write("imu.log", "-8.42 0.06 5.24 0.035 0.002 0.041\n");
  const ToolRun run = Plumb({"calibrate", log}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(Contains(run.err, log)) << run.err;
  EXPECT_TRUE(Contains(run.err, "--columns")) << run.err;
  EXPECT_TRUE(Contains(run.err, "--rate")) << run.err;
}

TEST(Cli, EffectsListsTheCatalogueWithUnits) {
  TempDir dir;
  const ToolRun run = Plumb({"effects"}, dir);
  EXPECT_EQ(run.exit_code, 0);
  for (const char* part : {"accel_linear", "gyro_g_sensitivity", "y_g += G f_b",
                           "gyro_g_sensitivity.G.xy", "rad/s per m/s^2", "time_offset"}) {
    EXPECT_TRUE(Contains(run.out, part)) << part;
  }
}

TEST(Cli, UnknownEffectIsAnErrorNamingIt) {
  TempDir dir;
  const ToolRun run = Plumb({"effects", "no_such_effect"}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(Contains(run.err, "no_such_effect")) << run.err;
}

TEST(Cli, SimulateThenCalibrateRecoversTheTruthWithinThreeSigma) {
  TempDir dir;
  const SimulatedSession s = Simulate(dir);
  const std::string out = dir.File("calibration.json");
  const ToolRun run = Calibrate({s.csv}, out, {}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "still segments: 12 detected")) << run.out;
  EXPECT_TRUE(Contains(run.out, "wrote " + out));

  const json doc = ReadJson(out);
  ExpectCalibrationKeys(doc);
  EXPECT_TRUE(AllNumbersFinite(doc));
  EXPECT_EQ(doc["fit"]["segments"]["still"], 12);
  EXPECT_EQ(doc["fit"]["converged"], true);
  std::map<std::string, double> truth;
  const json truth_doc = ReadJson(s.truth);
  for (const auto& p : truth_doc["parameters"]) truth[p["name"]] = p["value"];
  ASSERT_EQ(doc["parameters"].size(), truth.size());
  for (const auto& p : doc["parameters"]) {
    const std::string name = p["name"];
    ASSERT_TRUE(p["sigma"].is_number()) << name << " has no sigma";
    const double sigma = p["sigma"];
    EXPECT_LT(std::abs(p["value"].get<double>() - truth.at(name)), 3.0 * sigma)
        << name << ": " << p["value"] << " vs truth " << truth.at(name) << " +- " << sigma;
  }
}

TEST(Cli, GivenSegmentsFileReplacesDetection) {
  TempDir dir;
  const SimulatedSession s = Simulate(dir);
  const std::string out = dir.File("calibration.json");
  const ToolRun run = Calibrate({s.csv}, out, {"--segments", s.segments}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "still segments: 12 given in " + s.segments)) << run.out;
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["segmentation"]["method"], "given");
  EXPECT_EQ(doc["segments"][0]["label"], "pose 1 (z down)");
}

TEST(Cli, TwoFileFormGivesTheSameCalibrationAsNativeCsv) {
  TempDir dir;
  const SimulatedSession s = Simulate(dir);
  const std::string acc = dir.File("acc.txt"), gyr = dir.File("gyr.txt");
  SplitNativeCsv(s.csv, acc, gyr);
  const std::string native = dir.File("native.json"), pair = dir.File("pair.json"),
                    flags = dir.File("flags.json");
  ASSERT_EQ(Calibrate({s.csv}, native, {}, dir).exit_code, 0);
  const ToolRun pair_run = Calibrate({acc + "," + gyr}, pair, {}, dir);
  ASSERT_EQ(pair_run.exit_code, 0) << pair_run.err;
  const ToolRun flags_run = Calibrate({}, flags, {"--acc", acc, "--gyr", gyr}, dir);
  ASSERT_EQ(flags_run.exit_code, 0) << flags_run.err;
  const json expected = ReadJson(native)["accel"]["matrix"];
  EXPECT_EQ(ReadJson(pair)["accel"]["matrix"], expected);
  EXPECT_EQ(ReadJson(flags)["accel"]["matrix"], expected);
}

TEST(Cli, StrictFailsWhenThePosesCannotDetermineTheModel) {
  TempDir dir;
  const std::string csv = dir.File("three.csv");
  const ToolRun sim = Plumb({"simulate", "--out", csv, "--poses", "3", "--still", "4", "--turn",
                             "1.5", "--rate", "100", "--seed", "2"},
                            dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const ToolRun run = Plumb({"calibrate", csv, "--strict"}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(Contains(run.err, "distinct orientations")) << run.err;
}

TEST(Cli, MikoffSessionCalibratesAndWritesEverySpecKey) {
  // The bundled copy (data/README.md), so this runs in every clone.
  const std::string log = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const std::string out = dir.File("imu0.json");
  const ToolRun run = Plumb(
      {"calibrate", log, "--columns", "ax,ay,az,gx,gy,gz", "--rate", "100", "--json", out}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "still segments: ")) << run.out;
  const std::string text = testing::ReadAll(out);
  EXPECT_FALSE(std::regex_search(text, std::regex("[:,\\[]\\s*-?(nan|inf)", std::regex::icase)));
  const json doc = ReadJson(out);
  ExpectCalibrationKeys(doc);
  EXPECT_TRUE(AllNumbersFinite(doc));
  EXPECT_EQ(doc["site"]["source"], "none");
  EXPECT_TRUE(doc["site"]["lat_deg"].is_null());
  EXPECT_GE(doc["fit"]["segments"]["still"].get<int>(), 1);
}

TEST(Cli, PaperBenchmarkMethodRunsOnThePapersSchedule) {
  // The seed paper's section 3.1 schedule, simulated with a known accelerometer bias; the
  // section 4 closed form recovers it (Eq. (3) is exact up to noise) in both conventions.
  TempDir dir;
  const std::string csv = dir.File("bench.csv"), out = dir.File("bench.json");
  const ToolRun sim = Plumb({"simulate", "--out", csv, "--schedule", "paper-benchmark", "--still",
                             "5", "--turn", "2", "--rate", "100", "--truth", "accel.bias.x=0.2",
                             "--accel-rw", "0", "--gyro-rw", "0", "--seed", "4"},
                            dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const ToolRun run =
      Plumb({"calibrate", csv, "--method", "paper-benchmark", "--json", out}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("Paper's convention"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("Forward convention"), std::string::npos) << run.out;
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["method"], "paper-benchmark");
  // The headline (SPEC section 6) is the closed form's answer in the forward convention, the
  // same as the parameter of that name; the backend's fit of the same procedure is beside it.
  EXPECT_NEAR(doc["accel"]["bias"][0].get<double>(), 0.2, 0.01) << doc.dump(2);
  for (const auto& p : doc["parameters"]) {
    if (p["name"] == "accel.bias.x") EXPECT_EQ(p["value"], doc["accel"]["bias"][0]);
  }
  EXPECT_EQ(doc["paper-benchmark"]["paper_convention"]["accel"]["bias"][0],
            doc["accel"]["bias"][0]);
  EXPECT_NE(doc["paper-benchmark"]["backend"]["accel"]["bias"][0], doc["accel"]["bias"][0]);
  json backend_covariance = doc["paper-benchmark"]["backend"]["covariance"];
  backend_covariance["source"] = "backend";
  EXPECT_EQ(doc["covariance"], backend_covariance);
  EXPECT_EQ(doc["fit"]["source"], "backend");
}

TEST(Cli, PaperStaticMethodGyroscopeNeedsASiteAndTheBackendMarksTheFixedConstants) {
  TempDir dir;
  const std::string csv = dir.File("static.csv");
  const ToolRun sim = Plumb({"simulate", "--out", csv, "--schedule", "paper-static", "--rate",
                             "100", "--lat", "6.67", "--lon", "-1.57", "--seed", "5"},
                            dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const ToolRun no_site = Plumb({"calibrate", csv, "--method", "paper-static"}, dir);
  EXPECT_EQ(no_site.exit_code, 0) << no_site.err;
  EXPECT_TRUE(Contains(no_site.out, "gyroscope part (steps 5-7 need C_ecef^ned) is left out"))
      << no_site.out;
  const std::string out = dir.File("static.json");
  const ToolRun run = Plumb({"calibrate", csv, "--method", "paper-static", "--lat", "6.67",
                             "--lon", "-1.57", "--json", out},
                            dir);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "Paper's convention")) << run.out;
  EXPECT_TRUE(Contains(run.out, "accel.bias.x + 1 accel.matrix.xz")) << run.out;
  EXPECT_TRUE(Contains(run.out, "freed on the same data: unobservable: accel.matrix.xx")) << run.out;
  const json doc = ReadJson(out);
  const json& detail = doc["paper-static"];
  EXPECT_EQ(detail["backend"]["observability"]["unobservable"].size(), 6u) << detail.dump(2);
  EXPECT_EQ(detail["backend_freed"]["unobservable"].size(), 6u);
  // One pose: the headline's covariance is over the determined combinations, as the backend's.
  EXPECT_EQ(doc["observability"]["unobservable"].size(), 6u);
  EXPECT_EQ(doc["covariance"]["determined"]["combinations"].size(), 6u) << doc["covariance"];
  EXPECT_EQ(doc["accel"]["matrix"][0][0], 1.0) << "the paper's fixed F_xx";
  EXPECT_EQ(doc["accel"]["matrix"][0][1], 0.0) << "the paper's fixed alpha";
}

TEST(Cli, PaperCommandWritesTablesInputsAndFigures) {
  TempDir dir;
  const std::string bench = dir.File("bench.csv"), segs = dir.File("bench_seg.csv");
  const std::string still = dir.File("still.csv"), out = dir.File("paper");
  const std::vector<std::string> site = {"--lat", "6.69", "--lon", "-1.57"};
  std::vector<std::string> sim_b = {"simulate", "--out", bench, "--schedule", "paper-benchmark",
                                    "--still", "10", "--rate", "50", "--segments-out", segs,
                                    "--truth", "accel.bias.z=0.3", "--no-temperature"};
  sim_b.insert(sim_b.end(), site.begin(), site.end());
  ASSERT_EQ(Plumb(sim_b, dir).exit_code, 0);
  std::vector<std::string> sim_s = {"simulate", "--out", still, "--schedule", "paper-static",
                                    "--rate", "50", "--truth", "accel.bias.z=0.3",
                                    "--no-temperature", "--seed", "2"};
  sim_s.insert(sim_s.end(), site.begin(), site.end());
  ASSERT_EQ(Plumb(sim_s, dir).exit_code, 0);
  std::vector<std::string> args = {"paper", bench, "--segments", segs, "--static", still,
                                   "--out", out, "--no-plot"};
  args.insert(args.end(), site.begin(), site.end());
  const ToolRun run = Plumb(args, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "Table 1: gyroscope bias")) << run.out;
  EXPECT_TRUE(Contains(run.out, "Table 5: datasheet check against MPU-6000")) << run.out;
  const json doc = ReadJson(out + "/paper.json");
  // Table 3: the benchmark finds the z bias, the static method cannot (-100 % by design).
  EXPECT_NEAR(doc["tables"]["accel_bias"]["benchmark"][2].get<double>(), 0.3, 0.01);
  EXPECT_NEAR(doc["tables"]["accel_bias"]["error_pct"][2].get<double>(), -100.0, 5.0);
  EXPECT_EQ(doc["backend"]["static_freed"]["unobservable"].size(), 6u);
  EXPECT_TRUE(std::filesystem::exists(out + "/inputs.csv"));
  EXPECT_TRUE(std::filesystem::exists(out + "/figures.gp"));
  EXPECT_TRUE(std::filesystem::exists(out + "/tables.md"));
  // Issue 35 item 1: a disk that fills part way (a file-size limit here; inputs.csv is the
  // largest file) changes none of the four files: never this run's tables.md beside an
  // earlier paper.json. A folder the run made is removed again.
  const auto size = [&](const char* name) { return std::filesystem::file_size(out + "/" + name); };
  ASSERT_GT(size("inputs.csv"), 2 * size("tables.md"));
  const std::uintmax_t limit_blocks = (size("tables.md") + size("paper.json")) / 512 + 2;
  ASSERT_LT(limit_blocks * 512, size("inputs.csv"));
  for (const std::string& target : {out, dir.File("paper_new")}) {
    std::string command = "trap '' XFSZ; ulimit -f " + std::to_string(limit_blocks) +
                          "; exec '" + PLUMB_TOOL + "'";
    for (const std::string& a : args) command += " '" + (a == out ? target : a) + "'";
    if (target == out) std::ofstream(out + "/tables.md") << "an earlier run's";
    const ToolRun full = testing::Run("/bin/sh", {"-c", command}, dir);
    EXPECT_EQ(full.exit_code, 1) << full.err;
    EXPECT_TRUE(Contains(full.err, "plumb: error: cannot write " + target + "/inputs.csv")) << full.err;
    if (target == out) {
      EXPECT_EQ(testing::ReadAll(out + "/tables.md"), "an earlier run's");
    } else {
      EXPECT_FALSE(std::filesystem::exists(target)) << "the run's own folder is removed";
    }
  }
  // Without the section-5 record: a usage error naming both ways to give it.
  const ToolRun missing = Plumb({"paper", bench, "--segments", segs, "--out", out}, dir);
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_TRUE(Contains(missing.err, "--static FILE or --static-section")) << missing.err;
}


TEST(Cli, CalibratesAStillArdupilotLogAndSaysWhatOnePoseCannotDetermine) {
  const std::string log = std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/plane408_centre_point.BIN";
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const std::string out = dir.File("log.json");
  // The default still detector: the vibrating still log is one pose (runs joined).
  const ToolRun run = Plumb({"calibrate", log, "--json", out}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "(IMU instance 0)")) << run.out;
  EXPECT_TRUE(Contains(run.out, "still segments: 1 detected")) << run.out;
  // a warning: on standard error
  EXPECT_TRUE(Contains(run.err, "accelerometer reconstructed as logged ./ INS_ACCSCAL")) << run.err;
  EXPECT_TRUE(Contains(run.out, "(gps)")) << run.out;
  const json doc = ReadJson(out);
  EXPECT_EQ(doc["site"]["source"], "gps");
  // One level pose: the z bias and scale are tied; their combination is determined with sigma.
  bool z_pair = false;
  for (const auto& c : doc["observability"]["determined"]) {
    const std::string text = c["combination"].get<std::string>();
    if (text.find("accel.bias.z") != std::string::npos &&
        text.find("accel.matrix.zz") != std::string::npos) {
      z_pair = true;
      EXPECT_GT(c["sigma"].get<double>(), 0.0);
      EXPECT_LT(c["sigma"].get<double>(), 1e-2);
    }
  }
  EXPECT_TRUE(z_pair) << doc["observability"].dump(2);
  EXPECT_GT(doc["observability"]["unobservable"].size(), 0u);
}

TEST(Cli, InfoDescribesAnArdupilotLog) {
  const std::string log = std::string(PLUMB_SHARED_DATA_DIR) + "/ardupilot/plane408_centre_point.BIN";
  if (!std::filesystem::exists(log)) GTEST_SKIP() << "shared data absent: " << log;
  TempDir dir;
  const std::string out = dir.File("info.json");
  const ToolRun run = Plumb({"info", log, "--json", out}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "IMU instance 1, IMU2 (accel+gyro)")) << run.out;
  const json doc = ReadJson(out);
  ASSERT_EQ(doc["imus"].size(), 3u);  // IMU, IMU2, and IMU3 defined without rows
  EXPECT_EQ(doc["imus"][2]["samples"], 0);
  for (const char* key : {"name", "instance", "samples", "rate_hz", "t_start_s", "t_end_s"}) {
    EXPECT_TRUE(doc["imus"][0].contains(key)) << key;
  }
  EXPECT_NEAR(doc["imus"][0]["rate_hz"].get<double>(), 50.0, 0.1);
  EXPECT_NEAR(doc["site"]["lat_deg"].get<double>(), 51.64, 0.01);
  EXPECT_TRUE(doc["params"].contains("INS_ACCOFFS_X"));
  EXPECT_FALSE(doc["warnings"].empty());  // the truncated last record
  // Not a log: a clear error naming the file.
  const std::string csv = dir.File("x.csv");
  std::ofstream(csv) << "time_s,acc_x,acc_y,acc_z\n0,0,0,-9.8\n";
  const ToolRun bad = Plumb({"info", csv}, dir);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(Contains(bad.err, "not a flight log plumb reads")) << bad.err;
  EXPECT_TRUE(Contains(bad.err, csv)) << bad.err;
}

}  // namespace
}  // namespace plumb::cli

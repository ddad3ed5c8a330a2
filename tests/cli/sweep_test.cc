// `plumb sweep` as a user runs it: a small study, sharded and merged into the same files as
// one run, byte for byte (whatever the threads); a rerun resumes; bad input names the file.
#include <gtest/gtest.h>


#include <filesystem>
#include <fstream>
#include <map>

#include "run_tool.h"

namespace plumb::cli {
namespace {

namespace fs = std::filesystem;
using testing::Contains;
using testing::Plumb;
using testing::ReadAll;
using testing::TempDir;
using testing::ToolRun;

constexpr const char* kStudy = R"({"name": "t", "seed": 3, "runs": 3, "design": "grid",
  "base": {"poses": 9, "still_s": 3, "turn_s": 2, "rate_hz": 100},
  "factors": [{"name": "poses", "levels": [9, 12, 15]}]})";

/// Every file under `dir`, relative path -> contents.
std::map<std::string, std::string> Files(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = ReadAll(e.path().string());
  }
  return out;
}

TEST(SweepCli, ShardsMergeIntoTheUnshardedResultByteForByte) {
  TempDir dir;
  auto at = [&](const char* name) { return (dir.path() / name).string(); };
  std::ofstream(at("study.json")) << kStudy;
  const ToolRun whole = Plumb({"sweep", at("study.json"), "--out", at("whole"), "--jobs", "2"}, dir);
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  EXPECT_TRUE(Contains(whole.out, "point 2: poses=15; 3 runs, 0 failed")) << whole.out;
  for (const char* shard : {"1/2", "2/2"}) {
    const std::string out = std::string("shard") + shard[0];
    const ToolRun r = Plumb({"sweep", at("study.json"), "--out", at(out.c_str()), "--shard", shard,
                             "--jobs", "1"}, dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / out / "results.csv"));
  }
  const ToolRun merged = Plumb({"sweep", "merge", at("shard1"), at("shard2"), "--out", at("merged")}, dir);
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_EQ(Files(dir.path() / "merged"), Files(dir.path() / "whole"));
  // The page and its figures (gnuplot is part of the set-up).
  const std::string page = ReadAll(at("whole/index.html"));
  EXPECT_TRUE(Contains(page, "<h1>plumb sweep: t</h1>")) << page;
  EXPECT_TRUE(Contains(page, "<figure id=\"fig-error_poses_0\">\n<svg")) << page;  // inside the page, own ids
  EXPECT_TRUE(Contains(page, "id='nees_poses-gpDot'")) << page;
  EXPECT_TRUE(Contains(page, "id='error_poses_0-gpDot'")) << page;
  EXPECT_FALSE(fs::exists(dir.path() / "whole/error_poses_0.svg"));
  const std::string csv = ReadAll(at("whole/results.csv"));
  EXPECT_TRUE(Contains(csv, "point,poses,parameter,unit,runs,failed,flagged,mean_error")) << csv;
  EXPECT_TRUE(Contains(csv, "\n2,15,gyro.bias.z,rad/s,3,0,")) << csv;
  // A rerun resumes: a removed point is run again, the others kept, the result the same.
  fs::remove(dir.path() / "whole/points/point-00001.json");
  const ToolRun again = Plumb({"sweep", at("study.json"), "--out", at("whole")}, dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_TRUE(Contains(again.out, "2 already written, 1 to run")) << again.out;
  EXPECT_EQ(Files(dir.path() / "merged"), Files(dir.path() / "whole"));
  // plumb report --study draws the same page elsewhere.
  const ToolRun page_run = Plumb({"report", "--study", at("whole"), "--out", at("page")}, dir);
  ASSERT_EQ(page_run.exit_code, 0) << page_run.err;
  EXPECT_EQ(ReadAll(at("page/index.html")), ReadAll(at("whole/index.html")));
  EXPECT_TRUE(Contains(ReadAll(at("page/index.html")), "id='nees_poses-gpDot'"));
  // A merge with a shard missing says which point.
  const ToolRun missing = Plumb({"sweep", "merge", at("shard1"), "--out", at("m2")}, dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_TRUE(Contains(missing.err, "point 1 is in none of the shards")) << missing.err;
  EXPECT_FALSE(fs::exists(at("m2"))) << "a failed merge leaves no half-written folder";
  // Issue 35 item 4: a point file copied over another is refused on resume (it kept one point
  // twice and lost the other, exit 0), and by a merge; nothing is run or written.
  fs::copy_file(at("whole/points/point-00000.json"), at("whole/points/point-00002.json"),
                fs::copy_options::overwrite_existing);
  const std::string results = ReadAll(at("whole/results.csv"));
  const ToolRun copied = Plumb({"sweep", at("study.json"), "--out", at("whole")}, dir);
  EXPECT_EQ(copied.exit_code, 1) << copied.err;
  EXPECT_TRUE(Contains(copied.err, "plumb: error: " + at("whole/points/point-00002.json") +
                                       ":key 'point': holds point 0, not point 2 of the design (a "
                                       "file copied?): remove the file to run point 2 again"))
      << copied.err;
  EXPECT_EQ(ReadAll(at("whole/results.csv")), results);
  const ToolRun merge_copied =
      Plumb({"sweep", "merge", at("whole"), "--out", at("m3")}, dir);
  EXPECT_EQ(merge_copied.exit_code, 1) << merge_copied.err;
  EXPECT_TRUE(Contains(merge_copied.err, "holds point 0, not point 2")) << merge_copied.err;
  EXPECT_FALSE(fs::exists(at("m3")));
  // Merging into a folder of other files is refused: a merge replaces its folder whole.
  fs::create_directories(at("mine"));
  std::ofstream(at("mine/thesis.tex")) << "mine";
  const ToolRun into_mine =
      Plumb({"sweep", "merge", at("shard1"), at("shard2"), "--out", at("mine")}, dir);
  EXPECT_EQ(into_mine.exit_code, 2) << into_mine.err;
  EXPECT_TRUE(Contains(into_mine.err, "holds files that are not a plumb study's")) << into_mine.err;
  EXPECT_EQ(ReadAll(at("mine/thesis.tex")), "mine");
}

TEST(SweepCli, AYamlStudyIsTheSameStudy) {
  TempDir dir;
  auto at = [&](const char* name) { return (dir.path() / name).string(); };
  std::ofstream(at("s.json")) << kStudy;
  std::ofstream(at("s.yaml")) << "name: t\nseed: 3\nruns: 3\ndesign: grid\n"
                                 "base: {poses: 9, still_s: 3, turn_s: 2, rate_hz: 100}\n"
                                 "factors:\n  - name: poses\n    levels: [9, 12, 15]\n";
  ASSERT_EQ(Plumb({"sweep", at("s.json"), "--out", at("j")}, dir).exit_code, 0);
  const ToolRun yaml = Plumb({"sweep", at("s.yaml"), "--out", at("y")}, dir);
  ASSERT_EQ(yaml.exit_code, 0) << yaml.err;
  EXPECT_EQ(ReadAll(at("y/results.csv")), ReadAll(at("j/results.csv")));
  std::ofstream(at("bad.yaml")) << "runs: [1\n";
  const ToolRun bad = Plumb({"sweep", at("bad.yaml"), "--out", at("b")}, dir);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(Contains(bad.err, at("bad.yaml") + ":line 2: not valid YAML")) << bad.err;
}

// A study's bias wander levels take a datasheet's units, as calibrate's --gyro-bi does: the
// same results as with the SI numbers; a unit the level does not take names the file and the
// key.
TEST(SweepCli, WanderLevelsTakeADatasheetsUnits) {
  TempDir dir;
  auto at = [&](const char* name) { return (dir.path() / name).string(); };
  // 4 deg/h and 40 ug in SI, as %.17g writes them (the same doubles).
  std::ofstream(at("s.json")) << R"({"name": "t", "seed": 3, "runs": 2, "design": "grid",
    "base": {"poses": 9, "still_s": 3, "turn_s": 2, "rate_hz": 100,
             "accel_bi": 0.00039226599999999995},
    "fit": {"wander_levels": "given"},
    "factors": [{"name": "gyro_bi", "levels": [1.9392547244381439e-05]}]})";
  std::ofstream(at("s.yaml")) << "name: t\nseed: 3\nruns: 2\ndesign: grid\n"
                                 "base: {poses: 9, still_s: 3, turn_s: 2, rate_hz: 100, "
                                 "accel_bi: 40 ug}\n"
                                 "fit: {wander_levels: given}\n"
                                 "factors:\n  - name: gyro_bi\n    levels: [4 deg/h]\n";
  const ToolRun si = Plumb({"sweep", at("s.json"), "--out", at("j")}, dir);
  ASSERT_EQ(si.exit_code, 0) << si.err;
  const ToolRun text = Plumb({"sweep", at("s.yaml"), "--out", at("y")}, dir);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_EQ(ReadAll(at("y/results.csv")), ReadAll(at("j/results.csv")));
  EXPECT_TRUE(Contains(ReadAll(at("y/study.json")), "4 deg/h"));  // the study as read
  std::ofstream(at("bad.yaml")) << "name: t\nruns: 1\nbase: {gyro_bi: 4 ug}\n";
  const ToolRun bad = Plumb({"sweep", at("bad.yaml"), "--out", at("b")}, dir);
  EXPECT_EQ(bad.exit_code, 1) << bad.err;
  EXPECT_TRUE(Contains(bad.err, at("bad.yaml") + ":key 'base.gyro_bi': unit 'ug' not known "
                                                 "here; use one of rad/s, deg/s, deg/h"))
      << bad.err;
  EXPECT_FALSE(fs::exists(at("b")));
}

// Issue 35 item 4: nested aliases ("billion laughs": 9 levels of 10 make 10^9 values) are
// refused at the bound: the reading stops at the 100000th value, not after expanding a
// billion (minutes); nothing is written.
TEST(SweepCli, AYamlAliasBombIsRefusedAtOnce) {
  TempDir dir;
  auto at = [&](const char* name) { return (dir.path() / name).string(); };
  std::string bomb = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int k = 1; k <= 9; ++k) {
    const std::string prev = "*a" + std::to_string(k - 1);
    bomb += "a" + std::to_string(k) + ": &a" + std::to_string(k) + " [" + prev;
    for (int j = 1; j < 10; ++j) bomb += ", " + prev;
    bomb += "]\n";
  }
  bomb += "name: t\nruns: 1\nfactors: *a9\n";
  std::ofstream(at("bomb.yaml")) << bomb;
  const ToolRun run = Plumb({"sweep", at("bomb.yaml"), "--out", at("b")}, dir);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_TRUE(Contains(run.err, at("bomb.yaml") + ": more than 100000 values once its aliases "
                                                  "are expanded"))
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(at("b")));
}

TEST(SweepCli, ARealSessionIsTheTemplate) {
  // mikoff's imu0 (bundled): calibrate it, then simulate its poses and timing with known truth.
  TempDir dir;
  auto at = [&](const char* name) { return (dir.path() / name).string(); };
  const std::string imu0 = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
  ASSERT_EQ(Plumb({"calibrate", imu0, "--columns", "ax,ay,az,gx,gy,gz", "--rate", "100", "--json",
                   at("imu0.json")}, dir).exit_code, 0);
  std::ofstream(at("s.json")) << R"({"seed": 1, "runs": 3, "design": "grid",
    "base": {"schedule": "session", "template": "imu0.json", "rate_hz": 100},
    "factors": [{"name": "gyro_noise", "levels": [7e-5]}]})";
  const ToolRun run = Plumb({"sweep", at("s.json"), "--out", at("o")}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(Contains(run.out, "3 runs, 0 failed")) << run.out;
  std::ofstream(at("none.json")) << R"({"base": {"schedule": "session"}})";
  const ToolRun none = Plumb({"sweep", at("none.json"), "--out", at("o2")}, dir);
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_TRUE(Contains(none.err, "the session schedule takes a template")) << none.err;
}

TEST(SweepCli, BadStudiesAndOptionsAreSaid) {
  TempDir dir;
  auto at = [&](const char* name) { return (dir.path() / name).string(); };
  std::ofstream(at("bad.json")) << R"({"runs": 2, "factors": [{"name": "pose", "levels": [3]}]})";
  const ToolRun bad = Plumb({"sweep", at("bad.json"), "--out", at("o")}, dir);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_TRUE(Contains(bad.err, at("bad.json"))) << bad.err;
  EXPECT_TRUE(Contains(bad.err, "unknown factor 'pose'")) << bad.err;
  std::ofstream(at("broken.json")) << "{\"runs\": 2,";
  const ToolRun broken = Plumb({"sweep", at("broken.json"), "--out", at("o")}, dir);
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_TRUE(Contains(broken.err, "not valid JSON")) << broken.err;
  const ToolRun folder = Plumb({"sweep", dir.path().string(), "--out", at("o")}, dir);
  EXPECT_EQ(folder.exit_code, 1);
  EXPECT_TRUE(Contains(folder.err, "is a folder, not a JSON file")) << folder.err;
  std::ofstream(at("s.json")) << kStudy;
  const ToolRun shard = Plumb({"sweep", at("s.json"), "--out", at("o"), "--shard", "3/2"}, dir);
  EXPECT_EQ(shard.exit_code, 2);
  EXPECT_TRUE(Contains(shard.err, "--shard takes K/N with 1 <= K <= N")) << shard.err;
}

}  // namespace
}  // namespace plumb::cli

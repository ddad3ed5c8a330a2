// plumb report as a user runs it: on the bundled real session of scripts/demo (mikoff's
// imu0.log), the page, the JSON and CSV beside it and the PNG figures; without gnuplot, the
// page without figures and a warning.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "run_tool.h"

namespace plumb::cli {
namespace {

using testing::Contains;
using testing::Plumb;
using testing::ReadAll;
using testing::ReadJson;
using testing::TempDir;
using testing::ToolRun;

const std::string kSession = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";
/// How scripts/demo reads it: six columns, no time, 100 Hz.
const std::vector<std::string> kLayout = {"--columns", "ax,ay,az,gx,gy,gz", "--rate", "100"};

bool GnuplotOnPath() {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (!dir.empty() && ::access((std::filesystem::path(dir) / "gnuplot").c_str(), X_OK) == 0) {
      return true;
    }
  }
  return false;
}

std::uintmax_t SizeOf(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  return ec ? 0 : size;
}

/// One run of `plumb report` on the bundled session, shared by the tests below.
class ReportOnDemoSession : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    std::vector<std::string> args = {"report", kSession};
    args.insert(args.end(), kLayout.begin(), kLayout.end());
    args.insert(args.end(), {"--out", Out("")});
    run_ = new ToolRun(Plumb(args, *dir_));
  }
  static void TearDownTestSuite() {
    delete run_;
    delete dir_;
  }
  static std::string Out(const std::string& name) {
    return (dir_->path() / "page" / name).string();
  }
  static TempDir* dir_;
  static ToolRun* run_;
};
TempDir* ReportOnDemoSession::dir_ = nullptr;
ToolRun* ReportOnDemoSession::run_ = nullptr;

TEST_F(ReportOnDemoSession, WritesThePageAndTheFilesBesideIt) {
  ASSERT_EQ(run_->exit_code, 0) << run_->out << run_->err;
  EXPECT_TRUE(Contains(run_->out, "index.html")) << run_->out;
  for (const char* name :
       {"index.html", "result.json", "diagnose.json", "allan.json", "residuals.csv"}) {
    EXPECT_GT(SizeOf(Out(name)), 0u) << name;
  }
  const auto result = ReadJson(Out("result.json"));
  EXPECT_EQ(result["model"], "base");
  const auto diagnosis = ReadJson(Out("diagnose.json"));
  EXPECT_FALSE(diagnosis["candidates"].empty());
  // plumb allan's document on the fit's still segments.
  const auto noise = ReadJson(Out("allan.json"));
  EXPECT_EQ(noise["still"]["segments"].size(),
            result["fit"]["segments"]["still"].get<std::size_t>());
  EXPECT_TRUE(noise["accel"]["axes"]["x"]["terms"]["N"]["resolved"].get<bool>());
}

TEST_F(ReportOnDemoSession, PageHoldsTheParametersTheFitAndTheCommand) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const std::string page = ReadAll(Out("index.html"));
  const auto result = ReadJson(Out("result.json"));
  for (const auto& p : result["parameters"]) {
    EXPECT_TRUE(Contains(page, "<code>" + p["name"].get<std::string>() + "</code>")) << p["name"];
  }
  char chi2[64];
  std::snprintf(chi2, sizeof chi2, "%.6g over ", result["fit"]["chi2"].get<double>());
  EXPECT_TRUE(Contains(page, chi2)) << chi2;
  EXPECT_TRUE(Contains(page, "99 % band"));
  EXPECT_TRUE(Contains(page, "id=\"diagnosis\""));
  EXPECT_TRUE(Contains(page, "id=\"noise\""));
  EXPECT_TRUE(Contains(page, "velocity random walk"));
  EXPECT_TRUE(Contains(page, "--columns ax,ay,az,gx,gy,gz --rate 100 --out"));
  EXPECT_TRUE(Contains(page, "</html>"));
}

TEST_F(ReportOnDemoSession, DrawsTheFiguresWithGnuplot) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on the PATH: no PNGs to check";
  const std::string page = ReadAll(Out("index.html"));
  // imu0.log has no temperature column, so no temperature.png.
  for (const char* png : {"series.png", "residuals.png", "allan.png", "noise.png"}) {
    EXPECT_GT(SizeOf(Out(png)), 0u) << png << "\n" << ReadAll(Out("figures.log"));
    EXPECT_TRUE(Contains(page, std::string("<img src=\"") + png + "\"")) << png;
  }
  EXPECT_FALSE(std::filesystem::exists(Out("temperature.png")));
  EXPECT_FALSE(Contains(page, "No figures"));
}

TEST(Report, WithoutGnuplotWritesThePageWithoutFiguresAndWarns) {
  TempDir dir;
  std::vector<std::string> args = {"report", kSession};
  args.insert(args.end(), kLayout.begin(), kLayout.end());
  args.insert(args.end(), {"--no-diagnose", "--gnuplot", "/nonexistent/gnuplot", "--out",
                           dir.File("page")});
  const ToolRun run = Plumb(args, dir);
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  EXPECT_TRUE(Contains(run.err, "warning")) << run.err;
  const std::string page = ReadAll(dir.File("page/index.html"));
  EXPECT_TRUE(Contains(page, "No figures"));
  EXPECT_TRUE(Contains(page, "Not run (--no-diagnose)"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("page/series.png")));
  EXPECT_FALSE(std::filesystem::exists(dir.File("page/diagnose.json")));
  EXPECT_TRUE(std::filesystem::exists(dir.File("page/figures.gp")));
}

TEST(Report, NeedsAnOutputFolder) {
  TempDir dir;
  std::vector<std::string> args = {"report", kSession};
  args.insert(args.end(), kLayout.begin(), kLayout.end());
  const ToolRun run = Plumb(args, dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_TRUE(Contains(run.err, "--out")) << run.err;
}

TEST(Report, UnreadableInputIsAnErrorNamingTheFile) {
  TempDir dir;
  const ToolRun run = Plumb({"report", dir.File("missing.csv"), "--out", dir.File("page")}, dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_TRUE(Contains(run.err, "missing.csv")) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir.File("page/index.html")));
}

}  // namespace
}  // namespace plumb::cli

// plumb report as a user runs it: on the bundled real session of scripts/demo (mikoff's
// imu0.log), the page with its SVG figures and firmware section inside, the JSON and CSV beside
// it; without gnuplot, the page without figures and a warning; the command to run next when
// the diagnosis finds an effect, and that it runs. (The page in a browser: tests/report/
// browser_test.py.)
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "support/program_on_path.h"
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

bool GnuplotOnPath() { return plumb::testing::ProgramOnPath("gnuplot"); }

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
  EXPECT_TRUE(Contains(page, "band of a complete model"));
  EXPECT_TRUE(Contains(page, "id=\"diagnosis\""));
  EXPECT_TRUE(Contains(page, "id=\"noise\""));
  EXPECT_TRUE(Contains(page, "velocity random walk"));
  EXPECT_TRUE(Contains(page, "--columns ax,ay,az,gx,gy,gz --rate 100 --out"));
  EXPECT_TRUE(Contains(page, "</html>"));
}

TEST_F(ReportOnDemoSession, PutsTheFiguresInsideThePage) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on the PATH: no figures to check";
  const std::string page = ReadAll(Out("index.html"));
  // imu0.log has no temperature column, so no temperature figure.
  for (const char* stem : {"series", "residuals", "allan", "noise"}) {
    EXPECT_TRUE(Contains(page, std::string("<figure id=\"figure-") + stem + "\">\n<svg"))
        << stem << "\n" << ReadAll(Out("figures.log"));
    EXPECT_TRUE(Contains(page, std::string("id='") + stem + "-gpDot'")) << stem;  // own ids
    EXPECT_FALSE(std::filesystem::exists(Out(std::string(stem) + ".svg"))) << stem;
  }
  EXPECT_FALSE(Contains(page, "figure-temperature"));
  EXPECT_FALSE(Contains(page, "No figures"));
  EXPECT_FALSE(Contains(page, "<img"));
  EXPECT_GT(SizeOf(Out("figures.gp")), 0u);  // redraws them
}

TEST_F(ReportOnDemoSession, SaysWhatEachExportWouldWriteAndLeave) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const std::string page = ReadAll(Out("index.html"));
  EXPECT_TRUE(Contains(page, "<h2 id=\"firmware\">Firmware</h2>"));
  EXPECT_TRUE(Contains(page, "<td>ardupilot</td><td>accelerometer</td>"));
  EXPECT_TRUE(Contains(page, "<td>px4</td><td>gyroscope</td>"));
  EXPECT_TRUE(Contains(page, "\nINS_ACCSCAL_X,"));
  EXPECT_TRUE(Contains(page, "\tCAL_GYRO0_XOFF\t"));
  EXPECT_TRUE(Contains(page, "accelerometer_noise_density"));
  EXPECT_TRUE(Contains(page, " calibrate " + kSession +
                                 " --columns ax,ay,az,gx,gy,gz --rate 100 --export "
                                 "ardupilot=calibration.param</pre>"));
  // The numbers are calibrate's: its --export file is the one on the page.
  TempDir dir;
  std::vector<std::string> args = {"calibrate", kSession};
  args.insert(args.end(), kLayout.begin(), kLayout.end());
  args.insert(args.end(), {"--export", "ardupilot=" + dir.File("c.param")});
  const ToolRun calibrate = Plumb(args, *dir_);
  ASSERT_EQ(calibrate.exit_code, 0) << calibrate.err;
  std::string file = ReadAll(dir.File("c.param"));
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{{"&", "&amp;"}, {"'", "&#39;"}}) {
    for (std::size_t at = file.find(from); at != std::string::npos; at = file.find(from, at + to.size())) {
      file.replace(at, from.size(), to);
    }
  }
  EXPECT_TRUE(Contains(page, "<pre>" + file + "</pre>")) << file;
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
  // Issue 35 item 8: the warning names the page's folder, not the staging folder it was
  // written in (gone once the page is in place).
  EXPECT_TRUE(Contains(run.err, "' in " + dir.File("page") + " to draw the figures")) << run.err;
  EXPECT_FALSE(Contains(run.err, "plumb-tmp")) << run.err;
  const std::string page = ReadAll(dir.File("page/index.html"));
  EXPECT_TRUE(Contains(page, "No figures"));
  EXPECT_TRUE(Contains(page, "Not run (--no-diagnose)"));
  EXPECT_FALSE(Contains(page, "<svg"));
  EXPECT_FALSE(std::filesystem::exists(dir.File("page/diagnose.json")));
  EXPECT_TRUE(std::filesystem::exists(dir.File("page/figures.gp")));
}

/// The text of the first <pre class="next"> block of `page`, unescaped.
std::string NextCommand(const std::string& page) {
  const std::string open = "<pre class=\"next\">";
  const std::size_t begin = page.find(open);
  if (begin == std::string::npos) return "";
  std::string text = page.substr(begin + open.size(), page.find("</pre>", begin) - begin - open.size());
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{{"&#39;", "'"}, {"&amp;", "&"}}) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + 1)) {
      text.replace(at, from.size(), to);
    }
  }
  return text;
}

TEST(Report, ShowsTheCommandToRunNextAndItRuns) {
  // A simulated session with a temperature bias the base model lacks: the diagnosis finds it.
  TempDir dir;
  const ToolRun sim = Plumb({"simulate", "--out", dir.File("s.csv"), "--model",
                             "base+accel_temperature_bias", "--truth",
                             "accel_temperature_bias.c1.x=0.003", "--temperature",
                             "updown:20:40:40", "--seed", "5"}, dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const ToolRun run = Plumb({"report", dir.File("s.csv"), "--no-figures", "--out",
                             dir.File("page")}, dir);
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const std::string page = ReadAll(dir.File("page/index.html"));
  const std::string next = NextCommand(page);
  // The model diagnose's text suggests (printed by report too) is the one on the page.
  const std::size_t said = run.out.find(" -> refit with --model ");
  ASSERT_NE(said, std::string::npos) << run.out;
  const std::string spec = run.out.substr(said + 23, run.out.find('\n', said) - said - 23);
  EXPECT_EQ(next, std::string(PLUMB_TOOL) + " calibrate " + dir.File("s.csv") + " --model " + spec)
      << page;
  // It runs as written: the refit has the effect.
  std::vector<std::string> args;
  std::istringstream words(next.substr(std::string(PLUMB_TOOL).size()));
  for (std::string word; words >> word;) args.push_back(word);
  args.insert(args.end(), {"--json", dir.File("refit.json")});
  const ToolRun refit = Plumb(args, dir);
  ASSERT_EQ(refit.exit_code, 0) << refit.out << refit.err;
  EXPECT_EQ(ReadJson(dir.File("refit.json"))["model"], spec);
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

// Figures through gnuplot: the plan of plumb report's figures (which ones, their data), and
// running gnuplot as a child process, with and without gnuplot on the PATH.
#include "support/program_on_path.h"
#include "plumb/report/gnuplot.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "plumb/report/figures.h"
#include "report_test_util.h"

namespace plumb::report {
namespace {

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// True when an executable `gnuplot` is on the PATH.
bool GnuplotOnPath() { return plumb::testing::ProgramOnPath("gnuplot"); }

/// A line, drawn to line.svg.
GnuplotJob LineJob() {
  GnuplotJob job;
  job.data.push_back({"line.csv", "# x,y\n0,0\n1,1\n2,4\n"});
  job.script = SvgTerminal(320, 240) +
               "set datafile separator ','\nset output 'line.svg'\n"
               "plot 'line.csv' using 1:2 with lines title 'y'\nset output\n";
  job.outputs = {"line.svg"};
  return job;
}

/// 2 s at 100 Hz, two still segments (every fourth sample of noise), with or without
/// temperature.
ImuSeries Series(bool temperature) {
  std::mt19937_64 rng(20261122);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  ImuSeries s;
  for (int i = 0; i < 200; ++i) {
    s.t_s.push_back(1000.0 + 0.01 * i);
    s.acc.push_back(Vec3f(noise(rng), noise(rng), -9.8f + noise(rng)));
    s.gyr.push_back(Vec3f(noise(rng), noise(rng), noise(rng)));
    if (temperature) s.temp_c.push_back(25.0f + 0.01f * static_cast<float>(i));
  }
  return s;
}

diagnostics::ResidualAnalysis Analysis(bool with_temperature) {
  diagnostics::ResidualAnalysis a;
  for (int k = 0; k < 2; ++k) {
    diagnostics::SegmentComparison c;
    c.index = static_cast<std::size_t>(k);
    c.t_mid_s = 1000.5 + k;
    c.temp_c = with_temperature ? 25.0 + k : diagnostics::SegmentComparison::kNaN;
    c.has_acc = c.has_gyr = true;
    c.acc_whitened = Vec3(0.5, -1.0, 2.0);
    a.still.push_back(c);
  }
  return a;
}

TEST(Gnuplot, QuotesSingleQuotesByDoublingThem) {
  EXPECT_EQ(GnuplotQuote("it's"), "'it''s'");
}

TEST(Gnuplot, MissingProgramIsAnOutcomeNotAnError) {
  testing::TempDir dir;
  const GnuplotOutcome out = RunGnuplot(dir.path().string(), LineJob(), "plumb-no-such-gnuplot");
  EXPECT_FALSE(out.ran);
  EXPECT_TRUE(Contains(out.message, "was not found on the PATH")) << out.message;
  EXPECT_TRUE(out.written.empty());
  // The data and the script stay, to be drawn later.
  EXPECT_TRUE(std::filesystem::exists(dir.File("line.csv")));
  EXPECT_TRUE(std::filesystem::exists(dir.File("figures.gp")));
}

// Issue 35 item 4: a --gnuplot that never exits (here one that sleeps for a minute) is stopped
// at the limit and said; the report then goes on without its figures.
TEST(Gnuplot, AProgramThatNeverFinishesIsStoppedAtTheLimit) {
  testing::TempDir dir;
  const std::string stuck = dir.File("stuck-gnuplot");
  std::ofstream(stuck) << "#!/bin/sh\nexec sleep 60\n";
  std::filesystem::permissions(stuck, std::filesystem::perms::owner_all);
  const GnuplotOutcome out = RunGnuplot(dir.path().string(), LineJob(), stuck, 0.3);
  EXPECT_FALSE(out.ran);
  EXPECT_EQ(out.exit_code, -1);
  EXPECT_EQ(out.message, "'" + stuck + " figures.gp' did not finish within 0.3 s and was "
                         "stopped: no figures (is it waiting for input, or a window?)");
  EXPECT_TRUE(out.written.empty());
}

TEST(Gnuplot, FailingScriptReportsGnuplotsMessage) {
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on the PATH";
  testing::TempDir dir;
  GnuplotJob job = LineJob();
  job.script += "plot 'no_such_file.csv' using 1:2\n";
  const GnuplotOutcome out = RunGnuplot(dir.path().string(), job);
  EXPECT_FALSE(out.ran);
  EXPECT_TRUE(Contains(out.message, "failed (exit")) << out.message;
}

TEST(Gnuplot, DrawsTheImageInTheFolder) {
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on the PATH";
  testing::TempDir dir;
  const GnuplotOutcome out = RunGnuplot(dir.path().string(), LineJob());
  EXPECT_TRUE(out.ran) << out.message;
  EXPECT_TRUE(out.message.empty()) << out.message;
  ASSERT_EQ(out.written, std::vector<std::string>{"line.svg"});
  EXPECT_GT(std::filesystem::file_size(dir.File("line.svg")), 0u);
}

TEST(Figures, PlansSeriesAndResidualsWithoutTemperature) {
  const ImuSeries series = Series(false);
  const std::vector<StillSegment> segments = {{0, 80, "a", {}, false, {}},
                                              {120, 200, "b", {}, false, {}}};
  const FigurePlan plan =
      PlanFigures(series, segments, testing::MakeResult(), Analysis(false));
  EXPECT_EQ(plan.job.outputs, (std::vector<std::string>{"series.svg", "residuals.svg"}));
  ASSERT_EQ(plan.figures.size(), 2u);
  EXPECT_EQ(plan.figures[0].file, "series.svg");
  // Both still segments are shaded, in seconds since the first sample.
  EXPECT_TRUE(Contains(plan.job.script, "rect from first 0, graph 0 to first 0.79, graph 1"));
  EXPECT_TRUE(Contains(plan.job.script, "rect from first 1.2, graph 0 to first 1.99, graph 1"));
  const auto still = std::find_if(plan.job.data.begin(), plan.job.data.end(),
                                  [](const GnuplotFile& f) { return f.name == "still.csv"; });
  ASSERT_NE(still, plan.job.data.end());
  EXPECT_TRUE(Contains(still->content, "\n0.5,,0.5,-1,2,"));  // t_mid - t0, no temperature
}

TEST(Figures, AddsTheTemperatureFigureWhenTheSessionHasTemperature) {
  const FigurePlan plan =
      PlanFigures(Series(true), {{0, 80, "a", {}, false, {}}}, testing::MakeResult(),
                  Analysis(true));
  EXPECT_NE(std::find(plan.job.outputs.begin(), plan.job.outputs.end(), "temperature.svg"),
            plan.job.outputs.end());
  EXPECT_EQ(plan.figures.size(), plan.job.outputs.size());
}

TEST(Figures, DrawsEveryPlannedFigure) {
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on the PATH";
  diagnostics::ResidualAnalysis analysis = Analysis(true);
  diagnostics::ResidualAllan allan;
  allan.tau_s = {0.01, 0.1, 1.0};
  allan.adev = {1e-2, 3e-3, 1e-3};
  allan.white = {1e-2, 3.2e-3, 1e-3};
  allan.ratio = 1.0;
  analysis.allan = {allan};
  analysis.allan_segments = {0};
  testing::TempDir dir;
  const FigurePlan plan = PlanFigures(Series(true), {{0, 80, "a", {}, false, {}}},
                                      testing::MakeResult(), analysis);
  EXPECT_EQ(plan.job.outputs.size(), 4u);
  const GnuplotOutcome out = RunGnuplot(dir.path().string(), plan.job);
  EXPECT_TRUE(out.ran) << out.message;
  EXPECT_EQ(out.written, plan.job.outputs) << out.message;
  // Each drawn figure goes inside the page, with ids of its own; the files beside are gone.
  const std::vector<ReportFigure> drawn = EmbedDrawnFigures(dir.path().string(), plan, out);
  ASSERT_EQ(drawn.size(), plan.figures.size());
  for (const ReportFigure& figure : drawn) {
    const std::string stem = figure.file.substr(0, figure.file.find('.'));
    EXPECT_EQ(figure.svg.rfind("<svg", 0), 0u) << figure.file;
    EXPECT_TRUE(Contains(figure.svg, "id='" + stem + "-gpPt7'")) << figure.file;
    EXPECT_FALSE(Contains(figure.svg, "'#gpPt")) << figure.file;
    EXPECT_FALSE(std::filesystem::exists(dir.File(figure.file))) << figure.file;
  }
}

TEST(Figures, EmbedsOnlyTheFiguresGnuplotWrote) {
  FigurePlan plan;
  plan.figures = {{"series.svg", "Input", "", ""}, {"allan.svg", "Allan", "", ""}};
  testing::TempDir dir;
  std::ofstream(dir.File("allan.svg")) << "<svg width=\"1\" height=\"1\"><g id='a'/></svg>\n";
  GnuplotOutcome out;
  out.written = {"allan.svg"};
  const std::vector<ReportFigure> drawn = EmbedDrawnFigures(dir.path().string(), plan, out);
  ASSERT_EQ(drawn.size(), 1u);
  EXPECT_EQ(drawn[0].title, "Allan");
  EXPECT_EQ(drawn[0].svg, "<svg width=\"1\" height=\"1\"><g id='allan-a'/></svg>");
}

}  // namespace
}  // namespace plumb::report

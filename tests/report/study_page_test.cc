// The page of a sensitivity study (plumb sweep): for every factor and every parameter the
// study scores, a figure of the signed error against the factor (its mean, its spread over the
// runs, the mean sigma) with units on both axes and a legend for every line; a factor whose
// value names a case (gravity 0: WGS84) drawn by level; on one pose the determined
// combinations drawn instead of the raw parameters. Hand-made point summaries: no fit is run.
#include "support/program_on_path.h"
#include "plumb/report/study_page.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "plumb/report/study_figures.h"
#include "report_test_util.h"

namespace plumb::report {
namespace {

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

bool GnuplotOnPath() { return plumb::testing::ProgramOnPath("gnuplot"); }

study::Study MakeStudy() {
  return study::ParseStudy(nlohmann::json::parse(R"({"name": "g", "seed": 1, "runs": 3,
    "design": "one_at_a_time",
    "base": {"poses": 12, "still_s": 5, "turn_s": 2, "rate_hz": 100},
    "factors": [{"name": "fit_gravity_m_s2", "levels": [0, 9.80665]},
                {"name": "still_s", "levels": [5, 10]}]})"),
                           "g.json");
}

study::ParameterSummary Row(const std::string& name, const std::string& unit, double mean,
                            int runs = 3) {
  study::ParameterSummary r;
  r.name = name;
  r.unit = unit;
  r.runs = runs;
  r.mean_error = runs > 0 ? mean : NAN;
  r.sd_error = runs > 0 ? 1e-5 : NAN;
  r.rms_error = runs > 0 ? std::abs(mean) : NAN;
  r.mean_sigma = runs > 0 ? 4e-5 : NAN;
  return r;
}

/// The design's points, each with `rows` (their mean error moved by the point's index), NEES 1.
std::vector<study::PointSummary> Points(const study::Study& s,
                                        const std::vector<study::ParameterSummary>& rows) {
  std::vector<study::PointSummary> out;
  for (const study::Point& p : study::DesignPoints(s)) {
    study::PointSummary ps;
    ps.point = p;
    ps.runs = 3;
    ps.nees_per_dof = 1.0 + 0.1 * p.index;
    ps.nees_dof = 6;
    ps.nees_low = 0.2;
    ps.nees_high = 2.4;
    ps.parameters = rows;
    for (auto& r : ps.parameters) r.mean_error -= 1e-3 * p.index;
    out.push_back(ps);
  }
  return out;
}

const std::vector<study::ParameterSummary> kRows = {
    Row("accel.matrix.zz", "1", -1e-6), Row("accel.bias.z", "m/s^2", 2e-4),
    Row("gyro.bias.z", "rad/s", 1e-6)};

TEST(StudyPage, EveryScoredParameterGetsASignedErrorFigureAgainstEveryFactor) {
  const study::Study s = MakeStudy();
  const StudyFigurePlan plan = PlanStudyFigures(s, Points(s, kRows));
  ASSERT_EQ(plan.figures.size(), 2u * (1 + kRows.size()));  // per factor: NEES + 3 errors
  ASSERT_EQ(plan.job.outputs.size(), plan.figures.size());
  for (std::size_t f = 0; f < 2; ++f) {
    for (const auto& row : kRows) {
      const std::string title = "set title '" + row.name + "'";
      EXPECT_TRUE(Contains(plan.job.script, title)) << title;
      const bool found = std::any_of(plan.figures.begin(), plan.figures.end(), [&](const auto& fig) {
        return fig.factor == f && fig.parameter == row.name && fig.unit == row.unit;
      });
      EXPECT_TRUE(found) << row.name;
    }
  }
  const std::string& gp = plan.job.script;
  // Units on both axes: the parameter's on y, the factor's on x.
  EXPECT_TRUE(Contains(gp, "set ylabel 'error, estimate - truth (m/s^2)'")) << gp;
  EXPECT_TRUE(Contains(gp, "set ylabel 'error, estimate - truth (rad/s)'")) << gp;
  EXPECT_TRUE(Contains(gp, "set ylabel 'error, estimate - truth (1)'")) << gp;
  EXPECT_TRUE(Contains(gp, "set xlabel 'still_s (s)'")) << gp;
  EXPECT_TRUE(Contains(gp, "set xlabel 'fit_gravity_m_s2 (m/s^2), by level'")) << gp;
  EXPECT_TRUE(Contains(gp, "set ylabel 'NEES / dof (dimensionless)'")) << gp;
  // A legend for every line: the mean error, its spread, the sigma, the NEES and its band.
  for (const char* title : {"title 'mean error over runs'", "title 'spread: mean +- 1 sd over runs'",
                            "title '+- mean sigma the fit reported'", "title 'NEES / dof, all runs'",
                            "title '95 % band of NEES / dof (honest sigma)'"}) {
    EXPECT_TRUE(Contains(gp, title)) << title;
  }
  // The signed mean error is drawn, not the RMS: column 7 of the factor's data is the first
  // row's mean error, negative here.
  EXPECT_TRUE(Contains(gp, "using 1:7 with")) << gp;
  // The gravity factor's 0 is WGS84's gravity: a category at x = 0, named, not 0 m/s^2.
  EXPECT_TRUE(Contains(gp, "set xtics ('WGS84' 0, '9.80665' 1)")) << gp;
  const auto csv = std::find_if(plan.job.data.begin(), plan.job.data.end(),
                                [](const GnuplotFile& d) { return d.name == "study_fit_gravity_m_s2.csv"; });
  ASSERT_NE(csv, plan.job.data.end());
  EXPECT_TRUE(Contains(csv->content, "\n0,WGS84,1,0.2,2.4,,-1e-06,1e-05,4e-05,")) << csv->content;
  EXPECT_TRUE(Contains(csv->content, "\n1,9.80665,1.1,")) << csv->content;
  // still_s is a scale: drawn at its values.
  const auto still = std::find_if(plan.job.data.begin(), plan.job.data.end(),
                                  [](const GnuplotFile& d) { return d.name == "study_still_s.csv"; });
  ASSERT_NE(still, plan.job.data.end());
  EXPECT_TRUE(Contains(still->content, "\n10,10,1.2,")) << still->content;
}

TEST(StudyPage, OnePoseDrawsTheDeterminedCombinations) {
  const study::Study s = MakeStudy();
  // One pose: the raw parameters are determined by no run; the combinations are scored.
  const std::vector<study::ParameterSummary> rows = {
      Row("accel.matrix.xz", "1", 0.0, 0), Row("accel.bias.x", "m/s^2", 0.0, 0),
      Row("accel.bias.x - 9.78 accel.matrix.xz", "m/s^2", 0.04),
      Row("gyro.bias.y + 7.243e-05 gyro.matrix.yx", "rad/s", 5e-6)};
  const StudyFigurePlan plan = PlanStudyFigures(s, Points(s, rows));
  std::vector<std::string> drawn;
  for (const auto& fig : plan.figures) {
    if (fig.factor == 0 && !fig.parameter.empty()) drawn.push_back(fig.parameter);
  }
  EXPECT_EQ(drawn, (std::vector<std::string>{"accel.bias.x - 9.78 accel.matrix.xz",
                                             "gyro.bias.y + 7.243e-05 gyro.matrix.yx"}));
  EXPECT_TRUE(Contains(plan.job.script,
                       "set title 'accel.bias.x - 9.78 accel.matrix.xz'\nplot"));
  // A combination's other coefficients follow the factor (the fit's gravity: 9.807 instead of
  // 9.78): still one row, matched by its leading parameter, and its name says so.
  auto moved = Points(s, rows);
  moved[1].parameters[2].name = "accel.bias.x - 9.807 accel.matrix.xz";
  const StudyFigurePlan vary = PlanStudyFigures(s, moved);
  drawn.clear();
  for (const auto& fig : vary.figures) {
    if (fig.factor == 0 && !fig.parameter.empty()) drawn.push_back(fig.parameter);
  }
  EXPECT_EQ(drawn, (std::vector<std::string>{
                       "accel.bias.x - 9.78 accel.matrix.xz (coefficients vary)",
                       "gyro.bias.y + 7.243e-05 gyro.matrix.yx"}));
  const auto csv = std::find_if(vary.job.data.begin(), vary.job.data.end(), [](const GnuplotFile& d) {
    return d.name == "study_fit_gravity_m_s2.csv";
  });
  ASSERT_NE(csv, vary.job.data.end());
  EXPECT_TRUE(Contains(csv->content, "\n1,9.80665,1.1,0.2,2.4,,,,,,,,,,0.039,1e-05,4e-05,")) << csv->content;
}

TEST(StudyPage, WithoutAnUncertainFactorNoFirstOrderSpreadIsDrawn) {
  const study::Study s = MakeStudy();
  const StudyFigurePlan plan = PlanStudyFigures(s, Points(s, kRows));
  // The column is there, empty: no factor has a sigma.
  const std::string& csv = plan.job.data.front().content;
  EXPECT_TRUE(Contains(csv, ",mean_error0,sd_error0,mean_sigma0,sd_first_order0,mean_error1,")) << csv;
  EXPECT_TRUE(Contains(csv, "\n0,WGS84,1,0.2,2.4,,-1e-06,1e-05,4e-05,,0.0002,")) << csv;
  EXPECT_FALSE(Contains(plan.job.script, "sd_first_order")) << plan.job.script;
  for (const auto& fig : plan.figures) EXPECT_FALSE(fig.first_order) << fig.file;
}

TEST(StudyPage, AnUncertainFactorsFirstOrderSpreadIsDrawnAboutTheMeanError) {
  // Gravity known to 0.01 m/s^2: a row with d/dg = -0.1 per m/s^2 has sd_first_order 1e-3
  // (0.01 * 0.1); a row without a sensitivity has none, and no line.
  const study::Study s = study::ParseStudy(nlohmann::json::parse(R"({"name": "u", "seed": 1,
    "runs": 3, "design": "one_at_a_time", "fit": {"method": "generalized"},
    "base": {"poses": 12, "still_s": 5, "turn_s": 2, "rate_hz": 100},
    "factors": [{"name": "fit_gravity_m_s2", "levels": [9.78, 9.80665], "sigma": 0.01},
                {"name": "still_s", "levels": [5, 10]}]})"),
                                           "u.json");
  ASSERT_EQ(study::SensitivityFactors(s), std::vector<std::string>{"fit_gravity_m_s2"});
  std::vector<study::ParameterSummary> rows = kRows;
  rows[0].mean_d_dp = {-0.1};
  const StudyFigurePlan plan = PlanStudyFigures(s, Points(s, rows));
  const std::string& csv = plan.job.data.front().content;
  EXPECT_TRUE(Contains(csv, "\n0,WGS84,1,0.2,2.4,,-1e-06,1e-05,4e-05,0.001,0.0002,1e-05,4e-05,,")) << csv;
  // Row 0 (columns 7-10): the pair mean +- sd_first_order, with a legend entry, once per
  // factor; rows 1 and 2 (columns 11-14, 15-18) have no value, and no line.
  const std::string& gp = plan.job.script;
  EXPECT_TRUE(Contains(gp, "using 1:($7+$10) with lines dt 2")) << gp;
  EXPECT_TRUE(Contains(gp, "using 1:($7-$10) with lines dt 2")) << gp;
  EXPECT_TRUE(Contains(gp, "title 'mean +- sd_first_order'")) << gp;
  EXPECT_FALSE(Contains(gp, "$14)")) << gp;
  EXPECT_FALSE(Contains(gp, "$18)")) << gp;
  std::size_t drawn = 0;
  for (const auto& fig : plan.figures) {
    EXPECT_EQ(fig.first_order, fig.parameter == "accel.matrix.zz") << fig.file;
    drawn += fig.first_order ? 1 : 0;
  }
  EXPECT_EQ(drawn, 2u);  // against each factor
  if (!GnuplotOnPath()) return;
  // gnuplot draws every figure of it (the sums over empty fields are skipped, not an error).
  testing::TempDir dir;
  const GnuplotOutcome out = RunGnuplot(dir.path().string(), plan.job);
  ASSERT_TRUE(out.ran) << out.message;
  EXPECT_EQ(out.written.size(), plan.job.outputs.size()) << out.message;
  const auto svgs = TakeSvgFiles(dir.path().string(), out.written);
  const auto zz = std::find_if(svgs.begin(), svgs.end(), [](const InlineFigure& f) {
    return f.file == "error_fit_gravity_m_s2_0.svg";
  });
  ASSERT_NE(zz, svgs.end());
  EXPECT_TRUE(Contains(zz->svg, "mean +- sd_first_order")) << zz->svg;
}

TEST(StudyPage, ThePageGroupsTheDrawnFiguresByFactor) {
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on the PATH";
  const study::Study s = MakeStudy();
  const auto points = Points(s, kRows);
  testing::TempDir dir;
  const GnuplotJob job = StudyFigures(s, points);
  const GnuplotOutcome out = RunGnuplot(dir.path().string(), job);
  ASSERT_TRUE(out.ran) << out.message;
  ASSERT_EQ(out.written.size(), job.outputs.size());
  const std::string page = StudyPage(s, points, TakeSvgFiles(dir.path().string(), out.written), "");
  EXPECT_TRUE(Contains(page, "<th>fit_gravity_m_s2 (m/s^2)</th><th>still_s (s)</th>")) << page;
  EXPECT_TRUE(Contains(page, "<td class=\"num\">WGS84</td>")) << page;
  EXPECT_TRUE(Contains(page, "<nav class=\"toc\">")) << page;
  EXPECT_TRUE(Contains(page, "<section id=\"factor-fit_gravity_m_s2\">\n<h3>Against fit_gravity_m_s2 (m/s^2)</h3>"))
      << page;
  EXPECT_TRUE(Contains(page, "<h3>Against still_s (s)</h3>")) << page;
  for (const std::string& file : job.outputs) {
    const std::string id = file.substr(0, file.size() - 4);
    EXPECT_TRUE(Contains(page, "<figure id=\"fig-" + id + "\">\n<svg")) << id;
    EXPECT_TRUE(Contains(page, "<a href=\"#fig-" + id + "\">")) << id;
    EXPECT_TRUE(Contains(page, "id='" + id + "-gpDot'")) << id;  // ids of its own
  }
  EXPECT_TRUE(Contains(page, "<figcaption>error of accel.bias.z (m/s^2): mean over the runs")) << page;
  // Axis labels and legends are in the drawings.
  EXPECT_TRUE(Contains(page, "error, estimate - truth (m/s^2)")) << page;
  EXPECT_TRUE(Contains(page, "spread: mean +- 1 sd over runs")) << page;
  EXPECT_TRUE(Contains(page, ">WGS84<")) << page;
}

}  // namespace
}  // namespace plumb::report

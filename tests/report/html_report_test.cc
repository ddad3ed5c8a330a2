// The page of `plumb report`: text from outside is escaped, the parameter table, chi2 and its
// band, the figure list, and the sections that depend on what was run.
#include "plumb/report/html_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "plumb/estimation/uncertainty.h"
#include "plumb/report/summary.h"
#include "report_test_util.h"

namespace plumb::report {
namespace {

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// The pieces of a page around MakeResult() (dof set to 10), no diagnosis, no figures.
struct PageParts {
  InputSummary input;
  segmentation::SegmentationResult segmentation;
  estimation::CalibrationResult result = testing::MakeResult();
  diagnostics::ResidualAnalysis analysis;
  PageExtras extras;
  PageParts() {
    input.source = "session.csv";
    input.samples = 6450;
    input.rate_hz = 100.0;
    input.duration_s = 64.5;
    input.has_gyro = true;
    segmentation.report.method = "given";
    result.fit.dof = 10;
    extras.command = "plumb report session.csv --out out";
  }
  std::string Page(const diagnostics::Diagnosis* diagnosis = nullptr) const {
    return HtmlReport(input, segmentation, result, analysis, diagnosis, extras);
  }
};

TEST(HtmlReport, EscapesTheFiveSpecialCharacters) {
  EXPECT_EQ(HtmlEscape("<a href=\"x\">Tom & Jerry's</a>"),
            "&lt;a href=&quot;x&quot;&gt;Tom &amp; Jerry&#39;s&lt;/a&gt;");
  EXPECT_EQ(HtmlEscape("plain text 1.5 m/s^2"), "plain text 1.5 m/s^2");
}

TEST(HtmlReport, EscapesFileNamesWarningsAndTheCommand) {
  PageParts parts;
  parts.input.source = "<script>alert(1)</script>.csv";
  parts.input.warnings = {"row 7: <bad> & skipped"};
  parts.extras.command = "plumb report 'a<b>.csv' --out out";
  const std::string page = parts.Page();
  EXPECT_FALSE(Contains(page, "<script>"));
  EXPECT_TRUE(Contains(page, "&lt;script&gt;alert(1)&lt;/script&gt;.csv"));
  EXPECT_TRUE(Contains(page, "row 7: &lt;bad&gt; &amp; skipped"));
  EXPECT_TRUE(Contains(page, "plumb report &#39;a&lt;b&gt;.csv&#39; --out out"));
}

TEST(HtmlReport, ListsEveryParameterWithSigmaOrStatus) {
  PageParts parts;
  const std::string page = parts.Page();
  for (const auto& p : parts.result.calibration.parameters) {
    EXPECT_TRUE(Contains(page, "<td><code>" + p.name + "</code></td>")) << p.name;
  }
  // accel.bias.x: value 0.01 * its index, sigma 1e-3, unit "u<index>".
  EXPECT_TRUE(Contains(page, "<td class=\"num\">&plusmn; 0.001</td>"));
  EXPECT_TRUE(Contains(page, "<span class=\"warn\">unobservable</span>"));
  EXPECT_TRUE(Contains(page, "<span class=\"warn\">fixed</span>"));
}

TEST(HtmlReport, AboveItsBandBothSigmasAndWhatTheyMean) {
  // chi2 12.5 on 10 dof is within the band: one sigma column. chi2 400 on 10 dof (40, more
  // than 3 times the band): the scaled column, sigma * sqrt(40), and the terminal's notes.
  PageParts parts;
  EXPECT_FALSE(Contains(parts.Page(), "scaled sigma"));
  parts.result.fit.chi2 = 400.0;
  const std::string page = parts.Page();
  EXPECT_TRUE(Contains(page, "<th>scaled sigma</th>")) << page;
  char scaled[64];
  std::snprintf(scaled, sizeof scaled, "<td class=\"num\">&plusmn; %.2g</td>", 1e-3 * std::sqrt(40.0));
  EXPECT_TRUE(Contains(page, scaled)) << scaled;
  EXPECT_TRUE(Contains(page, "is above its band"));
  EXPECT_TRUE(Contains(page, "do not trust these parameters to their sigma"));
}

TEST(HtmlReport, ShowsChi2TheRatioAndItsBand) {
  PageParts parts;
  const std::string page = parts.Page();
  EXPECT_TRUE(Contains(page, "12.5 over 18 whitened residuals"));
  EXPECT_TRUE(Contains(page, "<b>1.25</b>"));
  const auto band = estimation::Chi2Band(10);
  char text[160];
  std::snprintf(text, sizeof text,
                "band of a complete model, 1 &plusmn; 3 sqrt(2/dof): %.3g to %.3g", band.first,
                band.second);
  EXPECT_TRUE(Contains(page, text)) << text;
}

// Issue 34 item 9: one meaning of "consistent": the page marks the verdict ok exactly when the
// terminal calls the fit consistent with the noise (estimation::Chi2Band), on both sides of
// either edge.
TEST(HtmlReport, MarksTheVerdictOkExactlyWhenTheTerminalSaysConsistent) {
  const auto band = estimation::Chi2Band(10);
  EXPECT_NEAR(band.second, 1.0 + 3.0 * std::sqrt(0.2), 1e-12);
  EXPECT_EQ(band.first, 0.0);  // 1 - 3 sqrt(0.2) < 0
  for (const double ratio : {0.5, 1.25, 2.3, 2.4, 3.0}) {
    PageParts parts;
    parts.result.fit.chi2 = ratio * parts.result.fit.dof;
    const std::string page = parts.Page();
    const bool consistent = Contains(FitVerdict(parts.result.fit), "consistent with the noise");
    EXPECT_EQ(Contains(page, "<p class=\"ok\">"), consistent) << ratio;
    EXPECT_EQ(consistent, ratio <= band.second) << ratio;
  }
}

TEST(HtmlReport, ShowsUnobservableDirectionsAndDeterminedCombinations) {
  const std::string page = PageParts().Page();
  EXPECT_TRUE(Contains(page, "The data cannot tell apart <code>accel.bias.z</code> and "
                             "<code>accel.matrix.zz</code>: moving them together along "
                             "<code>9.81 accel.bias.z + 1 accel.matrix.zz</code>"));
  EXPECT_TRUE(Contains(page, "<code>accel.bias.z - 9.81 accel.matrix.zz</code>"));
}

TEST(HtmlReport, PutsTheDrawnFiguresInsideThePage) {
  PageParts parts;
  parts.extras.figures = {{"series.svg", "Input time series", "shaded < still",
                           "<svg width=\"10\" height=\"5\"><g id='series-gpPt0'/></svg>"},
                          {"residuals.svg", "Whitened residuals", "dashed: +-3",
                           "<svg width=\"10\" height=\"5\"></svg>"}};
  const std::string page = parts.Page();
  EXPECT_TRUE(Contains(page, "<figure id=\"figure-series\">\n<svg width=\"10\" height=\"5\">"
                             "<g id='series-gpPt0'/></svg>\n<figcaption><b>Input time series."
                             "</b> shaded &lt; still</figcaption></figure>"));
  EXPECT_TRUE(Contains(page, "<figure id=\"figure-residuals\">"));
  EXPECT_FALSE(Contains(page, "No figures"));
  // Nothing the browser would fetch: no image, script, stylesheet or frame by reference.
  for (const char* fetched : {"<img", "<script", "<link", "<iframe", "src=", "url(", "@import"}) {
    EXPECT_FALSE(Contains(page, fetched)) << fetched;
  }
}

TEST(HtmlReport, NamesTheFilesBesideThePageWithoutLinkingThem) {
  PageParts parts;
  parts.extras.files = {"result.json", "figures.gp"};
  const std::string page = parts.Page();
  EXPECT_TRUE(Contains(page, "<li><code>result.json</code></li>"));
  EXPECT_FALSE(Contains(page, "href=\"result.json\""));
}

TEST(HtmlReport, ShowsTheCommandToRunNext) {
  PageParts parts;
  diagnostics::Diagnosis d;
  d.fit = parts.result;
  diagnostics::Candidate best;
  best.effect = "gyro_g_sensitivity";
  best.significant = true;
  d.candidates = {best};
  parts.extras.next_command = "plumb calibrate s.csv --model 'base+gyro_g_sensitivity'";
  const std::string page = parts.Page(&d);
  const std::string block = "<pre class=\"next\">plumb calibrate s.csv --model "
                            "&#39;base+gyro_g_sensitivity&#39;</pre>";
  // In the summary and under the ranking of the missing effects.
  const std::size_t first = page.find(block);
  ASSERT_NE(first, std::string::npos) << page;
  EXPECT_LT(first, page.find("id=\"input\""));
  EXPECT_NE(page.find(block, page.find("id=\"diagnosis\"")), std::string::npos);
  EXPECT_FALSE(Contains(PageParts().Page(&d), "class=\"next\""));  // none given, none shown
}

TEST(HtmlReport, ShowsWhatEachExportWritesAndLeaves) {
  PageParts parts;
  exporter::ExportOutput ardupilot;
  ardupilot.format = "ardupilot";
  ardupilot.text = "# a note in the file\nINS_ACCSCAL_X,0.99\n";
  exporter::ParameterSet set;
  set.parameters = {{"INS_ACCSCAL_X", 0.99, false}};
  ardupilot.parameters = set;
  exporter::ExportReport report;
  report.has_gyro = true;
  report.accel_still.segments = 6;
  report.accel_still.rms = Vec3(0.0980665, 0, 0);  // 10 mg
  report.accel_still.max_abs = Vec3(0.196133, 0, 0);  // 20 mg
  report.gyro_still.rms = Vec3(0, 1e-5, 0);  // 2.06 deg/h
  report.accel_per_input(0, 1) = 0.01;  // 10000 ppm
  report.dropped = {{"gyro_g_sensitivity", {"gyro_g_sensitivity.G.xx"}, {1e-4}, {"rad/s/(m/s^2)"}, true}};
  report.notes = {Notice{"device_id", "a note in the file", {}},
                  Notice{"board_frame", "a note for the page only", {}}};
  ardupilot.report = report;
  parts.extras.exports = {{"ardupilot", ardupilot, ""},
                          {"px4", std::nullopt, "the session does not determine accel.bias.x"}};
  parts.extras.export_commands = {{"ardupilot", "plumb calibrate s.csv --export ardupilot=c.param"}};
  const std::string page = parts.Page();
  EXPECT_TRUE(Contains(page, "<h2 id=\"firmware\">Firmware</h2>"));
  EXPECT_TRUE(Contains(page, "over the 6 still segments"));
  EXPECT_TRUE(Contains(page, "<td>ardupilot</td><td>accelerometer</td><td class=\"num\">10</td>"
                             "<td class=\"num\">0</td><td class=\"num\">0</td><td class=\"num\">20"
                             "</td><td class=\"num\">0</td><td class=\"num\">0</td><td>mg</td>"
                             "<td class=\"num\">1e+04</td>"));
  EXPECT_TRUE(Contains(page, "<td>ardupilot</td><td>gyroscope</td><td class=\"num\">0</td>"
                             "<td class=\"num\">2.06</td>"));
  EXPECT_TRUE(Contains(page, "<pre>plumb calibrate s.csv --export ardupilot=c.param</pre>"));
  EXPECT_TRUE(Contains(page, "gyro_g_sensitivity: gyro_g_sensitivity.G.xx 0.0001 rad/s/(m/s^2)"));
  EXPECT_TRUE(Contains(page, "<li>a note for the page only</li>"));
  EXPECT_FALSE(Contains(page, "<li>a note in the file</li>"));  // the file shows it
  EXPECT_TRUE(Contains(page, "<pre># a note in the file\nINS_ACCSCAL_X,0.99\n</pre>"));
  EXPECT_TRUE(Contains(page, "Not written: the session does not determine accel.bias.x"));
}

TEST(HtmlReport, SaysWhyThereAreNoFigures) {
  PageParts parts;
  parts.extras.figure_notes = {"'gnuplot' was not found on the PATH"};
  const std::string page = parts.Page();
  EXPECT_TRUE(Contains(page, "No figures: &#39;gnuplot&#39; was not found on the PATH"));
  EXPECT_FALSE(Contains(page, "<img"));
}

TEST(HtmlReport, SaysWhenTheDiagnosisWasNotRun) {
  EXPECT_TRUE(Contains(PageParts().Page(), "Not run (--no-diagnose)"));
}

TEST(HtmlReport, ListsTheCandidatesOfTheDiagnosis) {
  PageParts parts;
  diagnostics::Diagnosis d;
  diagnostics::Candidate best;
  best.effect = "gyro_g_sensitivity";
  best.lm = 812.4;
  best.dof = 9;
  best.evidence = 730.1;
  best.significant = true;
  best.refit_drop = 790.2;
  best.refit = estimation::CalibrationResult{};
  best.refit->fit.chi2 = 110.0;
  best.refit->fit.dof = 100;
  best.recommended = true;
  d.fit.fit.chi2 = 900.0;
  d.fit.fit.dof = 109;
  diagnostics::Candidate hidden;
  hidden.effect = "time_offset";
  hidden.identifiable = false;
  diagnostics::Confounding c;
  c.parameter = "time_offset.dt";
  c.excited = false;
  hidden.not_identifiable = {c};
  d.candidates = {best, hidden};
  d.skipped = {{"accel_temperature_bias", "needs a temperature column"}};
  const std::string page = parts.Page(&d);
  EXPECT_TRUE(Contains(page, "<td><code>gyro_g_sensitivity</code></td><td class=\"num\">812</td>"));
  EXPECT_TRUE(Contains(page, "<td class=\"num\">790</td>"));
  EXPECT_TRUE(Contains(page, "Most likely missing: <code>gyro_g_sensitivity</code>"));
  EXPECT_TRUE(Contains(page, "the refit with it has chi2/dof 1.1 against 8.26"));
  EXPECT_TRUE(Contains(page, "<td class=\"num\">1.1</td><td><b>yes</b></td>"));
  EXPECT_TRUE(Contains(page, "time_offset: time_offset.dt is not excited by this data"));
  EXPECT_TRUE(Contains(page, "accel_temperature_bias: needs a temperature column"));
}

// Like with like (issue 34): a significant candidate whose refit has a higher chi2/dof than
// the fit diagnosed is listed but never advised, and the fit it was scored in is named.
TEST(HtmlReport, NeverAdvisesWhatRaisesTheUsersChi2PerDof) {
  PageParts parts;
  diagnostics::Diagnosis d;
  d.fit.fit.chi2 = 127.0;
  d.fit.fit.dof = 103;
  d.fit_with_velocity = estimation::CalibrationResult{};
  d.fit_with_velocity->fit.chi2 = 8400.0;
  d.fit_with_velocity->fit.dof = 400;
  d.fit_with_velocity->fit.velocity_segments = 20;
  diagnostics::Candidate offset;
  offset.effect = "time_offset";
  offset.lm = 8.0;
  offset.dof = 1;
  offset.significant = true;
  offset.with_velocity = true;
  offset.dispersion = 38.1;
  offset.refit_drop = 325.0;
  offset.refit = estimation::CalibrationResult{};
  offset.refit->fit.chi2 = 7620.0;
  offset.refit->fit.dof = 399;
  offset.refit->fit.velocity_segments = 20;
  d.candidates = {offset};
  const std::string page = parts.Page(&d);
  EXPECT_FALSE(Contains(page, "Most likely missing"));
  EXPECT_FALSE(Contains(page, "Next: the refit diagnose advises"));
  EXPECT_TRUE(Contains(page, "Nothing advised: no significant effect of the catalogue lowers"));
  EXPECT_TRUE(Contains(page, "<td class=\"num\">19.1</td><td>no</td>"));
  EXPECT_TRUE(Contains(page, "in the fit with velocity residuals: chi2 8.4e+03 on 400 dof, "
                             "chi2/dof 21."));
  EXPECT_TRUE(Contains(page, "scored in the fit with velocity residuals; LM divided by 38.1"));
}

TEST(HtmlReport, NamesTheWorstRanges) {
  PageParts parts;
  diagnostics::WorstRange w;
  w.name = "still 'x up' 12.0-17.0 s";
  w.residual = diagnostics::ResidualKind::kStillGyro;
  w.axis = 2;
  w.score = 41.5;
  parts.analysis.worst = {w};
  const std::string page = parts.Page();
  EXPECT_TRUE(Contains(page, "<td>still &#39;x up&#39; 12.0-17.0 s</td><td>gyro</td><td>z</td>"
                             "<td class=\"num\">41.5</td>"));
}

TEST(HtmlReport, SaysWhichResultsDependOnAMissingSite) {
  const std::string page = PageParts().Page();  // MakeResult has no site
  EXPECT_TRUE(Contains(page, "none: gravity fixed at 9.80665 m/s^2 and the Earth rate left out"));
}

}  // namespace
}  // namespace plumb::report

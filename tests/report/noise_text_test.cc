// What plumb allan prints and writes, the page's noise section and noise figure: names and units
// of the IEEE terms per sensor, bounds marked, the JSON keys, the figure's data blocks.
#include "plumb/report/noise_text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "plumb/core/units.h"
#include "plumb/report/figures.h"
#include "plumb/report/html_report.h"
#include "report_test_util.h"

namespace plumb::report {
namespace {

using signal::NoiseTermKind;
using signal::Sensor;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Ten minutes at 50 Hz of white noise (1e-3 m/s^2/sqrt(Hz), 1e-4 rad/s/sqrt(Hz)) in two
/// still segments, analysed as plumb allan does.
struct Noise {
  ImuSeries series;
  signal::StillNoise noise;
  Noise() {
    const double dt = 0.02;
    std::mt19937_64 rng(5);
    std::normal_distribution<double> e(0.0, 1.0);
    for (int i = 0; i < 30000; ++i) {
      series.t_s.push_back(1000.0 + i * dt);
      const double a = 1e-3 / std::sqrt(dt), g = 1e-4 / std::sqrt(dt);
      series.acc.push_back(Vec3(a * e(rng), a * e(rng), -9.8 + a * e(rng)).cast<float>());
      series.gyr.push_back(Vec3(g * e(rng), g * e(rng), g * e(rng)).cast<float>());
    }
    StillSegment first, second;
    first.begin = 0, first.end = 20000, first.label = "first";
    second.begin = 21000, second.end = 30000, second.label = "second";
    noise = signal::AnalyseStillNoise(series, {first, second});
  }
};

TEST(NoiseText, LabelsTermsWithTheirUnitsAndDatasheetUnits) {
  const NoiseTermLabel vrw = LabelNoiseTerm(Sensor::kAccel, NoiseTermKind::kWhite, "m/s^2");
  EXPECT_EQ(vrw.name, "velocity random walk");
  EXPECT_EQ(vrw.unit, "m/s^2/sqrt(Hz)");
  EXPECT_EQ(vrw.datasheet_unit, "ug/sqrt(Hz)");
  EXPECT_NEAR(1e-3 * vrw.datasheet_scale, 101.97, 0.01);  // 1e-3 m/s^2 = 102 ug
  const NoiseTermLabel arw = LabelNoiseTerm(Sensor::kGyro, NoiseTermKind::kWhite, "rad/s");
  EXPECT_EQ(arw.name, "angle random walk");
  // 1 deg/sqrt(h) = (pi / 180) / 60 rad/sqrt(s).
  EXPECT_NEAR(units::kRadPerDeg / 60.0 * arw.datasheet_scale, 1.0, 1e-12);
  const NoiseTermLabel bias = LabelNoiseTerm(Sensor::kGyro, NoiseTermKind::kBiasInstability,
                                             "rad/s");
  EXPECT_EQ(bias.datasheet_unit, "deg/h");
  EXPECT_NEAR(bias.datasheet_scale, units::kDegPerHourPerRadPerS, 1e-9);
  const NoiseTermLabel rrw = LabelNoiseTerm(Sensor::kGyro, NoiseTermKind::kRandomWalk, "rad/s");
  EXPECT_EQ(rrw.unit, "rad/s^2/sqrt(Hz)");
  EXPECT_EQ(rrw.datasheet_unit, "deg/h/sqrt(h)");
  EXPECT_NEAR(rrw.datasheet_scale, units::kDegPerHourPerRadPerS * 60.0, 1e-6);
  const NoiseTermLabel arw_acc =
      LabelNoiseTerm(Sensor::kAccel, NoiseTermKind::kRandomWalk, "m/s^2");
  EXPECT_EQ(arw_acc.name, "acceleration random walk");
  EXPECT_EQ(arw_acc.unit, "m/s^3/sqrt(Hz)");
  // Counts: the forms built from the unit, no datasheet unit.
  const NoiseTermLabel counts = LabelNoiseTerm(Sensor::kAccel, NoiseTermKind::kWhite, "counts");
  EXPECT_EQ(counts.unit, "counts/sqrt(Hz)");
  EXPECT_TRUE(counts.datasheet_unit.empty());
  EXPECT_EQ(LabelNoiseTerm(Sensor::kGyro, NoiseTermKind::kQuantisation, "rad/s").unit, "rad");
}

TEST(NoiseText, TableMarksBoundsAndGivesTheFittedRanges) {
  const Noise n;
  const std::string text = StillNoiseText(n.noise);
  EXPECT_TRUE(Contains(text, "still data: 2 segments, 29000 samples, 580 s")) << text;
  EXPECT_TRUE(Contains(text, "accelerometer (m/s^2)")) << text;
  EXPECT_TRUE(Contains(text, "gyroscope (rad/s)")) << text;
  EXPECT_TRUE(Contains(text, "N  angle random walk")) << text;
  EXPECT_TRUE(Contains(text, "< ")) << text;  // B, K, Q, R are bounds on white noise
  EXPECT_TRUE(Contains(text, "(bound only: not in the model)")) << text;
  EXPECT_TRUE(Contains(text, "fitted: x tau 0.02 .. ")) << text;
  EXPECT_FALSE(Contains(text, "MISFIT")) << text;
}

TEST(NoiseText, JsonHasThePointsAndTheTermsOfEveryAxis) {
  const Noise n;
  const nlohmann::json doc = StillNoiseJson(n.noise, n.series);
  EXPECT_EQ(doc["schema_version"], 1);
  EXPECT_EQ(doc["still"]["segments"].size(), 2u);
  EXPECT_EQ(doc["still"]["segments"][1]["label"], "second");
  EXPECT_DOUBLE_EQ(doc["still"]["segments"][1]["t_start_s"].get<double>(), 1420.0);
  EXPECT_NEAR(doc["sample_interval_s"].get<double>(), 0.02, 1e-12);
  EXPECT_NEAR(doc["term_confidence"].get<double>(), 0.95, 1e-12);
  for (const char* sensor : {"accel", "gyro"}) {
    for (const char* axis : {"x", "y", "z"}) {
      const nlohmann::json& a = doc[sensor]["axes"][axis];
      ASSERT_FALSE(a["adev"].empty()) << sensor << axis;
      for (const char* key : {"tau_s", "m", "adev", "lower", "upper", "edf", "noise", "terms"}) {
        EXPECT_TRUE(a["adev"][0].contains(key)) << key;
      }
      for (const char* term : {"Q", "N", "B", "K", "R"}) {
        for (const char* key : {"name", "value", "unit", "resolved", "in_model", "fitted",
                                "upper_bound", "bound_tau_s", "tau_min_s", "tau_max_s"}) {
          EXPECT_TRUE(a["terms"][term].contains(key)) << term << " " << key;
        }
      }
      EXPECT_TRUE(a["terms"]["N"]["resolved"].get<bool>());
      EXPECT_FALSE(a["fit"]["misfit"].get<bool>());
    }
  }
  const double n_gyro = doc["gyro"]["axes"]["y"]["terms"]["N"]["value"].get<double>();
  EXPECT_NEAR(n_gyro / 1e-4, 1.0, 0.03);
  EXPECT_EQ(doc["gyro"]["axes"]["y"]["terms"]["N"]["datasheet"]["unit"], "deg/sqrt(h)");
}

TEST(NoiseText, FigureHasOneDataBlockPerAxisAndAPanelPerSensor) {
  const Noise n;
  FigurePlan plan;
  AddStillNoiseFigure(n.noise, FigureOptions{}, plan);
  ASSERT_EQ(plan.figures.size(), 1u);
  EXPECT_EQ(plan.figures[0].file, "noise.svg");
  EXPECT_EQ(plan.job.outputs, std::vector<std::string>{"noise.svg"});
  ASSERT_EQ(plan.job.data.size(), 1u);
  EXPECT_EQ(plan.job.data[0].name, "noise.csv");
  const std::string& csv = plan.job.data[0].content;
  EXPECT_TRUE(Contains(csv, "# gyroscope z: tau_s,adev,lower,upper,model\n")) << csv;
  EXPECT_TRUE(Contains(plan.job.script, "'noise.csv' index 0 using 1:2:3:4 with yerrorbars"));
  EXPECT_TRUE(Contains(plan.job.script, "'' index 5 using 1:5 with lines"));
  EXPECT_TRUE(Contains(plan.job.script, "set multiplot layout 2,1"));
  EXPECT_TRUE(Contains(plan.job.script, "set logscale xy"));
}

TEST(NoiseText, PageSectionListsTheTermsOrSaysWhyNot) {
  const Noise n;
  InputSummary input;
  segmentation::SegmentationResult seg;
  seg.report.method = "given";
  const estimation::CalibrationResult result = testing::MakeResult();
  const diagnostics::ResidualAnalysis analysis;
  PageExtras extras;
  extras.still_noise_note = "the longest still segment has 5 samples";
  std::string page = HtmlReport(input, seg, result, analysis, nullptr, extras);
  EXPECT_TRUE(Contains(page, "<h2 id=\"noise\">Sensor noise</h2>"));
  EXPECT_TRUE(Contains(page, "Not measured: the longest still segment has 5 samples"));
  extras.still_noise = n.noise;
  page = HtmlReport(input, seg, result, analysis, nullptr, extras);
  EXPECT_TRUE(Contains(page, "velocity random walk"));
  EXPECT_TRUE(Contains(page, "deg/sqrt(h)"));
  EXPECT_TRUE(Contains(page, "&lt; "));  // bounds
  EXPECT_TRUE(Contains(page, "allan.json"));
}

}  // namespace
}  // namespace plumb::report

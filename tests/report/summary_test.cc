// The terminal summaries: the verdict on chi^2/dof, the header, and the detector's finding.
#include "plumb/report/summary.h"

#include <gtest/gtest.h>

#include "plumb/report/version.h"
#include "plumb/report/calibration_text.h"
#include "report_test_util.h"

namespace plumb::report {
namespace {

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

estimation::FitReport Fit(double chi2, int dof) {
  estimation::FitReport f;
  f.chi2 = chi2;
  f.dof = dof;
  return f;
}

TEST(Summary, VerdictCallsChi2NearDofConsistent) {
  // dof 200: the spread of chi2/dof is 0.1, so 1.2 is within 3 sigma.
  EXPECT_TRUE(Contains(FitVerdict(Fit(240.0, 200)), "consistent with the noise"));
}

TEST(Summary, VerdictCallsLargeChi2AMissingEffect) {
  EXPECT_TRUE(Contains(FitVerdict(Fit(400.0, 200)), "miss something"));
}

TEST(Summary, VerdictCallsSmallChi2OverestimatedNoise) {
  EXPECT_TRUE(Contains(FitVerdict(Fit(100.0, 200)), "overestimated"));
}

TEST(Summary, VerdictWithoutDegreesOfFreedomSaysSo) {
  EXPECT_TRUE(Contains(FitVerdict(Fit(0.0, 0)), "cannot be judged"));
}

TEST(Summary, CalibrationSummaryIsHeaderThenFullReport) {
  const auto r = testing::MakeResult();
  const std::string text = CalibrationSummary(r);
  EXPECT_EQ(text.rfind("plumb " + Version() + " calibrate", 0), 0u) << text;
  EXPECT_TRUE(Contains(text, "1 unobservable direction"));
  EXPECT_TRUE(Contains(text, report::FullReport(r)));
}

TEST(Summary, GivenSegmentsNameTheirFile) {
  segmentation::SegmentationResult s;
  s.report.method = "given";
  s.segments.resize(9);
  EXPECT_EQ(SegmentationSummary(s, "poses.csv"), "still segments: 9 given in poses.csv\n");
}

TEST(Summary, DetectedSegmentsShowCountThresholdAndNoise) {
  segmentation::SegmentationResult s;
  s.report.method = "detected";
  s.report.window_s = 1.0;
  s.report.min_still_s = 2.0;
  s.report.notes = {"a long note"};
  s.segments.resize(23);
  s.noise.samples = 500;
  s.noise.acc_sigma = Vec3(0.0123, 0.011, 0.015);
  s.detail.acc_threshold = 1.42;
  const std::string text = SegmentationSummary(s);
  EXPECT_TRUE(Contains(text, "still segments: 23 detected")) << text;
  EXPECT_TRUE(Contains(text, "accel variance ratio 1.42")) << text;
  EXPECT_TRUE(Contains(text, "accel sigma (0.0123, 0.011, 0.015)")) << text;
  EXPECT_FALSE(Contains(text, "a long note"));
  EXPECT_TRUE(Contains(SegmentationSummary(s, "", true), "note: a long note"));
}

}  // namespace
}  // namespace plumb::report

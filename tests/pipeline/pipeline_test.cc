// The steps the front ends share (plumb/pipeline): a study's session template, the segments
// and the fit's inputs, the gate failure's text.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "plumb/core/error.h"
#include "plumb/pipeline/fit_setup.h"
#include "plumb/pipeline/study_template.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"

namespace plumb::pipeline {
namespace {

namespace fs = std::filesystem;

TEST(StudyTemplate, RelativeToTheFolderGiven) {
  const fs::path dir = fs::temp_directory_path() / "plumb_pipeline_template_test";
  fs::create_directories(dir);
  std::ofstream(dir / "session.json") << R"({"model": "base"})";
  study::Study s;
  s.base.template_path = "session.json";
  ReadSessionTemplate(s, dir.string());
  EXPECT_EQ(s.base.template_path, (dir / "session.json").string());
  EXPECT_EQ(s.template_document["model"], "base");

  study::Study absolute;
  absolute.base.template_path = (dir / "session.json").string();
  ReadSessionTemplate(absolute, "/elsewhere");
  EXPECT_EQ(absolute.base.template_path, (dir / "session.json").string());

  study::Study none;
  ReadSessionTemplate(none, dir.string());
  EXPECT_TRUE(none.template_document.is_null());

  study::Study missing;
  missing.base.template_path = "absent.json";
  EXPECT_THROW(ReadSessionTemplate(missing, dir.string()), InputError);
  fs::remove_all(dir);
}

/// A simulated session of six poses, noiseless but for white noise.
Session SixPoses() {
  sim::SimulationOptions o = sim::SimulationOptions::WhiteMems();
  o.rate_hz = 100.0;
  o.seed = 3;
  return sim::Simulate(sim::MultiPose(6, 4.0, 2.0, 3), o).session;
}

TEST(FitSetup, SegmentsGivenOrDetected) {
  const Session session = SixPoses();
  const segmentation::SegmentationResult detected = FindSegments(session.series, {});
  EXPECT_EQ(detected.segments.size(), 6u);

  const fs::path file = fs::temp_directory_path() / "plumb_pipeline_segments.csv";
  std::ofstream(file) << "start,end,label\n10,300,first\n700,900,second\n";
  SegmentRequest given;
  given.segments_path = file.string();
  const segmentation::SegmentationResult read = FindSegments(session.series, given);
  ASSERT_EQ(read.segments.size(), 2u);
  EXPECT_EQ(read.segments[1].begin, 700u);
  fs::remove(file);
}

TEST(FitSetup, RequestBecomesTheFitsInputs) {
  Session session = SixPoses();
  session.warnings = {Notice{"nan_rows_skipped", "from the reader", {}}};
  const segmentation::SegmentationResult seg = FindSegments(session.series, {});
  FitRequest request;
  request.model = model::Model::Parse("base");
  request.temp_ref_c = 30.0;
  request.level_north = true;
  request.options.max_iterations = 17;
  FitSetup none = PrepareFit(session, seg, request);
  EXPECT_FALSE(none.site.known);
  EXPECT_EQ(none.input_warnings, session.warnings);
  EXPECT_TRUE(none.segments.front().known_R_n_b.has_value());
  EXPECT_FALSE(none.segments.back().known_R_n_b.has_value());
  EXPECT_EQ(none.model.t_ref_s, session.series.t_s.front());
  EXPECT_EQ(none.model.temp_ref_c, 30.0);
  EXPECT_EQ(none.options.max_iterations, 17);

  request.site = SiteInput{45.0, 5.0, 200.0, "flags"};
  request.gravity_m_s2 = 9.8;
  const FitSetup fixed = PrepareFit(session, seg, request);
  EXPECT_TRUE(fixed.site.known);
  EXPECT_EQ(fixed.site.g_n.z(), 9.8);
  ASSERT_EQ(fixed.input_warnings.size(), 2u);
  EXPECT_EQ(fixed.input_warnings[1].message,
            "gravity fixed at 9.800000 m/s^2 by FitRequest/CompareOptions::gravity_m_s2 instead "
            "of WGS84 normal gravity");
  EXPECT_EQ(fixed.input_warnings[1].code, "gravity_fixed");
  EXPECT_EQ(fixed.input_warnings[1].options, std::vector<Option>{Option::kGravity});
}

TEST(FitSetup, GateFailureCountsTheGates) {
  estimation::FitReport fit;
  fit.gates = {{"not_converged", ""}};
  EXPECT_EQ(GateFailure(fit, "a.csv"), "the fit of a.csv failed a gate (not_converged)");
  fit.gates.push_back({"saturated", ""});
  EXPECT_EQ(GateFailure(fit, "a.csv"),
            "the fit of a.csv failed 2 gates (not_converged, saturated)");
}

}  // namespace
}  // namespace plumb::pipeline

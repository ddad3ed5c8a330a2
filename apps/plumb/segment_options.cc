// apps/plumb/segment_options.cc — see segment_options.h.
#include "segment_options.h"
#include "progress.h"

#include "validators.h"

namespace plumb::cli {

void AddSegmentOptions(CLI::App* app, SegmentArgs& a) {
  app->add_option("--segments", a.segments_path,
                  "Still segments given in FILE (CSV start_s,end_s[,label] or start,end "
                  "sample indices, or imucal's JSON) instead of detecting them")
      ->type_name("FILE");
  auto* det = app->add_option_group("Still detection", "Finding the still segments");
  det->add_option("--init-still", a.detector.init_still_s,
                  "Length of the still period at the start used for the noise, s (0 = the "
                  "quietest stretch, found automatically)")
      ->check(NonNegative)
      ->capture_default_str();
  det->add_option("--window", a.detector.window_s, "Length of the moving window, s")
      ->check(Positive)
      ->capture_default_str();
  det->add_option("--min-still", a.detector.min_still_s, "Shortest still segment kept, s")
      ->check(NonNegative)
      ->capture_default_str();
  det->add_option("--false-alarm", a.detector.false_alarm,
                  "Probability that a still window is called moving, all tests together "
                  "(0..0.5)")
      ->check(CLI::Range(1e-12, 0.5))
      ->capture_default_str();
  det->add_flag("--still-accel-only", a.still_accel_only,
                "Detect still segments from the accelerometer alone (keeps poses whose "
                "gyroscope shows jitter or slow turns)");
  app->add_flag("-v,--verbose", a.verbose, "Print the still detector's notes too");
}

segmentation::SegmentationResult FindSegments(const ImuSeries& series, const SegmentArgs& a) {
  if (a.segments_path.empty()) {
    Progress::Of().Stage("finding still segments in " + std::to_string(series.size()) + " samples");
  }
  return pipeline::FindSegments(series, a);
}

}  // namespace plumb::cli

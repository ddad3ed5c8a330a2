// plumb calibrate INPUT... — fit the error model to a recorded session (SPEC sections 3, 6).
//
// Reads the inputs (input_options.h), finds the still segments (detected, or --segments),
// resolves the site (flags, else the log's GPS, else none), fits, prints the detector's
// finding and the calibration report, and writes the JSON document when asked.
#include <iostream>
#include <optional>

#include "commands.h"
#include "input_options.h"
#include "paper_methods.h"
#include "plumb/core/error.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/io/segments_file.h"
#include "plumb/model/model.h"
#include "plumb/report/json_report.h"
#include "plumb/report/summary.h"
#include "plumb/segmentation/given_segments.h"
#include "plumb/segmentation/still_detector.h"
#include "site_options.h"

namespace plumb::cli {
namespace {

struct CalibrateArgs {
  InputArgs input;
  SiteArgs site;
  std::string method = "generalized";
  std::string model = "base";
  double gravity_m_s2 = 0.0;  ///< --gravity: fixed gravity magnitude, m/s^2, > 0
  CLI::Option* gravity = nullptr;
  std::string json_path;      ///< --json FILE
  std::string segments_path;  ///< --segments FILE
  bool strict = false;        ///< fail when the data cannot determine every parameter
  double heading_deg = 0.0;   ///< --heading: first still pose's x axis from north, degrees
  CLI::Option* heading = nullptr;
  bool level_north = false;       ///< first still pose is level with x north (known attitude)
  double temp_ref_c = 25.0;       ///< reference temperature of the temperature terms, degC
  bool still_accel_only = false;  ///< detect still segments from the accelerometer alone
  bool verbose = false;           ///< print the detector's notes
  segmentation::StillDetectorOptions detector;
};

class CalibrateCommand : public Command {
 public:
  explicit CalibrateCommand(CLI::App& parent) {
    app_ = parent.add_subcommand("calibrate",
                                 "Calibrate the accelerometer and gyroscope from a session of "
                                 "still poses joined by turns");
    CalibrateArgs& a = args_;
    AddInputOptions(app_, a.input);
    app_->add_option("--method", a.method,
                     "Calibration method: generalized (least squares), or the seed paper's "
                     "procedures as printed: paper-benchmark (section 4, six poses and turns "
                     "about each axis), paper-static (section 5, one level x-north minute; "
                     "needs --lat --lon)")
        ->check(CLI::IsMember({"generalized", "paper-benchmark", "paper-static"}))
        ->capture_default_str();
    app_->add_option("--model", a.model,
                     "Error model spec: base, paper, or base+EFFECT[:OPTION]+... "
                     "(see 'plumb effects')")
        ->capture_default_str();
    AddSiteOptions(app_, a.site);
    a.gravity = app_->add_option("--gravity", a.gravity_m_s2,
                                 "Use this fixed gravity magnitude, m/s^2, instead of WGS84 "
                                 "normal gravity at the site (only when you know better)")
                    ->check(CLI::PositiveNumber);
    app_->add_option("--json", a.json_path, "Write the result as JSON to FILE (atomically)")
        ->type_name("FILE");
    app_->add_option("--segments", a.segments_path,
                     "Still segments given in FILE (CSV start_s,end_s[,label] or start,end "
                     "sample indices, or imucal's JSON) instead of detecting them")
        ->type_name("FILE");
    app_->add_flag("--strict", a.strict,
                   "Fail (exit 1) when the data cannot determine every parameter of the model, "
                   "instead of reporting the unobservable directions");
    a.heading = app_->add_option("--heading", a.heading_deg,
                                 "Heading of the first still pose's x axis from north, degrees "
                                 "(0 = x north); otherwise the heading is an arbitrary gauge");
    auto* level = app_->add_flag("--level-north", a.level_north,
                                 "The first still pose is level with x north (the paper's pose): "
                                 "its attitude is known and held");
    level->excludes(a.heading);
    app_->add_option("--temp-ref", a.temp_ref_c,
                     "Reference temperature of the temperature terms, degC")
        ->capture_default_str();
    auto* det = app_->add_option_group("Still detection", "Finding the still segments");
    det->add_option("--init-still", a.detector.init_still_s,
                    "Length of the still period at the start used for the noise, s (0 = the "
                    "quietest stretch, found automatically)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    det->add_option("--window", a.detector.window_s, "Length of the moving window, s")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    det->add_option("--min-still", a.detector.min_still_s, "Shortest still segment kept, s")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    det->add_option("--false-alarm", a.detector.false_alarm,
                    "Probability that a still window is called moving, all tests together "
                    "(0..0.5)")
        ->check(CLI::Range(1e-12, 0.5))
        ->capture_default_str();
    det->add_flag("--still-accel-only", a.still_accel_only,
                  "Detect still segments from the accelerometer alone (keeps poses whose "
                  "gyroscope shows jitter or slow turns)");
    app_->add_flag("-v,--verbose", a.verbose, "Print the still detector's notes too");
  }

  int Run() override {
    const CalibrateArgs& a = args_;
    Session session = ReadInputs(a.input);
    const ImuSeries& series = session.series;
    if (series.empty()) throw Error(session.source + ": no samples");
    if (a.method != "generalized") return RunPaperMethod(session);

    const segmentation::SegmentationResult seg = FindSegments(series);
    std::vector<StillSegment> segments = seg.segments;
    if (a.level_north && !segments.empty()) segments.front().known_R_n_b = Quat::Identity();

    std::optional<double> gravity;
    if (a.gravity->count() > 0) gravity = a.gravity_m_s2;
    const geo::Site site = ResolveSite(a.site, session.site, gravity);
    if (gravity && site.known) {
      session.warnings.push_back("gravity fixed at " + std::to_string(*gravity) +
                                 " m/s^2 by --gravity instead of WGS84 normal gravity");
    }

    model::Model model = model::Model::Parse(a.model);
    model.t_ref_s = series.t_s.front();
    model.temp_ref_c = a.temp_ref_c;

    estimation::CalibrationOptions options;
    options.method = a.method;
    if (a.heading->count() > 0) options.first_heading_deg = a.heading_deg;
    if (a.strict) options.on_insufficient = estimation::InsufficientData::kError;

    std::cout << session.source << ": " << series.size() << " samples, " << series.duration_s()
              << " s" << (series.has_gyro() ? "" : ", no gyroscope")
              << (series.has_temperature() ? ", with temperature" : "") << "\n";
    for (const auto& w : session.warnings) std::cout << "warning: " << w << "\n";
    std::cout << report::SegmentationSummary(seg, a.segments_path, a.verbose) << "\n";

    const estimation::CalibrationResult result =
        estimation::Calibrate(series, segments, model, site, options);
    std::cout << report::CalibrationSummary(result);

    if (!a.json_path.empty()) {
      std::vector<std::string> inputs = a.input.inputs;
      if (!a.input.acc_file.empty()) inputs.push_back(a.input.acc_file + "," + a.input.gyr_file);
      report::WriteJson(a.json_path,
                        report::CalibrationJson(result, seg, inputs, session.warnings));
      std::cout << "wrote " << a.json_path << "\n";
    }
    return 0;
  }

 private:
  /// --method paper-benchmark | paper-static (plumb/paper; paper_methods.h).
  int RunPaperMethod(const Session& session) const {
    const CalibrateArgs& a = args_;
    std::optional<double> gravity;
    if (a.gravity->count() > 0) gravity = a.gravity_m_s2;
    const geo::Site site = ResolveSite(a.site, session.site, gravity);
    std::cout << session.source << ": " << session.series.size() << " samples, "
              << session.series.duration_s() << " s\n";
    for (const auto& w : session.warnings) std::cout << "warning: " << w << "\n";
    if (a.method == "paper-static") {
      // The paper's minute is the whole record; a section file picks its first still section.
      std::size_t begin = 0;
      std::size_t end = session.series.size();
      if (!a.segments_path.empty()) {
        const auto given = io::ReadSegments(a.segments_path, session.series);
        if (given.empty()) throw UsageError(a.segments_path + ": no still section");
        begin = given.front().begin;
        end = given.front().end;
      }
      return RunPaperStatic(session, begin, end, site, a.json_path);
    }
    std::vector<StillSegment> still;
    std::vector<paper::MotionRange> motion;
    if (!a.segments_path.empty()) {
      const io::GivenSections given = io::ReadGivenSections(a.segments_path, session.series);
      still = given.still;
      for (const auto& m : given.motion) motion.push_back({m.begin, m.end, m.label});
    } else {
      const segmentation::SegmentationResult seg = FindSegments(session.series);
      std::cout << report::SegmentationSummary(seg, a.segments_path, a.verbose) << "\n";
      still = seg.segments;
    }
    return RunPaperBenchmark(session, still, motion, site, a.json_path);
  }

  segmentation::SegmentationResult FindSegments(const ImuSeries& series) const {
    if (!args_.segments_path.empty()) {
      return segmentation::UseGivenSegments(series, io::ReadSegments(args_.segments_path, series));
    }
    segmentation::StillDetectorOptions detector = args_.detector;
    detector.use_gyro = !args_.still_accel_only;
    detector.acc_unit = series.acc_unit;
    detector.gyr_unit = series.gyr_unit;
    return segmentation::DetectStillSegments(series, detector);
  }

  CalibrateArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeCalibrateCommand(CLI::App& parent) {
  return std::make_unique<CalibrateCommand>(parent);
}

}  // namespace plumb::cli

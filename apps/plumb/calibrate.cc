// plumb calibrate INPUT... — fit the error model to a recorded session (SPEC sections 3, 6).
//
// Reads the inputs (input_options.h), finds the still segments (detected, or --segments),
// resolves the site (flags, else the log's GPS, else none), fits, prints the detector's
// finding and the calibration report, and writes the JSON document when asked.
#include <algorithm>
#include <iostream>
#include <optional>

#include "commands.h"
#include "validators.h"
#include "export_options.h"
#include "fit_options.h"
#include "input_options.h"
#include "jobs.h"
#include "paper_methods.h"
#include "plumb/core/error.h"
#include "plumb/estimation/board_agreement.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/io/text/segments_file.h"
#include "plumb/model/model.h"
#include "plumb/report/board_agreement_text.h"
#include "plumb/report/json_report.h"
#include "plumb/report/summary.h"
#include "plumb/segmentation/given_segments.h"
#include "plumb/segmentation/still_detector.h"
#include "segment_options.h"
#include "site_options.h"
#include "json_output.h"

namespace plumb::cli {
namespace {

struct CalibrateArgs {
  InputArgs input;
  SiteArgs site;
  std::string method = "generalized";
  FitArgs fit;                ///< --model, --strict, --heading, --level-north, --temp-ref
  std::string json_path;      ///< --json FILE
  SegmentArgs segments;       ///< --segments FILE or the still detector's options
  std::string baseline;           ///< --baseline SPEC: also fit this model, side by side
  ExportArgs exports;             ///< --export FORMAT=FILE, --export-imu, --kalibr-topic
  int jobs = 0;                   ///< --jobs N: threads for the motion residuals (0: every core)
};

class CalibrateCommand : public Command {
 public:
  explicit CalibrateCommand(CLI::App& parent) {
    app_ = parent.add_subcommand("calibrate",
                                 "Calibrate the accelerometer and gyroscope from a session of "
                                 "still poses joined by turns");
    app_->footer("Example (the bundled session: the result as JSON and ArduPilot parameters):\n  plumb calibrate data/mikoff/imu0.log --columns ax,ay,az,gx,gy,gz --rate 100 --json cal.json --export ardupilot=cal.param");
    CalibrateArgs& a = args_;
    AddInputOptions(app_, a.input, true);
    app_->add_option("--method", a.method,
                     "Calibration method: generalized (least squares), or the seed paper's "
                     "procedures as printed: paper-benchmark (section 4, six poses and turns "
                     "about each axis), paper-static (section 5, one level x-north minute; "
                     "needs --lat --lon)")
        ->check(CLI::IsMember({"generalized", "paper-benchmark", "paper-static"}))
        ->capture_default_str();
    AddModelOption(app_, a.fit, true);
    AddSiteOptions(app_, a.site);
    AddGravityOption(app_, a.site);
    app_->add_option("--json", a.json_path, "Write the result as JSON to FILE (atomically; - for stdout, the text then on stderr)")
        ->type_name("FILE");
    AddFitOptions(app_, a.fit);
    app_->add_option("--baseline", a.baseline,
                     "Also fit this model spec (e.g. base) on the same segments and print both "
                     "fits side by side: chi2/dof, per-axis RMS, and the parameters the model "
                     "adds, with sigma (the error falling as an effect is added)")
        ->type_name("SPEC");
    AddSegmentOptions(app_, a.segments);
    AddExportOptions(app_, a.exports);
    app_->add_option("--jobs", a.jobs,
                     "Threads for reading (a .bin, .tlog or .ulg of 32 MiB or more in two parts) and the motion "
                     "residuals' integration (default 0: every core); the result is the same "
                     "bit for bit")
        ->check(Jobs)
        ->capture_default_str();
  }

  FileRoles Files() const override {
    const CalibrateArgs& a = args_;
    FileRoles roles;
    AddFitInputFiles(a.input, a.segments.segments_path, a.fit, roles);
    roles.output_files.push_back({"--json", a.json_path});
    for (const ExportRequest& e : ParseExports(a.exports)) {
      roles.output_files.push_back({"--export " + e.format, e.path});
    }
    return roles;
  }

  int Run() override {
    const CalibrateArgs& a = args_;
    const TextAsideForJson text_aside(a.json_path);
    const std::vector<ExportRequest> exports = ParseExports(a.exports);
    if (!exports.empty() && a.method != "generalized") {
      throw UsageError("--export needs --method generalized (plumb's forward model)");
    }
    const bool firmware = std::any_of(exports.begin(), exports.end(),
                                      [](const ExportRequest& r) { return r.format != "kalibr"; });
    if (firmware && a.input.as_logged) {
      throw UsageError("--export with --as-logged: the samples keep the log's INS_* correction, "
                       "so exported parameters would replace it instead of adding to it; drop "
                       "--as-logged so that plumb calibrates the sensor's own output");
    }
    Session session = ReadInputs(a.input, a.jobs);
    const ImuSeries& series = session.series;
    if (a.method != "generalized") return RunPaperMethod(session);
    if (!exports.empty()) CheckExportable(series);
    if (firmware && !session.firmware_left.empty()) {
      std::string left;
      for (const std::string& l : session.firmware_left) left += "\n  " + l;
      throw Error("--export: the samples still carry corrections the flight controller "
                  "applied and plumb could not undo:" + left +
                  "\nparameters calibrated from them would replace those corrections instead "
                  "of adding to them; export kalibr only, or use a log whose parameters state "
                  "the correction");
    }

    const segmentation::SegmentationResult seg = FindSegments(series, a.segments);
    FitSetup fit = PrepareFit(session, seg, a.site, a.fit, a.input);
    const std::vector<StillSegment>& segments = fit.segments;
    const geo::Site& site = fit.site;
    const model::Model& model = fit.model;
    estimation::CalibrationOptions& options = fit.options;
    options.method = a.method;
    options.run_jobs = ParallelJobs(a.jobs);
    PrintSession(session);
    std::cout << report::SegmentationSummary(seg, a.segments.segments_path, a.segments.verbose) << "\n";

    const estimation::CalibrationResult result = CalibrateWithProgress(session, fit);
    std::cout << report::CalibrationSummary(result, session.source);
    const std::vector<estimation::ImuAgreement> agreement =
        estimation::BoardAgreement(result, series, session.other_imus);
    if (!agreement.empty()) std::cout << "\n" << report::BoardAgreementText(agreement);
    PrintWarnings(result.fit.warnings);
    std::optional<estimation::CalibrationResult> baseline;
    if (!a.baseline.empty()) {
      model::Model before = ParseModelOption("--baseline", a.baseline);
      before.t_ref_s = model.t_ref_s;
      before.temp_ref_c = model.temp_ref_c;
      estimation::CalibrationOptions same = options;  // the same residuals in both fits
      same.accel_in_motion = result.fit.velocity_segments > 0;
      // With the board, the board again: its IMUs without a model of their own take --baseline.
      baseline = estimation::CalibrateBoard(series, session.other_imus, segments, before, site,
                                            same, fit.board_models);
      std::cout << "\n" << report::BeforeAfterSummary(*baseline, result);
    }

    if (const int code = StrictGateExit(result.fit, session.source, a.fit.strict)) return code;
    CheckGatesForExport(exports, a.exports, result.fit, session.source);
    nlohmann::json exported;
    if (!exports.empty()) {
      exported = RunExports(exports, a.exports, a.input.imu, result, session, std::cout);
    }

    if (!a.json_path.empty()) {
      nlohmann::json doc = report::CalibrationJson(result, seg, InputNames(), session.warnings);
      if (baseline) {
        doc["baseline"] = {{"model", baseline->calibration.model.spec()},
                           {"fit", report::ToJson(*baseline)["fit"]},
                           {"chi2_drop", baseline->fit.chi2 - result.fit.chi2}};
      }
      if (!exports.empty()) doc["export"] = exported;
      if (!agreement.empty()) doc["board_agreement"] = report::BoardAgreementJson(agreement);
      WriteJsonOutput(a.json_path, doc);
    }
    return 0;
  }

 private:
  /// --method paper-benchmark | paper-static (plumb/paper; paper_methods.h).
  int RunPaperMethod(const Session& session) const {
    const CalibrateArgs& a = args_;
    const std::optional<double> gravity = a.site.fixed_gravity();
    const geo::Site site = ResolveSite(a.site, session.site, gravity);
    std::cout << session.source << ": " << session.series.size() << " samples, "
              << session.series.duration_s() << " s\n";
    PrintWarnings(session.warnings);
    if (a.method == "paper-static") {
      // The paper's minute is the whole record; a section file picks its first still section.
      std::size_t begin = 0;
      std::size_t end = session.series.size();
      if (!a.segments.segments_path.empty()) {
        const auto given = io::ReadSegments(a.segments.segments_path, session.series);
        if (given.empty()) throw UsageError(a.segments.segments_path + ": no still section");
        begin = given.front().begin;
        end = given.front().end;
      }
      return RunPaperStatic(session, begin, end, site, InputNames(), a.json_path, a.fit.strict);
    }
    std::vector<StillSegment> still;
    std::vector<paper::MotionRange> motion;
    if (!a.segments.segments_path.empty()) {
      const io::GivenSections given = io::ReadGivenSections(a.segments.segments_path, session.series);
      still = given.still;
      for (const auto& m : given.motion) motion.push_back({m.begin, m.end, m.label});
    } else {
      const segmentation::SegmentationResult seg = FindSegments(session.series, a.segments);
      std::cout << report::SegmentationSummary(seg, a.segments.segments_path, a.segments.verbose) << "\n";
      still = seg.segments;
    }
    return RunPaperBenchmark(session, still, motion, site, InputNames(), a.json_path,
                             a.fit.strict);
  }

  /// The input files as given, a two-file input as "acc,gyr" (the document's "inputs").
  std::vector<std::string> InputNames() const {
    const CalibrateArgs& a = args_;
    std::vector<std::string> inputs = a.input.inputs;
    if (!a.input.acc_file.empty()) inputs.push_back(a.input.acc_file + "," + a.input.gyr_file);
    return inputs;
  }

  CalibrateArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeCalibrateCommand(CLI::App& parent) {
  return std::make_unique<CalibrateCommand>(parent);
}

}  // namespace plumb::cli

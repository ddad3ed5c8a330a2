// plumb diagnose INPUT... — which catalogue effects is the model missing (SPEC section 5)?
//
// Reads the inputs and finds the still segments as calibrate does, fits the model, runs the
// score test for every catalogue effect not in it (plumb/diagnostics/diagnose.h), refits the
// best significant ones, prints the ranking and the before/after of the best, and writes the
// JSON of SPEC section 6 when asked.
#include <iomanip>
#include <iostream>
#include <sstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "validators.h"
#include "jobs.h"
#include "progress.h"
#include "commands.h"
#include "fit_options.h"
#include "input_options.h"
#include "plumb/core/error.h"
#include "plumb/diagnostics/board_diagnosis.h"
#include "plumb/diagnostics/diagnose.h"
#include "plumb/diagnostics/residual_analysis.h"
#include "plumb/io/common/atomic_file.h"
#include "plumb/report/board_diagnosis_text.h"
#include "plumb/report/diagnosis_json.h"
#include "plumb/report/json_report.h"
#include "plumb/report/summary.h"
#include "plumb/report/diagnosis_text.h"
#include "plumb/report/time_base_text.h"
#include "plumb/signal/time_base.h"
#include "segment_options.h"
#include "site_options.h"
#include "json_output.h"

namespace plumb::cli {
namespace {

struct DiagnoseArgs {
  InputArgs input;
  SiteArgs site;
  SegmentArgs segments;
  FitArgs fit;                          ///< --model, --heading, --temp-ref (fit_options.h)
  std::string json_path;                ///< --json FILE
  std::string residuals_path;           ///< --residuals FILE: per-sample residuals, CSV
  double significance = 0.01;           ///< level of the score test, (0, 0.5)
  int confirm = 3;                      ///< refit the best N significant candidates, >= 0
  int jobs = 0;                         ///< --jobs N: refits at once (0: every core)
  std::vector<std::string> candidates;  ///< --candidates: effect names (default: catalogue)
};

class DiagnoseCommand : public Command {
 public:
  explicit DiagnoseCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "diagnose",
        "Find which effects of the catalogue the model is missing: the score test of every "
        "effect not in the model, ranked, the best confirmed by refitting");
    app_->footer("Example (which effect the base model misses on the bundled session):\n  plumb diagnose data/mikoff/imu0.log --columns ax,ay,az,gx,gy,gz --rate 100 --json diagnosis.json");
    DiagnoseArgs& a = args_;
    AddInputOptions(app_, a.input, true);
    app_->add_option("--model", a.fit.model, "The model to diagnose (a spec, see 'plumb effects')")
        ->capture_default_str();
    AddImuModelOption(app_, a.fit);
    AddSiteOptions(app_, a.site);
    AddGravityOption(app_, a.site);
    app_->add_option("--json", a.json_path, "Write the diagnosis as JSON to FILE (atomically; - for stdout, the text then on stderr)")
        ->type_name("FILE");
    app_->add_option("--residuals", a.residuals_path,
                     "Write the per-sample still residuals of the model's fit as CSV to FILE "
                     "(time, segment, measured minus predicted and normalised, per axis)")
        ->type_name("FILE");
    app_->add_option("--significance", a.significance,
                     "Level of the score test: the chance that an effect which is not missing "
                     "is called significant")
        ->check(CLI::Range(1e-12, 0.5))
        ->capture_default_str();
    app_->add_option("--confirm", a.confirm,
                     "Refit the model with each of the best N significant effects (the actual "
                     "fall of chi2)")
        ->check(NonNegative)
        ->capture_default_str();
    app_->add_option("--jobs", a.jobs,
                     "The two probe fits, then the refits, in parallel, each on one core "
                     "(the first refits while the second probe fit runs; default: every "
                     "core), and a .bin, .tlog or .ulg of 32 MiB or more read in two parts; the result is the "
                     "same whatever N")
        ->check(Jobs);
    app_->add_option("--candidates", a.candidates,
                     "Test only these effects (NAME or NAME:OPTION, comma-separated); default: "
                     "every catalogue effect not in the model")
        ->delimiter(',');
    a.fit.heading = app_->add_option("--heading", a.fit.heading_deg,
                                 "Heading of the first still pose's x axis from north, degrees")
                     ->check(CLI::Range(-360.0, 360.0));
    app_->add_option("--temp-ref", a.fit.temp_ref_c,
                     "Reference temperature of the temperature terms, degC")
        ->check(CLI::Range(-100.0, 200.0))
        ->capture_default_str();
    AddSegmentOptions(app_, a.segments);
  }

  FileRoles Files() const override {
    const DiagnoseArgs& a = args_;
    FileRoles roles;
    AddFitInputFiles(a.input, a.segments.segments_path, a.fit, roles);
    roles.output_files.push_back({"--json", a.json_path});
    roles.output_files.push_back({"--residuals", a.residuals_path});
    return roles;
  }

  int Run() override {
    const DiagnoseArgs& a = args_;
    const TextAsideForJson text_aside(a.json_path);
    Session session = ReadInputs(a.input, a.jobs);
    const ImuSeries& series = session.series;
    const segmentation::SegmentationResult seg = FindSegments(series, a.segments);
    const FitSetup fit = PrepareFit(session, seg, a.site, a.fit, a.input);
    const geo::Site& site = fit.site;
    const model::Model& model = fit.model;
    diagnostics::DiagnoseOptions options;
    options.significance = a.significance;
    options.confirm = a.confirm;
    options.candidates = a.candidates;
    options.calibration = fit.options;
    options.calibration.method = "generalized";
    options.on_stage = [](const std::string& stage) { Progress::Of().Stage(stage); };
    options.run_jobs = ParallelJobs(a.jobs);
    options.calibration.run_jobs = options.run_jobs;  // the probe fit's motion residuals

    PrintSession(session);
    const signal::TimeBase time_base = signal::AnalyseTimeBase(series.t_s);
    std::cout << report::TimeBaseLine(time_base);
    std::cout << report::SegmentationSummary(seg, a.segments.segments_path, a.segments.verbose)
              << "\n";
    diagnostics::ResidualAnalysisOptions ra_options;
    ra_options.significance = a.significance;
    if (!session.other_imus.empty()) {
      RunBoard(session, seg.segments, fit, options, ra_options, time_base);
      return 0;
    }
    const diagnostics::Diagnosis d =
        diagnostics::Diagnose(series, seg.segments, model, site, options);
    const diagnostics::ResidualAnalysis ra = diagnostics::AnalyseResiduals(series, d.fit, ra_options);
    std::cout << "plumb diagnose: ";
    PrintDiagnosis(d, ra, session.source);
    PrintWarnings(d.fit.fit.warnings);

    if (!a.json_path.empty()) {
      nlohmann::json doc = report::DiagnosisJson(d, ra);
      doc["time_base"] = report::TimeBaseJson(time_base);
      WriteJsonOutput(a.json_path, doc);
    }
    WriteResiduals(ra);
    return 0;
  }

 private:
  /// The verdict, gates, residual analysis and candidates of one diagnosis, and its refit
  /// advised (else the best one made) before and after.
  static void PrintDiagnosis(const diagnostics::Diagnosis& d,
                             const diagnostics::ResidualAnalysis& ra, const std::string& source) {
    std::cout << report::FitVerdict(d.fit.fit) << "\n"
              << report::GateLines(d.fit.fit, source) << report::ResidualAnalysisText(ra)
              << report::DiagnosisText(d);
    const diagnostics::Candidate* shown = diagnostics::Recommended(d);
    if (shown == nullptr) shown = diagnostics::BestRefitted(d);
    if (shown != nullptr) {
      std::cout << "\n" << report::BeforeAfterSummary(d.fit, *shown->refit);
    }
  }

  /// --imus: the board's IMUs each alone, then together (diagnostics/board_diagnosis.h).
  void RunBoard(const Session& session, const std::vector<StillSegment>& segments,
                const FitSetup& fit, const diagnostics::DiagnoseOptions& options,
                const diagnostics::ResidualAnalysisOptions& ra_options,
                const signal::TimeBase& time_base) const {
    const diagnostics::BoardDiagnosis d =
        diagnostics::DiagnoseBoard(session.series, session.other_imus, segments, fit.model,
                                   fit.site, options, fit.board_models);
    std::vector<diagnostics::ResidualAnalysis> analyses;
    for (std::size_t k = 0; k < d.imus.size(); ++k) {
      const ImuSeries& series = k == 0 ? session.series : session.other_imus[k - 1].series;
      analyses.push_back(diagnostics::AnalyseResiduals(series, d.imus[k].diagnosis.fit, ra_options));
    }
    std::cout << "plumb diagnose: " << report::BoardDiagnosisSummary(d);
    for (std::size_t k = 0; k < d.imus.size(); ++k) {
      std::cout << "\n" << report::BoardImuLabel(k, d.imus[k].name, d.imus[k].instance) << " alone: ";
      PrintDiagnosis(d.imus[k].diagnosis, analyses[k], session.source);
    }
    std::cout << "\nall IMUs together: " << report::FitVerdict(d.board.fit) << "\n"
              << report::GateLines(d.board.fit, session.source);
    PrintWarnings(d.board.fit.warnings);
    if (!args_.json_path.empty()) {
      nlohmann::json doc = report::BoardDiagnosisJson(d, analyses);
      doc["time_base"] = report::TimeBaseJson(time_base);
      WriteJsonOutput(args_.json_path, doc);
    }
    WriteResiduals(analyses.front());
  }

  /// --residuals: IMU 0's per-sample residuals.
  void WriteResiduals(const diagnostics::ResidualAnalysis& ra) const {
    if (args_.residuals_path.empty()) return;
    io::WriteFileAtomic(args_.residuals_path, report::ResidualsCsv(ra.samples));
    std::cout << "wrote " << args_.residuals_path << "\n";
  }

  DiagnoseArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeDiagnoseCommand(CLI::App& parent) {
  return std::make_unique<DiagnoseCommand>(parent);
}

}  // namespace plumb::cli

// plumb report INPUT... --out DIR — one page that says what was calibrated and how well
// (plumb report --study SWEEP_DIR --out DIR: the page of a sensitivity study instead)
// (SPEC section 6): DIR/index.html, a page that stands alone: its figures (SVG, drawn by
// gnuplot) are inside it, it names no other file and makes no request. Beside it, for other
// programs: result.json (calibrate's JSON), diagnose.json, allan.json (plumb allan's JSON on
// the fit's still segments), residuals.csv, figures.gp and the CSV files it draws from
// (`gnuplot figures.gp` there redraws the SVGs).
//
// Reads the inputs, finds the still segments and resolves the site exactly as calibrate does
// (the same options), fits, runs diagnose's ranking of the missing-effect catalogue unless
// --no-diagnose, compares the fit with the measurements (plumb/diagnostics), draws the
// figures (plumb/report/gnuplot.h) and writes the page (plumb/report/html_report.h). Every
// file is written atomically. Without gnuplot the page is written without figures, says why,
// and the command warns on stderr and exits 0: figures.gp and its data stay in DIR, to be
// drawn later with `gnuplot figures.gp` there.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>

#include "validators.h"
#include "commands.h"
#include "jobs.h"
#include "progress.h"
#include "fit_options.h"
#include "input_options.h"
#include "plumb/core/error.h"
#include "plumb/diagnostics/board_diagnosis.h"
#include "plumb/diagnostics/diagnose.h"
#include "plumb/estimation/board_agreement.h"
#include "plumb/diagnostics/residual_analysis.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/export/export.h"
#include "plumb/io/common/atomic_file.h"
#include "plumb/model/model.h"
#include "plumb/report/board_diagnosis_text.h"
#include "plumb/report/diagnosis_json.h"
#include "plumb/report/figures.h"
#include "plumb/report/gnuplot.h"
#include "plumb/report/html_report.h"
#include "plumb/report/json_report.h"
#include "plumb/report/noise_text.h"
#include "plumb/report/summary.h"
#include "plumb/report/diagnosis_text.h"
#include "plumb/signal/noise_terms.h"
#include "plumb/study/study.h"
#include "segment_options.h"
#include "study_files.h"
#include "site_options.h"

namespace plumb::cli {
namespace {

struct ReportArgs {
  InputArgs input;
  SiteArgs site;
  SegmentArgs segments;
  FitArgs fit;                      ///< --model, --strict, --heading, --level-north, --temp-ref
  std::string out_dir;              ///< --out DIR: created when missing
  bool diagnose = true;             ///< --diagnose / --no-diagnose
  double significance = 0.01;       ///< level of the score test, (0, 0.5)
  int confirm = 3;                  ///< refit the best N significant candidates, >= 0
  int jobs = 0;                     ///< --jobs N: diagnose's refits at once (0: every core)
  bool no_figures = false;          ///< --no-figures: do not draw (nor write figure data)
  std::string gnuplot = "gnuplot";  ///< --gnuplot PROGRAM
  std::string study;                ///< --study DIR: the page of a plumb sweep folder instead
};

/// A report's folder is replaced whole (io::StagedFolder): it must be new, empty, or a page
/// plumb wrote before (its index.html says so), never a folder of the user's other files.
void CheckReplaceable(const std::string& out_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(out_dir, ec)) return;
  if (!fs::is_directory(out_dir, ec)) throw UsageError("--out " + out_dir + " exists and is not a folder");
  if (fs::is_empty(out_dir, ec)) return;
  std::ifstream index(fs::path(out_dir) / "index.html");
  std::string head(4096, '\0');
  index.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(index.gcount()));
  const bool plumb_page = head.find("<meta name=\"generator\" content=\"plumb") != std::string::npos ||
                          head.find("<title>plumb report: ") != std::string::npos ||
                          head.find("<title>plumb sweep: ") != std::string::npos;
  if (!plumb_page) {
    throw UsageError("--out " + out_dir + " holds files that are not a plumb report's, and a "
                     "report replaces its folder whole: give a new or empty folder; nothing "
                     "was written");
  }
}

/// `text` quoted for a POSIX shell when it holds anything but safe characters.
std::string ShellQuote(const std::string& text) {
  const bool safe = !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) ||
           std::string("_-./=:,+@%^").find(c) != std::string::npos;
  });
  if (safe) return text;
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string CommandText(const std::vector<std::string>& args = CommandLineArgs()) {
  std::string out;
  for (const auto& arg : args) out += (out.empty() ? "" : " ") + ShellQuote(arg);
  return out;
}

/// The report's command line as the `plumb calibrate` command that fits the same data the
/// same way: the subcommand renamed, the options only `plumb report` has dropped (with their
/// values), the options in `replaced` dropped too, `extra` appended. calibrate takes every
/// other option of report (input, site, segments, model and fit options).
std::string CalibrateCommand(const std::vector<std::string>& replaced,
                             const std::vector<std::string>& extra) {
  // Report's own options, and whether each takes a value.
  const std::vector<std::pair<std::string, bool>> own = {
      {"--out", true},         {"--significance", true}, {"--confirm", true}, {"--jobs", true},
      {"--gnuplot", true},     {"--study", true},        {"--diagnose", false},
      {"--no-diagnose", false}, {"--no-figures", false}};
  const std::vector<std::string>& args = CommandLineArgs();
  std::vector<std::string> out;
  bool in_report = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (!in_report) {
      in_report = i > 0 && arg == "report";
      out.push_back(in_report ? "calibrate" : arg);
      continue;
    }
    const std::string name = arg.rfind("--", 0) == 0 ? arg.substr(0, arg.find('=')) : "";
    bool takes_value = false, drop = false;
    for (const auto& [option, value] : own) {
      if (name == option) drop = true, takes_value = value;
    }
    for (const auto& option : replaced) {
      if (name == option) drop = true, takes_value = true;
    }
    if (!drop) {
      out.push_back(arg);
    } else if (takes_value && arg.find('=') == std::string::npos) {
      ++i;  // its value
    }
  }
  out.insert(out.end(), extra.begin(), extra.end());
  return CommandText(out);
}

report::InputSummary Summarise(const Session& session, const InputArgs& args) {
  const ImuSeries& s = session.series;
  report::InputSummary in;
  in.source = session.source;
  in.inputs = args.inputs;
  if (!args.acc_file.empty()) in.inputs.push_back(args.acc_file + "," + args.gyr_file);
  in.samples = s.size();
  const double dt = s.median_dt_s();
  in.rate_hz = dt > 0 ? 1.0 / dt : 0.0;
  in.duration_s = s.duration_s();
  in.has_gyro = s.has_gyro();
  in.has_temperature = s.has_temperature();
  if (s.has_temperature()) {
    const auto range = std::minmax_element(s.temp_c.begin(), s.temp_c.end());
    in.temp_min_c = *range.first;
    in.temp_max_c = *range.second;
  }
  in.acc_unit = s.acc_unit;
  in.gyr_unit = s.gyr_unit;
  in.warnings = Messages(session.warnings);
  return in;
}

class ReportCommand : public Command {
 public:
  explicit ReportCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "report",
        "Calibrate, diagnose and write one self-contained HTML page with figures: what was "
        "calibrated and how well (DIR/index.html)");
    app_->footer("Example (calibration and diagnosis of the bundled session on one page):\n  plumb report data/mikoff/imu0.log --columns ax,ay,az,gx,gy,gz --rate 100 --out report");
    ReportArgs& a = args_;
    AddInputOptions(app_, a.input, true);
    app_->add_option("--out", a.out_dir,
                     "Folder of the page (created when missing): index.html (the figures inside "
                     "it), and beside it result.json, diagnose.json, allan.json, residuals.csv, "
                     "figures.gp and its CSV data")
        ->type_name("DIR")
        ->required();
    AddModelOption(app_, a.fit, true);
    AddSiteOptions(app_, a.site);
    AddGravityOption(app_, a.site);
    app_->add_flag("--diagnose,!--no-diagnose", a.diagnose,
                   "Rank the missing effects of the catalogue on the page (default), or not")
        ->capture_default_str();
    app_->add_option("--significance", a.significance,
                     "Level of the score test and of the residual signature tests")
        ->check(CLI::Range(1e-12, 0.5))
        ->capture_default_str();
    app_->add_option("--confirm", a.confirm,
                     "Refit the model with each of the best N significant effects")
        ->check(NonNegative)
        ->capture_default_str();
    app_->add_option("--jobs", a.jobs,
                     "Diagnose's probe fits, then its refits, in parallel, each on one core "
                     "(default: every core), and a .bin, .tlog or .ulg of 32 MiB or more read in two parts; "
                     "the page is the same whatever N")
        ->check(Jobs);
    AddFitOptions(app_, a.fit);
    app_->add_flag("--no-figures", a.no_figures, "Write the page without figures (no gnuplot)");
    app_->add_option("--gnuplot", a.gnuplot,
                     "The gnuplot program (a name looked up on PATH, or a path)")
        ->type_name("PROGRAM")
        ->capture_default_str();
    AddSegmentOptions(app_, a.segments);
    app_->add_option("--study", a.study,
                     "Instead of a calibration: the page of a sensitivity study's folder (what "
                     "'plumb sweep' wrote): its points, and the NEES band and the error and "
                     "sigma against every factor")
        ->type_name("SWEEP_DIR");
  }

  FileRoles Files() const override {
    const ReportArgs& a = args_;
    FileRoles roles;
    AddFitInputFiles(a.input, a.segments.segments_path, a.fit, roles);
    if (!a.study.empty()) roles.inputs.push_back({"--study", a.study});
    roles.output_folders.push_back({"--out", a.out_dir});
    return roles;
  }

  int Run() override {
    const ReportArgs& a = args_;
    if (!a.study.empty()) return RunStudy();
    CheckReplaceable(a.out_dir);
    Session session = ReadInputs(a.input, a.jobs);
    const ImuSeries& series = session.series;
    const segmentation::SegmentationResult seg = FindSegments(series, a.segments);
    const FitSetup fit = PrepareFit(session, seg, a.site, a.fit, a.input);
    const std::vector<StillSegment>& segments = fit.segments;
    const geo::Site& site = fit.site;
    const model::Model& model = fit.model;
    const estimation::CalibrationOptions& options = fit.options;
    PrintSession(session);
    std::cout << report::SegmentationSummary(seg, a.segments.segments_path, a.segments.verbose);

    const estimation::CalibrationResult result = CalibrateWithProgress(session, fit);
    std::cout << report::FitVerdict(result.fit) << "\n" << report::GateLines(result.fit, session.source);
    if (const int code = StrictGateExit(result.fit, session.source, a.fit.strict)) return code;
    // With the board's IMUs, diagnose --imus's diagnosis: each IMU alone (IMU 0's is the
    // page's diagnosis) and the board across.
    std::optional<diagnostics::Diagnosis> diagnosis;
    std::optional<diagnostics::BoardDiagnosis> board_diagnosis;
    if (a.diagnose && !session.other_imus.empty()) {
      board_diagnosis = RunBoardDiagnosis(session, fit);
      if (board_diagnosis) diagnosis = board_diagnosis->imus.front().diagnosis;
    } else if (a.diagnose) {
      diagnosis = RunDiagnosis(series, segments, model, site, options);
    }

    diagnostics::ResidualAnalysisOptions ra_options;
    ra_options.significance = a.significance;
    const diagnostics::ResidualAnalysis analysis =
        diagnostics::AnalyseResiduals(series, result, ra_options);

    // Written as a whole: an interrupted report leaves the old folder as it was.
    io::StagedFolder staged(a.out_dir);
    const std::filesystem::path dir(staged.staging());
    std::vector<std::string> files = {"result.json", "residuals.csv"};
    report::WriteJson((dir / "result.json").string(),
                      report::CalibrationJson(result, seg, Summarise(session, a.input).inputs,
                                              session.warnings));
    if (board_diagnosis) {
      std::vector<diagnostics::ResidualAnalysis> analyses;
      for (std::size_t k = 0; k < board_diagnosis->imus.size(); ++k) {
        const ImuSeries& s = k == 0 ? series : session.other_imus[k - 1].series;
        analyses.push_back(diagnostics::AnalyseResiduals(
            s, board_diagnosis->imus[k].diagnosis.fit, ra_options));
      }
      report::WriteJson((dir / "diagnose.json").string(),
                        report::BoardDiagnosisJson(*board_diagnosis, analyses));
      files.insert(files.begin() + 1, "diagnose.json");
    } else if (diagnosis) {
      report::WriteJson((dir / "diagnose.json").string(),
                        report::DiagnosisJson(*diagnosis, analysis));
      files.insert(files.begin() + 1, "diagnose.json");
    }
    io::WriteFileAtomic((dir / "residuals.csv").string(), report::ResidualsCsv(analysis.samples));

    report::PageExtras extras;
    extras.title = "plumb report: " + session.source;
    extras.command = CommandText();
    extras.segments_source = a.segments.segments_path;
    // The sensor's noise as `plumb allan` measures it on the same still segments.
    try {
      extras.still_noise = signal::AnalyseStillNoise(series, segments, {}, ParallelJobs(a.jobs));
      report::WriteJson((dir / "allan.json").string(),
                        report::StillNoiseJson(*extras.still_noise, series));
      files.push_back("allan.json");
    } catch (const InsufficientDataError& e) {
      extras.still_noise_note = e.what();
      std::cerr << "warning: no noise terms: " << e.what() << "\n";
    }
    if (a.no_figures) {
      extras.figure_notes.push_back("not drawn (--no-figures)");
    } else {
      Progress::Of().Stage("drawing the figures with gnuplot");
      DrawFigures(dir.string(), series, segments, result, ra_options, extras, files);
    }
    extras.files = files;
    if (diagnosis) {
      if (diagnostics::UniformClockNext(*diagnosis)) {
        extras.next_command = CalibrateCommand({"--clock"}, {"--clock", "uniform"});
      } else if (diagnostics::EstimateWanderNext(*diagnosis)) {
        extras.next_command = CalibrateCommand({}, {"--estimate-rw"});
      } else if (board_diagnosis) {  // each IMU's advice, refitted together
        if (board_diagnosis->next && board_diagnosis->next->advised) {
          extras.next_command =
              CalibrateCommand({"--model", "--imu-model"}, report::NextBoardFlags(*board_diagnosis));
        }
      } else if (const auto spec = diagnostics::NextModelSpec(*diagnosis)) {
        extras.next_command = CalibrateCommand({"--model"}, {"--model", *spec});
      }
    }
    if (board_diagnosis) extras.board_diagnosis = report::BoardDiagnosisSummary(*board_diagnosis);
    PreviewExports(session, result, extras);
    extras.board_agreement = estimation::BoardAgreement(result, series, session.other_imus);
    const std::string page = report::HtmlReport(Summarise(session, a.input), seg, result,
                                                analysis, diagnosis ? &*diagnosis : nullptr,
                                                extras);
    io::WriteFileAtomic((dir / "index.html").string(), page);
    staged.Commit();
    std::cout << "wrote " << (std::filesystem::path(a.out_dir) / "index.html").string() << " ("
              << extras.figures.size()
              << " figures; also " << files.size() << " files beside it)\n";
    return 0;
  }

 private:
  /// --study SWEEP_DIR --out DIR.
  int RunStudy() const {
    const ReportArgs& a = args_;
    if (!a.input.inputs.empty() || !a.input.acc_file.empty()) {
      throw UsageError("--study takes a plumb sweep folder instead of INPUT files");
    }
    CheckReplaceable(a.out_dir);
    const std::string study_path = (std::filesystem::path(a.study) / "study.json").string();
    const study::Study s = study::ParseStudy(ReadJsonFile(study_path), study_path);
    const std::vector<study::PointSummary> points =
        ReadStudyPoints(s, study::DesignPoints(s), a.study);
    io::StagedFolder staged(a.out_dir);  // written as a whole
    const std::string why = WriteStudyPage(s, points, staged.staging(), !a.no_figures, a.gnuplot);
    staged.Commit();
    if (!why.empty() && !a.no_figures) std::cerr << "warning: no figures: " << why << "\n";
    std::cout << "wrote " << (std::filesystem::path(a.out_dir) / "index.html").string() << " ("
              << points.size() << " points of " << (s.name.empty() ? study_path : s.name) << ")\n";
    return 0;
  }

  /// diagnose's options for a fit of `calibration`'s.
  diagnostics::DiagnoseOptions DiagnoseOptionsFor(
      const estimation::CalibrationOptions& calibration) const {
    diagnostics::DiagnoseOptions options;
    options.significance = args_.significance;
    options.confirm = args_.confirm;
    options.calibration = calibration;
    options.calibration.on_insufficient = estimation::InsufficientData::kReport;
    options.on_stage = [](const std::string& stage) { Progress::Of().Stage(stage); };
    options.run_jobs = ParallelJobs(args_.jobs);
    options.calibration.run_jobs = options.run_jobs;  // the probe fit's motion residuals
    return options;
  }

  /// diagnose --imus's: each IMU alone and the board across (diagnostics/board_diagnosis.h);
  /// a failure is a warning, as RunDiagnosis's.
  std::optional<diagnostics::BoardDiagnosis> RunBoardDiagnosis(const Session& session,
                                                              const FitSetup& fit) const {
    try {
      diagnostics::BoardDiagnosis d = diagnostics::DiagnoseBoard(
          session.series, session.other_imus, fit.segments, fit.model, fit.site,
          DiagnoseOptionsFor(fit.options), fit.board_models);
      std::cout << report::BoardDiagnosisSummary(d);
      return d;
    } catch (const Error& e) {
      std::cerr << "warning: the diagnosis failed: " << e.what() << "\n";
      return std::nullopt;
    }
  }

  /// diagnose's ranking; a failure is a warning on the page and on stdout, not the end of
  /// the report (the calibration itself succeeded).
  std::optional<diagnostics::Diagnosis> RunDiagnosis(
      const ImuSeries& series, const std::vector<StillSegment>& segments,
      const model::Model& model, const geo::Site& site,
      const estimation::CalibrationOptions& calibration) {
    const diagnostics::DiagnoseOptions options = DiagnoseOptionsFor(calibration);
    try {
      diagnostics::Diagnosis d = diagnostics::Diagnose(series, segments, model, site, options);
      std::cout << report::DiagnosisText(d);
      return d;
    } catch (const Error& e) {
      std::cerr << "warning: the diagnosis failed: " << e.what() << "\n";
      return std::nullopt;
    }
  }

  /// The page's firmware section: what each --export would write and leave, or why not.
  void PreviewExports(const Session& session, const estimation::CalibrationResult& result,
                      report::PageExtras& extras) const {
    const ImuSeries& series = session.series;
    if (series.acc_unit != "m/s^2" || (series.has_gyro() && series.gyr_unit != "rad/s")) {
      extras.exports_note = "the samples are in " + series.acc_unit + " and " + series.gyr_unit +
                            ", not m/s^2 and rad/s: no export acts on them";
      return;
    }
    exporter::ExportOptions options;
    options.imu = args_.input.imu;
    options.log_params = session.log_params;
    options.system_id = session.system_id;
    std::string firmware_refused;
    if (args_.input.as_logged) {
      firmware_refused = "--as-logged: the samples keep the log's correction, so parameters "
                         "fitted to them would replace it instead of adding to it";
    } else if (!session.firmware_left.empty()) {
      firmware_refused = "the samples still carry corrections the flight controller applied "
                         "and plumb could not undo:";
      for (const std::string& left : session.firmware_left) firmware_refused += " " + left + ";";
    }
    extras.exports = exporter::PreviewExports(result.calibration, series, result.fit.still,
                                              options, firmware_refused);
    const std::pair<const char*, const char*> files[] = {
        {"ardupilot", "calibration.param"}, {"px4", "calibration.params"}, {"kalibr", "imu.yaml"}};
    for (const auto& [format, file] : files) {
      extras.export_commands[format] =
          CalibrateCommand({}, {"--export", std::string(format) + "=" + file});
    }
    if (!result.fit.gates.empty()) {
      extras.exports_note = "The fit failed a gate: plumb calibrate refuses these exports "
                            "unless --export-anyway is given (see the summary).";
    }
  }

  /// Plans the figures, runs gnuplot in the output folder, and keeps the figures it drew.
  /// The Allan figure pools only the longest still segment(s).
  void DrawFigures(const std::string& dir, const ImuSeries& series,
                   const std::vector<StillSegment>& segments,
                   const estimation::CalibrationResult& result,
                   diagnostics::ResidualAnalysisOptions ra_options, report::PageExtras& extras,
                   std::vector<std::string>& files) const {
    ra_options.allan_length_fraction = 1.0;
    const diagnostics::ResidualAnalysis longest =
        diagnostics::AnalyseResiduals(series, result, ra_options);
    report::FigurePlan plan = report::PlanFigures(series, segments, result, longest);
    if (extras.still_noise) report::AddStillNoiseFigure(*extras.still_noise, {}, plan);
    const report::GnuplotOutcome outcome = report::RunGnuplot(dir, plan.job, args_.gnuplot);
    extras.figures = report::EmbedDrawnFigures(dir, plan, outcome);  // inside the page
    if (!outcome.message.empty()) {
      // `dir` is the staging folder, renamed to --out once the page is written: the message
      // names the files where the user will find them.
      std::string message = outcome.message;
      for (std::size_t at = message.find(dir); at != std::string::npos;
           at = message.find(dir, at + args_.out_dir.size())) {
        message.replace(at, dir.size(), args_.out_dir);
      }
      extras.figure_notes.push_back(message);
      std::cerr << "plumb: warning: " << message << "\n";
    }
    files.push_back(plan.job.script_name);
    for (const auto& data : plan.job.data) files.push_back(data.name);
    files.push_back(plan.job.log_name);
  }

  ReportArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeReportCommand(CLI::App& parent) {
  return std::make_unique<ReportCommand>(parent);
}

}  // namespace plumb::cli

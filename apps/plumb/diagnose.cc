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

#include "commands.h"
#include "input_options.h"
#include "plumb/core/error.h"
#include "plumb/diagnostics/diagnose.h"
#include "plumb/diagnostics/residual_analysis.h"
#include "plumb/io/atomic_file.h"
#include "plumb/report/json_report.h"
#include "plumb/report/summary.h"
#include "segment_options.h"
#include "site_options.h"

namespace plumb::cli {
namespace {

struct DiagnoseArgs {
  InputArgs input;
  SiteArgs site;
  SegmentArgs segments;
  std::string model = "base";
  std::string json_path;                ///< --json FILE
  std::string residuals_path;           ///< --residuals FILE: per-sample residuals, CSV
  double significance = 0.01;           ///< level of the score test, (0, 0.5)
  int confirm = 3;                      ///< refit the best N significant candidates, >= 0
  std::vector<std::string> candidates;  ///< --candidates: effect names (default: catalogue)
  double heading_deg = 0.0;             ///< --heading: first still pose's x from north, deg
  CLI::Option* heading = nullptr;
  double temp_ref_c = 25.0;             ///< reference temperature of temperature terms, degC
};

nlohmann::json CandidateJson(const diagnostics::Candidate& c) {
  nlohmann::json j = {{"effect", c.effect},
                      {"option", c.option},
                      {"lm", report::Number(c.lm)},
                      {"dof", c.dof},
                      {"parameters", c.num_parameters},
                      {"evidence", report::Number(c.evidence)},
                      {"threshold", report::Number(c.threshold)},
                      {"significant", c.significant},
                      {"predicted_drop", report::Number(c.lm)},
                      {"refit_drop", c.refit_drop ? report::Number(*c.refit_drop) : nullptr},
                      {"identifiable", c.identifiable},
                      {"with_velocity", c.with_velocity},
                      {"dispersion", report::Number(c.dispersion)}};
  nlohmann::json confounded = nlohmann::json::array();
  for (const auto& n : c.not_identifiable) {
    confounded.push_back({{"parameter", n.parameter},
                          {"excited", n.excited},
                          {"ratio", report::Number(n.ratio)},
                          {"too_weak", n.too_weak},
                          {"sigma", report::Number(n.sigma)},
                          {"typical", n.typical},
                          {"confounded_with", n.confounders},
                          {"shares", n.shares}});
  }
  j["not_identifiable"] = confounded;
  j["indistinguishable_from"] = c.indistinguishable_from;
  if (c.refit) {
    j["refit"] = {{"model", c.refit->model.spec()}, {"fit", report::ToJson(*c.refit)["fit"]}};
    nlohmann::json added = nlohmann::json::array();
    for (const auto& p : c.refit->parameters) {
      if (p.name.rfind(c.effect + ".", 0) != 0) continue;
      added.push_back({{"name", p.name}, {"value", report::Number(p.value)},
                       {"sigma", report::Number(p.sigma)}, {"observable", p.observable},
                       {"unit", p.unit}});
    }
    j["refit"]["parameters"] = added;
  }
  return j;
}

nlohmann::json CompareJson(const diagnostics::ResidualAnalysis& ra) {
  nlohmann::json still = nlohmann::json::array();
  for (std::size_t k : ra.still_rank) {
    const auto& c = ra.still[k];
    still.push_back({{"index", c.index}, {"label", c.label}, {"t_begin_s", c.t_begin_s},
                     {"t_end_s", c.t_end_s}, {"temp_c", report::Number(c.temp_c)},
                     {"f_b", report::Vector(c.f_b)},
                     {"acc", {{"measured", report::Vector(c.acc_measured)},
                              {"predicted", report::Vector(c.acc_predicted)},
                              {"residual", report::Vector(c.acc_residual)},
                              {"whitened", report::Vector(c.acc_whitened)}}},
                     {"gyro", {{"measured", report::Vector(c.gyr_measured)},
                               {"predicted", report::Vector(c.gyr_predicted)},
                               {"residual", report::Vector(c.gyr_residual)},
                               {"whitened", report::Vector(c.gyr_whitened)}}},
                     {"whitened_norm", c.whitened_norm}});
  }
  nlohmann::json motion = nlohmann::json::array();
  for (std::size_t k : ra.motion_rank) {
    const auto& m = ra.motion[k];
    motion.push_back({{"from", m.from}, {"to", m.to}, {"t_begin_s", m.t_begin_s},
                      {"t_end_s", m.t_end_s}, {"residual_rad", report::Vector(m.residual)},
                      {"whitened", report::Vector(m.whitened)},
                      {"mean_rate", m.mean_rate}, {"mean_rate2", m.mean_rate2},
                      {"max_angular_acc", m.max_angular_acc}});
  }
  nlohmann::json worst = nlohmann::json::array();
  for (const auto& w : ra.worst) {
    worst.push_back({{"name", w.name}, {"t_begin_s", w.t_begin_s}, {"t_end_s", w.t_end_s},
                     {"residual", diagnostics::ResidualKindName(w.residual)},
                     {"axis", std::string(1, "xyz"[w.axis])}, {"score", w.score}});
  }
  nlohmann::json signatures = nlohmann::json::array();
  for (const auto& g : ra.signatures) {
    signatures.push_back({{"residual", diagnostics::ResidualKindName(g.residual)},
                          {"axis", std::string(1, "xyz"[g.axis])},
                          {"regressor", g.regressor}, {"unit", g.unit}, {"points", g.points},
                          {"correlation", g.correlation}, {"slope", g.slope_residual},
                          {"slope_sigma", g.slope_residual_sigma}, {"p_value", g.p_value},
                          {"significant", g.significant}});
  }
  nlohmann::json allan = nlohmann::json::array();
  for (const auto& al : ra.allan) {
    allan.push_back({{"residual", diagnostics::ResidualKindName(al.residual)},
                     {"axis", std::string(1, "xyz"[al.axis])}, {"tau_s", al.tau_s},
                     {"adev", al.adev}, {"white", al.white}, {"ratio", al.ratio},
                     {"sigma_white", al.sigma_white}, {"fit_sigma", al.fit_sigma}});
  }
  return {{"still", still}, {"motion", motion}, {"worst", worst},
          {"signatures", signatures}, {"p_threshold", ra.p_threshold}, {"allan", allan}};
}

std::string ResidualsCsv(const diagnostics::SampleResiduals& s) {
  std::ostringstream csv;
  csv << std::setprecision(9)
      << "time_s,segment,acc_res_x,acc_res_y,acc_res_z,gyr_res_x,gyr_res_y,gyr_res_z,"
         "acc_norm_x,acc_norm_y,acc_norm_z,gyr_norm_x,gyr_norm_y,gyr_norm_z\n";
  for (std::size_t i = 0; i < s.size(); ++i) {
    csv << s.t_s[i] << "," << s.segment[i];
    for (const Vec3* v : {&s.acc_residual[i], &s.gyr_residual[i], &s.acc_normalised[i],
                          &s.gyr_normalised[i]}) {
      csv << "," << v->x() << "," << v->y() << "," << v->z();
    }
    csv << "\n";
  }
  return csv.str();
}

class DiagnoseCommand : public Command {
 public:
  explicit DiagnoseCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "diagnose",
        "Find which effects of the catalogue the model is missing: the score test of every "
        "effect not in the model, ranked, the best confirmed by refitting");
    DiagnoseArgs& a = args_;
    AddInputOptions(app_, a.input);
    app_->add_option("--model", a.model, "The model to diagnose (a spec, see 'plumb effects')")
        ->capture_default_str();
    AddSiteOptions(app_, a.site);
    AddGravityOption(app_, a.site);
    app_->add_option("--json", a.json_path, "Write the diagnosis as JSON to FILE (atomically)")
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
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app_->add_option("--candidates", a.candidates,
                     "Test only these effects (NAME or NAME:OPTION, comma-separated); default: "
                     "every catalogue effect not in the model")
        ->delimiter(',');
    a.heading = app_->add_option("--heading", a.heading_deg,
                                 "Heading of the first still pose's x axis from north, degrees");
    app_->add_option("--temp-ref", a.temp_ref_c,
                     "Reference temperature of the temperature terms, degC")
        ->capture_default_str();
    AddSegmentOptions(app_, a.segments);
  }

  int Run() override {
    const DiagnoseArgs& a = args_;
    Session session = ReadInputs(a.input);
    const ImuSeries& series = session.series;
    const segmentation::SegmentationResult seg = FindSegments(series, a.segments);
    const std::optional<double> gravity = a.site.fixed_gravity();
    const geo::Site site = ResolveSite(a.site, session.site, gravity);
    model::Model model = model::Model::Parse(a.model);
    model.t_ref_s = series.t_s.front();
    model.temp_ref_c = a.temp_ref_c;
    diagnostics::DiagnoseOptions options;
    options.significance = a.significance;
    options.confirm = a.confirm;
    options.candidates = a.candidates;
    options.calibration.method = "generalized";
    if (a.heading->count() > 0) options.calibration.first_heading_deg = a.heading_deg;

    std::cout << session.source << ": " << series.size() << " samples, " << series.duration_s()
              << " s" << (series.has_temperature() ? ", with temperature" : "") << "\n";
    for (const auto& w : session.warnings) std::cout << "warning: " << w << "\n";
    std::cout << report::SegmentationSummary(seg, a.segments.segments_path, a.segments.verbose)
              << "\n";
    const diagnostics::Diagnosis d =
        diagnostics::Diagnose(series, seg.segments, model, site, options);
    diagnostics::ResidualAnalysisOptions ra_options;
    ra_options.significance = a.significance;
    const diagnostics::ResidualAnalysis ra = diagnostics::AnalyseResiduals(series, d.fit, ra_options);
    std::cout << "plumb diagnose: " << report::FitVerdict(d.fit.fit) << "\n"
              << ra.BriefReport() << d.BriefReport();
    const auto best = std::find_if(d.candidates.begin(), d.candidates.end(),
                                   [](const diagnostics::Candidate& c) { return c.refit.has_value(); });
    if (best != d.candidates.end()) {
      const bool velocity = best->with_velocity && d.fit_with_velocity.has_value();
      std::cout << "\n"
                << report::BeforeAfterSummary(velocity ? *d.fit_with_velocity : d.fit,
                                              *best->refit);
    }
    for (const auto& w : d.fit.warnings) std::cout << "warning: " << w << "\n";

    if (!a.json_path.empty()) {
      nlohmann::json doc;
      doc["model"] = d.fit.model.spec();
      doc["fit"] = report::ToJson(d.fit)["fit"];
      doc["significance"] = d.significance;
      doc["num_residuals"] = d.num_residuals;
      doc["candidates"] = nlohmann::json::array();
      for (const auto& c : d.candidates) doc["candidates"].push_back(CandidateJson(c));
      doc["skipped"] = nlohmann::json::array();
      for (const auto& s : d.skipped) {
        doc["skipped"].push_back({{"effect", s.effect}, {"reason", s.reason}});
      }
      doc["compare"] = CompareJson(ra);
      doc["site"] = report::ToJson(d.fit)["site"];
      doc["warnings"] = d.fit.warnings;
      report::WriteJson(a.json_path, doc);
      std::cout << "wrote " << a.json_path << "\n";
    }
    if (!a.residuals_path.empty()) {
      io::WriteFileAtomic(a.residuals_path, ResidualsCsv(ra.samples));
      std::cout << "wrote " << a.residuals_path << "\n";
    }
    return 0;
  }

 private:
  DiagnoseArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeDiagnoseCommand(CLI::App& parent) {
  return std::make_unique<DiagnoseCommand>(parent);
}

}  // namespace plumb::cli

#include "plumb/report/diagnosis_json.h"

#include <iomanip>
#include <sstream>

#include "plumb/report/json_report.h"

namespace plumb::report {

nlohmann::json ToJson(const diagnostics::Candidate& c) {
  nlohmann::json j = {{"kind", c.kind == diagnostics::CandidateKind::kTimeBase ? "time_base"
                               : c.kind == diagnostics::CandidateKind::kWander ? "bias_wander"
                                                                                 : "effect"},
                      {"effect", c.effect},
                      {"option", c.option},
                      {"lm", Number(c.lm)},
                      {"dof", c.dof},
                      {"parameters", c.num_parameters},
                      {"evidence", Number(c.evidence)},
                      {"threshold", Number(c.threshold)},
                      {"significant", c.significant},
                      {"predicted_drop", Number(c.lm)},
                      {"refit_drop", c.refit_drop ? Number(*c.refit_drop) : nullptr},
                      {"identifiable", c.identifiable},
                      {"with_velocity", c.with_velocity},
                      {"recommended", c.recommended},
                      {"dispersion", Number(c.dispersion)}};
  nlohmann::json confounded = nlohmann::json::array();
  for (const auto& n : c.not_identifiable) {
    confounded.push_back({{"parameter", n.parameter},
                          {"excited", n.excited},
                          {"ratio", Number(n.ratio)},
                          {"too_weak", n.too_weak},
                          {"sigma", Number(n.sigma)},
                          {"typical", n.typical},
                          {"confounded_with", n.confounders},
                          {"shares", n.shares}});
  }
  j["not_identifiable"] = confounded;
  j["indistinguishable_from"] = c.indistinguishable_from;
  if (c.refit) {
    j["refit"] = {{"model", c.refit->calibration.model.spec()}, {"fit", ToJson(*c.refit)["fit"]}};
    nlohmann::json added = nlohmann::json::array();
    for (const auto& p : c.refit->calibration.parameters) {
      if (p.name.rfind(c.effect + ".", 0) != 0) continue;
      added.push_back({{"name", p.name}, {"value", Number(p.value)},
                       {"sigma", Number(p.sigma)}, {"observable", p.observable},
                       {"unit", p.unit}});
    }
    j["refit"]["parameters"] = added;
  }
  return j;
}

nlohmann::json ToJson(const diagnostics::ResidualAnalysis& ra) {
  nlohmann::json still = nlohmann::json::array();
  for (std::size_t k : ra.still_rank) {
    const auto& c = ra.still[k];
    still.push_back({{"index", c.index}, {"label", c.label}, {"t_begin_s", c.t_begin_s},
                     {"t_end_s", c.t_end_s}, {"temp_c", Number(c.temp_c)},
                     {"f_b", Vector(c.f_b)},
                     {"acc", {{"measured", Vector(c.acc_measured)},
                              {"predicted", Vector(c.acc_predicted)},
                              {"residual", Vector(c.acc_residual)},
                              {"whitened", Vector(c.acc_whitened)}}},
                     {"gyro", {{"measured", Vector(c.gyr_measured)},
                               {"predicted", Vector(c.gyr_predicted)},
                               {"residual", Vector(c.gyr_residual)},
                               {"whitened", Vector(c.gyr_whitened)}}},
                     {"whitened_norm", c.whitened_norm}});
  }
  nlohmann::json motion = nlohmann::json::array();
  for (std::size_t k : ra.motion_rank) {
    const auto& m = ra.motion[k];
    motion.push_back({{"from", m.from}, {"to", m.to}, {"t_begin_s", m.t_begin_s},
                      {"t_end_s", m.t_end_s}, {"residual_rad", Vector(m.residual)},
                      {"whitened", Vector(m.whitened)},
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

nlohmann::json DiagnosisJson(const diagnostics::Diagnosis& d,
                             const diagnostics::ResidualAnalysis& ra) {
  nlohmann::json doc;
  const nlohmann::json fit = ToJson(d.fit);
  doc["model"] = d.fit.calibration.model.spec();
  doc["fit"] = fit["fit"];
  // Like with like: the fit where the candidates with_velocity were scored, beside the user's.
  doc["fit_with_velocity"] =
      d.fit_with_velocity ? ToJson(*d.fit_with_velocity)["fit"] : nlohmann::json(nullptr);
  const auto next = diagnostics::NextModelSpec(d);
  doc["recommendation"] = next ? nlohmann::json(*next) : nlohmann::json(nullptr);
  // What else the next fit takes: the uniform clock when the time base is advised, the wander
  // estimated when the bias wander is.
  doc["recommendation_options"] = diagnostics::UniformClockNext(d)
                                      ? nlohmann::json::array({"--clock", "uniform"})
                                  : diagnostics::EstimateWanderNext(d)
                                      ? nlohmann::json::array({"--estimate-rw"})
                                      : nlohmann::json::array();
  doc["significance"] = d.significance;
  doc["num_residuals"] = d.num_residuals;
  doc["candidates"] = nlohmann::json::array();
  for (const auto& c : d.candidates) doc["candidates"].push_back(ToJson(c));
  doc["skipped"] = nlohmann::json::array();
  for (const auto& s : d.skipped) {
    doc["skipped"].push_back({{"effect", s.effect}, {"reason", s.reason}});
  }
  doc["compare"] = ToJson(ra);
  doc["site"] = fit["site"];
  doc["warnings"] = Messages(d.fit.fit.warnings);
  doc["gates"] = GatesJson(d.fit.fit);  // the user's fit's, as calibrate's JSON has them
  return doc;
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

}  // namespace plumb::report

#include "plumb/study/run.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/core/units.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/elimination.h"
#include "plumb/estimation/sensitivity.h"
#include "plumb/paper/backend.h"
#include "plumb/paper/benchmark.h"
#include "plumb/paper/static_procedure.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb::study {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The simulator's options for a point (study.h's base with the point applied).
sim::SimulationOptions SensorOf(const Base& b, const model::Model& model, std::uint64_t seed) {
  sim::SimulationOptions o = b.sensor == "white" ? sim::SimulationOptions::WhiteMems()
                                                 : sim::SimulationOptions::TypicalMems();
  auto set = [](double value, double& field) {
    if (!std::isnan(value)) field = value;
  };
  set(b.accel_noise, o.accel_noise_density);
  set(b.gyro_noise, o.gyro_noise_density);
  set(b.accel_rw, o.accel_bias_walk_density);
  set(b.gyro_rw, o.gyro_bias_walk_density);
  set(b.accel_bi, o.accel_bias_instability);
  set(b.gyro_bi, o.gyro_bias_instability);
  o.bias_instability_time_s = b.bi_time_s;
  o.temperature = sim::TemperatureProfile::Ramp(25.0, 25.0 + b.temperature_rise_c);
  o.hand.vibration_accel = b.hand_vibration;
  o.hand.translation_m = b.hand_translation_m;
  o.rate_hz = b.rate_hz;
  o.site = geo::Site::At(b.lat_deg, b.lon_deg, b.height_m, "study");
  o.model = model;
  o.truth = sim::RandomParameters(model, b.random_truth, seed);
  for (const auto& [name, value] : b.truth) sim::SetParameter(model, o.truth, name, value);
  o.seed = seed;
  return o;
}

sim::Schedule ScheduleOf(const Study& study, const Base& b, std::uint64_t seed) {
  if (b.schedule == "session") return TemplateSchedule(study.template_document, b.template_path);
  if (b.schedule == "paper_static") {
    // The hold as it truly is: turned from north, then tilted about body y (study.h).
    const Quat R_n_b =
        Quat(Eigen::AngleAxisd(b.heading_error_deg * units::kRadPerDeg, Vec3::UnitZ())) *
        Quat(Eigen::AngleAxisd(b.level_error_deg * units::kRadPerDeg, Vec3::UnitY()));
    sim::Schedule schedule(R_n_b);
    schedule.Hold(b.still_s, "level, x north");
    return schedule;
  }
  if (b.schedule == "paper_benchmark") return sim::PaperBenchmark(b.still_s, b.turn_s);
  return sim::MultiPose(static_cast<int>(std::lround(b.poses)), b.still_s, b.turn_s, seed);
}

/// The true value of a fitted parameter: the simulated model's, or, for a parameter the
/// simulation lacks (an effect fitted but not simulated), the fitted model's nominal value.
class Truth {
 public:
  Truth(const sim::Simulation& s, const model::Model& fitted)
      : sim_names_(s.model.ParameterNames()), sim_values_(model::ReportedValues(s.model, s.truth)),
        fit_names_(fitted.ParameterNames()),
        nominal_(model::ReportedValues(fitted, fitted.ZeroParameters())) {}
  double operator()(const std::string& name) const {
    for (std::size_t j = 0; j < sim_names_.size(); ++j) {
      if (sim_names_[j] == name) return sim_values_[j];
    }
    for (std::size_t j = 0; j < fit_names_.size(); ++j) {
      if (fit_names_[j] == name) return nominal_[j];
    }
    return 0.0;
  }

 private:
  std::vector<std::string> sim_names_;
  std::vector<double> sim_values_;
  std::vector<std::string> fit_names_;
  std::vector<double> nominal_;
};

/// out.nees = e^T C^-1 e (LDLT), left NaN when C is not positive definite.
void SetNees(const Eigen::VectorXd& e, const Eigen::MatrixXd& C, RunOutcome& out) {
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(C);
  if (C.rows() == e.size() && ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > 0.0).all()) {
    out.nees = e.dot(ldlt.solve(e));
    out.nees_dof = static_cast<int>(e.size());
  }
}

/// The unit of a determined combination: its leading parameter's (the one of coefficient 1,
/// "accel.bias.z" of "accel.bias.z - 9.78 accel.matrix.zz"; the other terms carry their
/// coefficient's unit), "" when there is none.
std::string CombinationUnit(const estimation::Combination& c,
                            const std::vector<estimation::ParameterEstimate>& params) {
  for (std::size_t i = 0; i < c.names.size() && i < c.coefficients.size(); ++i) {
    if (c.coefficients[i] != 1.0) continue;
    for (const auto& p : params) {
      if (p.name == c.names[i]) return p.unit;
    }
  }
  return "";
}

/// Where the data determine no parameter alone (one pose), the combinations they determine
/// (estimation::Observability::determined) are scored instead, each a row named by its text
/// in its leading parameter's unit, and the NEES is over their covariance.
void Combinations(const estimation::CalibrationResult& result, const Truth& truth_of,
                  RunOutcome& out) {
  const auto& obs = result.calibration.observability;
  if (obs.determined.empty()) return;
  const auto m = static_cast<Eigen::Index>(obs.determined.size());
  Eigen::VectorXd e(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    const estimation::Combination& c = obs.determined[static_cast<std::size_t>(k)];
    double truth = 0.0;
    for (std::size_t i = 0; i < c.names.size(); ++i) truth += c.coefficients[i] * truth_of(c.names[i]);
    e[k] = c.value - truth;
    out.names.push_back(c.text);
    out.units.push_back(CombinationUnit(c, result.calibration.parameters));
    out.error.push_back(e[k]);
    out.sigma.push_back(c.sigma);
  }
  SetNees(e, obs.determined_covariance, out);
}

/// Errors, sigmas and the NEES of a calibration against the simulated truth.
void Score(const estimation::CalibrationResult& result, const sim::Simulation& s,
           const model::Model& fitted, RunOutcome& out) {
  const Truth truth_of(s, fitted);
  const auto& params = result.calibration.parameters;
  std::vector<Eigen::Index> in_nees;
  for (std::size_t i = 0; i < params.size(); ++i) {
    const auto& p = params[i];
    out.names.push_back(p.name);
    out.units.push_back(p.unit);
    const bool determined = !p.fixed && p.observable && std::isfinite(p.sigma);
    out.error.push_back(determined ? p.value - truth_of(p.name) : kNaN);
    out.sigma.push_back(determined ? p.sigma : kNaN);
    if (determined) in_nees.push_back(static_cast<Eigen::Index>(i));
  }
  const auto n = static_cast<Eigen::Index>(in_nees.size());
  if (n == 0) {
    Combinations(result, truth_of, out);
    return;
  }
  Eigen::VectorXd e(n);
  Eigen::MatrixXd C(n, n);
  for (Eigen::Index a = 0; a < n; ++a) {
    e[a] = out.error[static_cast<std::size_t>(in_nees[static_cast<std::size_t>(a)])];
    for (Eigen::Index b = 0; b < n; ++b) {
      C(a, b) = result.calibration.covariance(in_nees[static_cast<std::size_t>(a)],
                                              in_nees[static_cast<std::size_t>(b)]);
    }
  }
  SetNees(e, C, out);
}

/// A closed form's forward-form answer (F, b_a, E, b_g) scored against the truth by the
/// fitted model's names: values only, no sigma.
void ClosedForm(const Mat3& F, const Vec3& b_a, const Mat3& E, const Vec3& b_g,
                const sim::Simulation& s, const model::Model& fitted, RunOutcome& out) {
  const Truth truth_of(s, fitted);
  const std::vector<std::string> names = fitted.ParameterNames();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string& name = names[i];
    // accel.matrix.RC, accel.bias.X, gyro.matrix.RC, gyro.bias.X (the base model's names).
    const bool acc = name.rfind("accel.", 0) == 0;
    const std::string tail = name.substr(name.rfind('.') + 1);
    const bool matrix = name.find(".matrix.") != std::string::npos;
    double value = kNaN;
    if (matrix && tail.size() == 2) {
      value = (acc ? F : E)(tail[0] - 'x', tail[1] - 'x');
    } else if (name.find(".bias.") != std::string::npos && tail.size() == 1) {
      value = (acc ? b_a : b_g)[tail[0] - 'x'];
    }
    out.names.push_back(name);
    out.units.push_back(matrix ? "1" : acc ? "m/s^2" : "rad/s");
    out.error.push_back(value - truth_of(name));
    out.sigma.push_back(kNaN);
  }
}

/// The seed paper's closed forms: section 5 on the one hold, or section 4 on the benchmark
/// schedule (its turns the gaps between holds of the same pose).
void PaperClosedForm(const Study& study, const sim::Simulation& s,
                     const std::vector<StillSegment>& segments, const geo::Site& site,
                     const model::Model& fitted, RunOutcome& out) {
  if (study.fit_method == "paper_static") {
    const paper::PaperStaticResult r = paper::CalibratePaperStatic(
        s.session.series, segments.front().begin, segments.front().end, site, {});
    ClosedForm(r.F, r.b_a, r.E, r.b_g, s, fitted, out);
    return;
  }
  paper::PaperBenchmarkOptions options;
  options.gravity_m_s2 = site.gravity();
  const paper::PaperBenchmarkResult r =
      paper::CalibratePaperBenchmark(s.session.series, segments, {}, options);
  ClosedForm(r.F, r.b_a, r.E, r.b_g, s, fitted, out);
}

/// The effect of a true parameter's name ("gyro_g_sensitivity.G.zy" -> gyro_g_sensitivity;
/// a temperature term's order from its coefficient: ".c2." -> ":2").
std::pair<std::string, std::string> EffectOf(const std::string& parameter) {
  const std::string effect = parameter.substr(0, parameter.find('.'));
  std::string option;
  for (const char* order : {"3", "2"}) {
    if (option.empty() && parameter.find(std::string(".c") + order + ".") != std::string::npos) {
      option = order;
    }
  }
  return {effect, option};
}

/// For a truth.PARAMETER factor whose effect the fitted model lacks: the bias the missing
/// effect leaves in every fitted parameter per unit of it, (J^T J)^+ J^T Z at the fit with
/// the effect added as a probe (held at zero: the same fit), J the whitened Jacobian over the
/// unknowns and Z the probe's columns (the residuals are measured minus predicted, so data
/// carrying the effect move them by -Z per unit). Empty when the rows are not the fitted
/// model's parameters one by one.
std::vector<double> MissingEffectSensitivity(const std::string& parameter, const sim::Simulation& s,
                                             const std::vector<StillSegment>& segments,
                                             const geo::Site& site, const model::Model& fitted,
                                             const estimation::CalibrationOptions& options,
                                             const std::vector<std::string>& rows) {
  model::Model probe = fitted;
  const auto [effect, option] = EffectOf(parameter);
  probe.AddProbe(effect, option);
  const estimation::CalibrationResult r =
      estimation::Calibrate(s.session.series, segments, probe, site, options);
  if (!r.fit.probes) throw Error("study: the fit gave no probe columns for '" + parameter + "'");
  const estimation::ProbeJacobian& pj = *r.fit.probes;
  const auto col = std::find(pj.probe_names.begin(), pj.probe_names.end(), parameter);
  if (col == pj.probe_names.end()) throw Error("study: '" + parameter + "' is not a probe's parameter");
  const Eigen::VectorXd z = pj.Z.col(col - pj.probe_names.begin());
  const Eigen::VectorXd d = estimation::ProbeRange(pj, options.rank_tolerance)->Coefficients(z);
  std::vector<double> out(rows.size(), kNaN);
  for (std::size_t c = 0; c < pj.unknown_names.size(); ++c) {
    const auto row = std::find(rows.begin(), rows.end(), pj.unknown_names[c]);
    if (pj.unknown_is_model[c] && row != rows.end()) {
      out[static_cast<std::size_t>(row - rows.begin())] = d[static_cast<Eigen::Index>(c)];
    }
  }
  return out;
}

/// The study's fit-side changes (the gravity and the latitude the fit is told), in
/// SensitivityFactors order, moved about the point's values.
std::vector<estimation::AssumptionChange> FitSideChanges(const Study& study, const Base& b,
                                                         const std::vector<StillSegment>& segments,
                                                         const geo::Site& site) {
  std::vector<estimation::AssumptionChange> changes;
  for (const std::string& name : SensitivityFactors(study)) {
    if (name.rfind("truth.", 0) == 0) continue;  // MissingEffectSensitivity
    estimation::AssumptionChange c{name, 0.0, site, site, segments, segments};
    if (name == "level_error_deg" || name == "heading_error_deg") {
      // The true hold tilted (about body y) or turned (about down) by +-step while the fit
      // assumes the same attitude is, to first order, the fit assuming the opposite turn on
      // the same data: the data are what they are, the assumption moves.
      c.step = 0.1;  // deg
      const Vec3 axis = name == "level_error_deg" ? Vec3::UnitY() : Vec3::UnitZ();
      const double step_rad = c.step * units::kRadPerDeg;
      for (auto* segs : {&c.segments_minus, &c.segments_plus}) {
        const double sign = segs == &c.segments_plus ? -1.0 : 1.0;
        for (StillSegment& seg : *segs) {
          seg.known_R_n_b = seg.known_R_n_b.value_or(Quat::Identity()) *
                            Quat(Eigen::AngleAxisd(sign * step_rad, axis));
        }
      }
    } else if (name == "fit_gravity_m_s2") {
      c.step = 0.01;  // m/s^2
      c.site_minus.g_n = Vec3(0.0, 0.0, site.gravity() - c.step);
      c.site_plus.g_n = Vec3(0.0, 0.0, site.gravity() + c.step);
    } else {
      c.step = 0.5;  // deg
      const double lat = b.lat_deg + b.fit_lat_error_deg;
      c.site_minus = geo::Site::At(lat - c.step, b.lon_deg, b.height_m, "study");
      c.site_plus = geo::Site::At(lat + c.step, b.lon_deg, b.height_m, "study");
      if (b.fit_gravity_m_s2 > 0.0) {
        c.site_minus.g_n = c.site_plus.g_n = Vec3(0.0, 0.0, b.fit_gravity_m_s2);
      }
    }
    changes.push_back(c);
  }
  return changes;
}

/// The run's d_dp in SensitivityFactors order: the fit-side ones (`fit_side`, from the fit
/// itself), then a refit with the probe for each missing effect.
std::vector<std::vector<double>> Sensitivities(const Study& study, const sim::Simulation& s,
                                               const std::vector<StillSegment>& segments,
                                               const geo::Site& site, const model::Model& fitted,
                                               const estimation::CalibrationOptions& options,
                                               const estimation::Sensitivities& fit_side) {
  std::vector<std::vector<double>> out;
  Eigen::Index next = 0;
  for (const std::string& name : SensitivityFactors(study)) {
    if (name.rfind("truth.", 0) == 0) {
      out.push_back(MissingEffectSensitivity(name.substr(6), s, segments, site, fitted, options,
                                             fitted.ParameterNames()));
    } else {
      const auto col = fit_side.d_dp.col(next++);
      out.emplace_back(col.data(), col.data() + col.size());
    }
  }
  return out;
}

/// d_dp per parameter (rows as `names`) carried to the rows a run scored: the parameters
/// themselves, and the determined combinations sum_i c_i theta_i of a one-pose design
/// (Combinations), whose sensitivity is sum_i c_i d theta_i / dp (the parameters the gauge
/// holds, NaN in d_dp, do not move).
std::vector<std::vector<double>> OnScoredRows(const std::vector<std::vector<double>>& d_dp,
                                              const std::vector<std::string>& names,
                                              const estimation::CalibrationResult& result,
                                              const RunOutcome& out) {
  if (out.names == names) return d_dp;
  const auto& determined = result.calibration.observability.determined;
  const auto index_of = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
  };
  std::vector<std::vector<double>> rows;
  for (const std::vector<double>& column : d_dp) {
    std::vector<double> scored;
    for (const std::string& row : out.names) {
      if (const std::size_t i = index_of(row); i < names.size()) {
        scored.push_back(column[i]);
        continue;
      }
      const auto c = std::find_if(determined.begin(), determined.end(),
                                  [&](const estimation::Combination& d) { return d.text == row; });
      double sum = c == determined.end() ? kNaN : 0.0;
      for (std::size_t k = 0; c != determined.end() && k < c->names.size(); ++k) {
        const std::size_t i = index_of(c->names[k]);
        const double d = i < names.size() ? column[i] : kNaN;
        sum += std::isnan(d) ? 0.0 : c->coefficients[k] * d;
      }
      scored.push_back(sum);
    }
    rows.push_back(scored);
  }
  return rows;
}

}  // namespace

sim::Schedule TemplateSchedule(const nlohmann::json& doc, const std::string& path) {
  struct Hold {
    Quat R_n_b;
    double begin, end, t_mid;
  };
  std::vector<Hold> holds;
  const nlohmann::json* segments = doc.is_object() && doc.contains("segments") ? &doc.at("segments") : nullptr;
  if (segments == nullptr || !segments->is_array() || segments->size() < 2) {
    throw InputError(path, "key 'segments'", "a session template needs the still segments of " +
                                             OptionText(Option::kCalibrationJson) + " (2 or more)",
                     {Option::kCalibrationJson});
  }
  for (std::size_t k = 0; k < segments->size(); ++k) {
    const nlohmann::json& seg = segments->at(k);
    const std::string where = "key 'segments[" + std::to_string(k) + "]'";
    try {
      const auto q = seg.at("attitude_quaternion_wxyz").get<std::vector<double>>();
      if (q.size() != 4) throw InputError(path, where, "expected attitude_quaternion_wxyz [w, x, y, z]");
      holds.push_back({Quat(q[0], q[1], q[2], q[3]).normalized(), seg.at("begin").get<double>(),
                       seg.at("end").get<double>(), seg.at("t_mid_s").get<double>()});
    } catch (const nlohmann::json::exception&) {
      throw InputError(path, where, "expected attitude_quaternion_wxyz, begin, end and t_mid_s");
    }
  }
  const Hold& first = holds.front();
  const Hold& last = holds.back();
  const double samples = 0.5 * ((last.begin + last.end) - (first.begin + first.end));
  const double dt = samples > 0.0 ? (last.t_mid - first.t_mid) / samples : 0.0;
  if (!(dt > 0.0)) throw InputError(path, "key 'segments'", "cannot tell the sample interval");
  sim::Schedule schedule(first.R_n_b);
  for (std::size_t k = 0; k < holds.size(); ++k) {
    if (k > 0) schedule.TurnTo(holds[k].R_n_b, std::max(0.5, (holds[k].begin - holds[k - 1].end) * dt));
    schedule.Hold(std::max(dt, (holds[k].end - holds[k].begin) * dt), "template still #" + std::to_string(k + 1));
  }
  return schedule;
}

std::vector<std::string> SensitivityFactors(const Study& study) {
  std::vector<std::string> out;
  if (study.fit_method != "generalized") return out;
  const model::Model fitted = model::Model::Parse(study.fit_model);
  for (const Factor& f : study.factors) {
    if (f.name == "fit_gravity_m_s2" || f.name == "fit_lat_error_deg") out.push_back(f.name);
    // What the paper's static hold is assumed to be (level, x north) against what it is.
    if ((f.name == "level_error_deg" || f.name == "heading_error_deg") &&
        study.base.schedule == "paper_static") {
      out.push_back(f.name);
    }
    // A true parameter of an effect the fit lacks: the bias it leaves (MissingEffectSensitivity).
    if (f.name.rfind("truth.", 0) == 0 && !fitted.FindParameter(f.name.substr(6))) {
      out.push_back(f.name);
    }
  }
  return out;
}

RunOutcome RunOnce(const Study& study, const Point& point, int run) {
  const Base b = Apply(study, DrawUncertainFactors(study, point, run));
  const std::uint64_t seed = RunSeed(study.seed, point.index, run);
  const model::Model sim_model =
      model::Model::Parse(study.simulate_model.empty() ? study.fit_model : study.simulate_model);
  const sim::SimulationOptions sensor = SensorOf(b, sim_model, seed);
  const sim::Simulation s = sim::Simulate(ScheduleOf(study, b, seed), sensor);
  std::vector<StillSegment> segments = s.truth_segments;
  for (auto& seg : segments) {
    // Unknown attitudes, but on the paper's static design: level, x north, as assumed.
    if (b.schedule == "paper_static") {
      seg.known_R_n_b = Quat::Identity();
    } else {
      seg.known_R_n_b.reset();
    }
  }
  geo::Site site = geo::Site::At(b.lat_deg + b.fit_lat_error_deg, b.lon_deg, b.height_m, "study");
  if (b.fit_gravity_m_s2 > 0.0) site.g_n = Vec3(0.0, 0.0, b.fit_gravity_m_s2);
  model::Model fitted = model::Model::Parse(study.fit_model);
  fitted.t_ref_s = s.model.t_ref_s;
  fitted.temp_ref_c = s.model.temp_ref_c;
  estimation::CalibrationOptions options;
  options.constant_bias = study.constant_bias;
  if (study.wander_levels_given) {
    options.accel_walk_density = sensor.accel_bias_walk_density;
    options.gyro_walk_density = sensor.gyro_bias_walk_density;
    options.accel_instability = sensor.accel_bias_instability;
    options.gyro_instability = sensor.gyro_bias_instability;
    options.instability_time_s = sensor.bias_instability_time_s;
  }
  RunOutcome out;
  if (study.fit_method == "paper_static_backend") {
    try {
      const paper::PaperStaticBackend backend = paper::CalibratePaperStaticOnBackend(
          s.session.series, segments.front().begin, segments.front().end, site);
      out.chi2_dof = backend.fixed.fit.chi2_dof();
      out.flagged = !backend.fixed.fit.gates.empty();
      Score(backend.fixed, s, backend.fixed.calibration.model, out);
    } catch (const Error& e) {
      out.failed = true;
      out.failure = e.what();
    }
    return out;
  }
  if (study.fit_method == "paper_static" || study.fit_method == "paper_benchmark") {
    try {
      PaperClosedForm(study, s, segments, site, fitted, out);
    } catch (const Error& e) {
      out.failed = true;
      out.failure = e.what();
    }
    return out;
  }
  try {
    // One fit, and the fit-side sensitivities on its solution.
    const estimation::SensitiveCalibration fit = estimation::CalibrateWithSensitivities(
        s.session.series, segments, fitted, site, options, FitSideChanges(study, b, segments, site));
    const estimation::CalibrationResult& result = fit.result;
    out.chi2_dof = result.fit.chi2_dof();
    out.flagged = !result.fit.gates.empty();
    if (!result.fit.converged) {
      out.failed = true;
      out.failure = "not converged";
    }
    Score(result, s, fitted, out);
    out.d_dp = OnScoredRows(Sensitivities(study, s, segments, site, fitted, options, fit.sensitivities),
                            fitted.ParameterNames(), result, out);
  } catch (const Error& e) {
    out.failed = true;
    out.failure = e.what();
  }
  return out;
}

}  // namespace plumb::study

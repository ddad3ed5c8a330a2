#include "plumb/report/json_report.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <map>

#include "plumb/document/calibration_keys.h"
#include "plumb/estimation/uncertainty.h"
#include "plumb/io/common/atomic_file.h"
#include "plumb/model/board_mount.h"
#include "plumb/report/version.h"

namespace plumb::report {
namespace {

using nlohmann::json;
namespace keys = document::keys;  // the key names its reader reads, spelled once

/// Names of the model's non-base effects, for the correction's note.
std::vector<std::string> ExtraEffects(const model::Model& model, model::Sensor sensor) {
  std::vector<std::string> out;
  for (const auto& term : model.terms()) {
    const auto& info = term.effect->info();
    if (!info.linear_stage && info.sensor == sensor) out.push_back(info.name);
  }
  return out;
}

/// The correction a user applies, x = M^-1 (y - b), labelled; null matrix when M is singular.
json Correction(const Mat3& forward, const Vec3& bias, const std::string& formula,
                const std::vector<std::string>& extra_effects) {
  const Eigen::FullPivLU<Mat3> lu(forward);
  json c;
  c["formula"] = formula;
  c["matrix"] = lu.isInvertible() ? Matrix(lu.inverse()) : json(nullptr);
  c["offset"] = Vector(bias);
  if (!extra_effects.empty()) {
    std::string list;
    for (const auto& e : extra_effects) list += (list.empty() ? "" : ", ") + e;
    c["note"] = "linear part only: the terms of " + list +
                " (see effects) must be subtracted from the output first";
  }
  return c;
}

json Sensor(const Mat3& forward, const Vec3& bias, const json& correction) {
  return json{{keys::kMatrix, Matrix(forward)},
              {keys::kBias, Vector(bias)},
              {"correction", correction}};
}

/// `sigma_scale` (estimation::SigmaScale) multiplies "sigma"; "sigma_formal" is the fit's own.
json ParameterJson(const estimation::ParameterEstimate& p, double sigma_scale) {
  const bool none = p.fixed || !p.observable;
  return json{{keys::kName, p.name},
              {keys::kValue, Number(p.value)},
              {keys::kSigma, none ? json(nullptr) : Number(sigma_scale * p.sigma)},
              {"sigma_formal", none ? json(nullptr) : Number(p.sigma)},
              {keys::kObservable, p.observable},
              {keys::kFixed, p.fixed},
              {keys::kUnit, p.unit}};
}

/// One entry of "effects": the effect's parameters in block order with sigma and units.
json EffectJson(const model::EffectInfo& info,
                const std::map<std::string, const estimation::ParameterEstimate*>& by_name,
                double sigma_scale) {
  json names = json::array(), values = json::array(), sigmas = json::array(), units = json::array();
  json formal = json::array();
  bool uniform = true;
  for (int i = 0; i < info.size(); ++i) {
    const std::string full = info.ParameterName(i);
    const auto& unit = info.parameters[static_cast<std::size_t>(i)].unit;
    uniform = uniform && unit == info.parameters.front().unit;
    names.push_back(full);
    units.push_back(unit);
    const auto it = by_name.find(full);
    if (it == by_name.end()) {
      values.push_back(nullptr);
      sigmas.push_back(nullptr);
      formal.push_back(nullptr);
      continue;
    }
    const auto& p = *it->second;
    const bool none = p.fixed || !p.observable;
    values.push_back(Number(p.value));
    sigmas.push_back(none ? json(nullptr) : Number(sigma_scale * p.sigma));
    formal.push_back(none ? json(nullptr) : Number(p.sigma));
  }
  json e{{"term", info.term},
         {"option", info.option},
         {"names", names},
         {"parameters", values},
         {"sigma", sigmas},
         {"sigma_formal", formal}};
  e["unit"] = (uniform && info.size() > 0) ? json(info.parameters.front().unit) : units;
  return e;
}

/// "effects" of `model`'s terms beyond the linear stage, from `parameters` named `prefix` +
/// the effect's names ("imu2." for a board IMU's, "" for IMU 0's).
json EffectsOf(const model::Model& model, const std::vector<estimation::ParameterEstimate>& parameters,
               const std::string& prefix, double sigma_scale) {
  std::map<std::string, const estimation::ParameterEstimate*> by_name;
  for (const auto& p : parameters) {
    if (p.name.compare(0, prefix.size(), prefix) == 0) by_name[p.name.substr(prefix.size())] = &p;
  }
  json effects = json::object();
  for (const auto& term : model.terms()) {
    const auto& info = term.effect->info();
    if (!info.linear_stage) effects[info.name] = EffectJson(info, by_name, sigma_scale);
  }
  return effects;
}

json EffectsJson(const estimation::CalibrationResult& r) {
  return EffectsOf(r.calibration.model, r.calibration.parameters, "", estimation::SigmaScale(r.fit));
}

json LinearityJson(const estimation::LinearityReport& l) {
  if (!l.checked) return nullptr;
  return json{{"step_sigmas", Number(l.step_sigmas)},
              {"worst_ratio", Number(l.worst_ratio)},
              {"worst_direction", l.worst_direction}};
}

json FitJson(const estimation::CalibrationResult& r) {
  const auto& f = r.fit;
  json rms{{"accel", Vector(f.rms_acc)},
           {"gyro", r.calibration.has_gyro ? Vector(f.rms_gyr) : json(nullptr)},
           {"motion", f.motion_segments > 0 ? Vector(f.rms_motion) : json(nullptr)}};
  return json{{"chi2", Number(f.chi2)},
              {keys::kDof, f.dof},
              {keys::kChi2Dof, Number(f.chi2_dof())},
              {"num_residuals", f.num_residuals},
              {"residual_rms", rms},
              {"segments", {{"still", f.still_segments}, {"motion", f.motion_segments}}},
              {"converged", f.converged},
              {"iterations", f.iterations},
              {"solves", f.solves},
              {"last_solve_iterations", f.last_solve_iterations},
              {"solver", f.solver_report},
              {"chi2_above_band", estimation::Chi2AboveBand(f)},
              {"misfit_beyond_noise", estimation::MisfitBeyondNoise(f)},
              {"distinct_poses", f.distinct_poses},
              {"linearity", LinearityJson(f.linearity)}};
}

json ObservabilityJson(const estimation::Observability& o, double sigma_scale) {
  json determined = json::array();
  for (const auto& d : o.determined) {
    determined.push_back({{keys::kCombination, d.text},
                          // The combination as numbers: sum of coefficients[i] * parameters[i].
                          {keys::kParameters, d.names},
                          {keys::kCoefficients, d.coefficients},
                          {keys::kValue, Number(d.value)},
                          {keys::kSigma, Number(sigma_scale * d.sigma)},
                          {"sigma_formal", Number(d.sigma)}});
  }
  json weak = json::array();
  for (const auto& w : o.weakly_determined) {
    weak.push_back({{keys::kCombination, w.text},
                    {keys::kParameters, w.names},
                    {keys::kCoefficients, w.coefficients},
                    {"held_at", Number(w.value)},
                    {"sigma_data", Number(w.sigma)},
                    {"typical", Number(w.typical)}});
  }
  return json{{"rank", o.rank},
              {"unknowns", o.num_unknowns},
              {"wander_states", o.wander_states},
              {"unobservable", o.unobservable},
              {"weakly_determined", weak},
              {keys::kDetermined, determined}};
}

json SiteJson(const geo::Site& site) {
  const json none(nullptr);
  return json{{"lat_deg", site.known ? Number(site.lat_deg) : none},
              {"lon_deg", site.known ? Number(site.lon_deg) : none},
              {"height_m", site.known ? Number(site.height_m) : none},
              {keys::kGravity, Number(site.gravity())},
              {"earth_rate", site.known ? Number(site.omega_ie_n.norm()) : none},
              {keys::kSource, site.known ? site.source : std::string("none")}};
}

json NoiseJson(const estimation::CalibrationResult& r) {
  const auto& n = r.calibration.noise;
  json out{{keys::kAccel, Vector(n.acc)},
           {"gyro", r.calibration.has_gyro ? Vector(n.gyr) : json(nullptr)},
           {"tau_accel", Number(n.tau_acc)},
           {"tau_gyro", r.calibration.has_gyro ? Number(n.tau_gyr) : json(nullptr)},
           {"units", "sensor units per sample; tau in samples"}};
  // The bias random walk the fit assumed (present only when the bias walked in the fit).
  const bool acc_walk = n.walk_acc.minCoeff() > 0;
  const bool gyr_walk = n.walk_gyr.minCoeff() > 0;
  if (acc_walk || gyr_walk) {
    out["walk_accel"] = acc_walk ? Vector(n.walk_acc) : json(nullptr);
    out["walk_gyro"] = gyr_walk ? Vector(n.walk_gyr) : json(nullptr);
    out["walk_units"] = "sensor units / s / sqrt(Hz) (bias random walk density)";
  }
  // The bias instability the fit assumed (a Gauss-Markov process), when it did.
  const bool acc_bi = n.instability_acc.minCoeff() > 0;
  const bool gyr_bi = n.instability_gyr.minCoeff() > 0;
  if (acc_bi || gyr_bi) {
    out["instability_accel"] = acc_bi ? Vector(n.instability_acc) : json(nullptr);
    out["instability_gyro"] = gyr_bi ? Vector(n.instability_gyr) : json(nullptr);
    out["instability_time_s"] = Number(n.instability_time_s);
    out["instability_units"] = "sensor units (Gauss-Markov sigma); correlation time in s";
  }
  // Quantisation, when the still data resolved it on some axis.
  const bool acc_q = !n.quantisation_acc.isZero(), gyr_q = !n.quantisation_gyr.isZero();
  if (acc_q || gyr_q) {
    out["quantisation_accel"] = Vector(n.quantisation_acc);
    out["quantisation_gyro"] = r.calibration.has_gyro ? Vector(n.quantisation_gyr) : json(nullptr);
    out["quantisation_units"] = "sensor units x s (IEEE Q)";
  }
  // Where each wander level came from, per axis (estimation/wander_levels.h).
  if (acc_walk || gyr_walk || acc_bi || gyr_bi) {
    auto sources = [](const std::array<estimation::LevelSource, 3>& from) {
      json list = json::array();
      for (estimation::LevelSource s : from) list.push_back(estimation::LevelSourceName(s));
      return list;
    };
    out["sources"] = {{"walk_accel", sources(n.from.walk_acc)},
                      {"walk_gyro", sources(n.from.walk_gyr)},
                      {"instability_accel", sources(n.from.instability_acc)},
                      {"instability_gyro", sources(n.from.instability_gyr)},
                      {"meaning", "given: an option; allan: the Allan deviation of still data; "
                                  "allan_bound: its 95% upper bound, below the typical level; "
                                  "typical: the typical MEMS sensor; estimated: --estimate-rw; "
                                  "none: not in the fit"}};
  }
  return out;
}

json StillJson(const estimation::StillSegmentFit& s, bool has_gyro) {
  const Quat& q = s.R_n_b;
  json out{
      {keys::kLabel, s.segment.label},
      {"begin", s.segment.begin},
      {"end", s.segment.end},
      {"t_mid_s", Number(s.t_mid_s)},
      {keys::kCount, s.count},
      {keys::kAccMean, Vector(s.acc_mean)},
      {"gyr_mean", has_gyro ? Vector(s.gyr_mean) : json(nullptr)},
      {"acc_residual", Vector(s.acc_residual)},
      {"gyr_residual", has_gyro ? Vector(s.gyr_residual) : json(nullptr)},
      {"acc_whitened", Vector(s.acc_whitened)},
      {"gyr_whitened", has_gyro ? Vector(s.gyr_whitened) : json(nullptr)},
      {"attitude_quaternion_wxyz", {Number(q.w()), Number(q.x()), Number(q.y()), Number(q.z())}},
      {"attitude_known", s.attitude_known}};
  // With a bias random walk in the fit: the walk's mean over the segment, sensor units.
  if (!s.acc_walk.isZero()) out["acc_walk"] = Vector(s.acc_walk);
  if (!s.gyr_walk.isZero()) out["gyr_walk"] = Vector(s.gyr_walk);
  return out;
}

json MotionJson(const estimation::MotionFit& m) {
  json out{{"from", m.from},
           {"to", m.to},
           {"duration_s", Number(m.duration_s)},
           {"rotation_residual", Vector(m.rotation_residual)},
           {"whitened", Vector(m.whitened)}};
  if (m.has_velocity) {
    out["velocity_residual"] = Vector(m.velocity_residual);
    out["velocity_whitened"] = Vector(m.velocity_whitened);
  }
  return out;
}

json NoiseEstimateJson(const segmentation::NoiseEstimate& n) {
  json periods = json::array();
  for (const auto& p : n.periods) periods.push_back(json::array({p.begin, p.end}));
  json out{{"periods", periods},
           {"samples", n.samples},
           {"source", n.source},
           {"acc_mean", Vector(n.acc_mean)},
           {"acc_sigma", Vector(n.acc_sigma)},
           {"acc_tau_int", Vector(n.acc_tau_int)}};
  out["gyr_sigma"] = n.has_gyro ? Vector(n.gyr_sigma) : json(nullptr);
  out["gyr_tau_int"] = n.has_gyro ? Vector(n.gyr_tau_int) : json(nullptr);
  out["gyr_still_rate"] = n.has_gyro ? Vector(n.gyr_still_rate) : json(nullptr);
  return out;
}

json DetectionJson(const segmentation::DetectionDetail& d) {
  return json{{"window_samples", d.window_samples},
              {"acc_dof", Number(d.acc_dof)},
              {"acc_threshold", Number(d.acc_threshold)},
              {"gyr_dof", Number(d.gyr_dof)},
              {"gyr_threshold", Number(d.gyr_threshold)},
              {"rate_threshold", Number(d.rate_threshold)},
              {"rate_allowance", Vector(d.rate_allowance)},
              {"windows", d.windows},
              {"failed_acc", d.failed_acc},
              {"failed_gyr", d.failed_gyr},
              {"failed_rate", d.failed_rate},
              {"failed_gap", d.failed_gap},
              {"still_runs", d.still_runs},
              {"rejected_by_gyro", d.rejected_by_gyro}};
}

}  // namespace

json Number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

json LogMotionJson(const LogMotion& m) {
  const bool gps = m.evidence == LogMotion::Evidence::kGpsMoving;
  json j = {{"evidence", gps ? "gps_moving" : "airborne"},
            {"t_begin_s", Number(m.t_begin_s)},
            {"t_end_s", Number(m.t_end_s)},
            {"source", m.source}};
  if (gps) {
    j["max_ground_speed_m_s"] = Number(m.max_ground_speed_m_s);
    j["max_climb_m_s"] = Number(m.max_climb_m_s);
    j["ground_distance_m"] = Number(m.ground_distance_m);
  }
  return j;
}

json Vector(const Vec3& v) { return json::array({Number(v.x()), Number(v.y()), Number(v.z())}); }

json Matrix(const Mat3& m) {
  json rows = json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(Vector(m.row(r).transpose()));
  return rows;
}

namespace {

json Rows(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    json row = json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(Number(m(r, c)));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

json CovarianceJson(const estimation::CalibrationResult& r) {
  const double scale = estimation::SigmaScale(r.fit);
  const estimation::NamedCovariance params = estimation::ParameterCovariance(r.calibration);
  const estimation::NamedCovariance combos = estimation::DeterminedCovariance(r.calibration);
  json units = json::array();
  for (const auto& name : params.names) {
    for (const auto& p : r.calibration.parameters) {
      if (p.name == name) units.push_back(p.unit);
    }
  }
  return json{{keys::kParameters, params.names},
              {"units", units},
              {keys::kMatrix, Rows(scale * scale * params.matrix)},
              {keys::kSigmaScaledByChi2, scale > 1.0},
              {"sigma_scale", scale},
              {keys::kDetermined,
               {{"combinations", combos.names},
                {keys::kMatrix, Rows(scale * scale * combos.matrix)}}}};
}

/// The mount of a board IMU as SPEC 6's "imus" entries give it: "rotation" {matrix, vector,
/// sigma}, "lever_arm" {value, sigma}, "time_offset" {value, sigma} (sigma null where held or
/// undetermined); IMU 0's is the identity with zero sigma.
json MountJson(const Quat& R_b_i, const Vec3& rho_sigma, const Vec3& lever_arm,
               const Vec3& lever_sigma, double time_offset, double time_sigma) {
  auto sigmas = [](const Vec3& v) {
    return json::array({Number(v.x()), Number(v.y()), Number(v.z())});
  };
  const Eigen::AngleAxisd aa(R_b_i);
  return json{{"rotation",
               {{keys::kMatrix, Matrix(R_b_i.toRotationMatrix())},
                {"vector", Vector(aa.angle() * aa.axis())},
                {keys::kSigma, sigmas(rho_sigma)}}},
              {"lever_arm", {{keys::kValue, Vector(lever_arm)}, {keys::kSigma, sigmas(lever_sigma)}}},
              {"time_offset", {{keys::kValue, Number(time_offset)}, {keys::kSigma, Number(time_sigma)}}}};
}

/// One board IMU's entry of "imus": its sensors, parameters and mount.
json BoardImuJson(const estimation::BoardImuCalibration& b, double sigma_scale) {
  json entry{{"instance", b.instance}, {keys::kModel, b.model.spec()}};
  entry[keys::kAccel] = Sensor(b.AccelMatrix(), b.AccelBias(),
                               Correction(b.AccelMatrix(), b.AccelBias(), "f_i = matrix (y_a - offset)",
                                          ExtraEffects(b.model, model::Sensor::kAccel)));
  entry[keys::kGyro] = b.has_gyro ? Sensor(b.GyroMatrix(), b.GyroBias(),
                                           Correction(b.GyroMatrix(), b.GyroBias(),
                                                      "omega_i = matrix (y_g - offset)",
                                                      ExtraEffects(b.model, model::Sensor::kGyro)))
                                  : json(nullptr);
  entry["effects"] =
      EffectsOf(b.model, b.parameters, "imu" + std::to_string(b.instance) + ".", sigma_scale);
  entry[keys::kParameters] = json::array();
  for (const auto& p : b.parameters) entry[keys::kParameters].push_back(ParameterJson(p, sigma_scale));
  auto sigma = [&](int i) {
    const auto& p = b.MountParameter(i);
    return p.fixed || !p.observable ? std::nan("") : sigma_scale * p.sigma;
  };
  using model::board_mount::kLeverArm;
  using model::board_mount::kRotation;
  const Vec3 rho_sigma(sigma(kRotation), sigma(kRotation + 1), sigma(kRotation + 2));
  const Vec3 lever_sigma(sigma(kLeverArm), sigma(kLeverArm + 1), sigma(kLeverArm + 2));
  entry.update(MountJson(b.R_b_i(), rho_sigma, b.LeverArm(), lever_sigma, b.TimeOffset(),
                         sigma(model::board_mount::kTimeOffset)));
  entry["turn_comparison"] = {{"chi2", Number(b.turn_chi2)}, {"residuals", b.turn_residuals}};
  return entry;
}

/// SPEC 6's "imus" (IMU 0 first, at the identity) and the one covariance over every IMU's
/// parameters ("imus_covariance": parameters, units, matrix; scaled as "covariance").
void AddBoardJson(const estimation::CalibrationResult& r, json& doc) {
  const estimation::Calibration& c = r.calibration;
  if (c.board.empty()) return;
  const double scale = estimation::SigmaScale(r.fit);
  json imu0{{"instance", 0}, {keys::kModel, c.model.spec()}};
  imu0[keys::kAccel] = doc[keys::kAccel];
  imu0[keys::kGyro] = doc[keys::kGyro];
  imu0["effects"] = doc["effects"];
  imu0.update(MountJson(Quat::Identity(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), 0.0, 0.0));
  json imus = json::array({imu0});
  json names = json::array(), units = json::array();
  for (const auto& p : c.parameters) {
    names.push_back(p.name);
    units.push_back(p.unit);
  }
  for (const auto& b : c.board) {
    imus.push_back(BoardImuJson(b, scale));
    for (const auto& p : b.parameters) {
      names.push_back(p.name);
      units.push_back(p.unit);
    }
  }
  doc["imus"] = imus;
  doc["imus_covariance"] = {{keys::kParameters, names},
                            {"units", units},
                            {keys::kMatrix, Rows(scale * scale * c.board_covariance)},
                            {keys::kSigmaScaledByChi2, scale > 1.0}};
}

json GatesJson(const estimation::FitReport& fit) {
  json gates = json::array();
  for (const auto& g : fit.gates) gates.push_back({{"name", g.name}, {"message", g.message}});
  return gates;
}

json ToJson(const estimation::CalibrationResult& r) {
  json doc;
  doc["schema_version"] = kSchemaVersion;
  doc["plumb_version"] = Version();
  doc[keys::kMethod] = r.calibration.method;
  doc[keys::kModel] = r.calibration.model.spec();
  doc[keys::kModelReference] = {{keys::kTRefS, Number(r.calibration.model.t_ref_s)},
                                {keys::kTempRefC, Number(r.calibration.model.temp_ref_c)}};
  doc["convention"] = {
      {"frame", "body = accelerometer-defined, FRD; navigation NED; SI units"},
      {"accel",
       "forward: y_a = matrix f_b + bias + effects; correction: f_b = correction.matrix "
       "(y_a - correction.offset)"},
      {"gyro",
       "forward: y_g = matrix omega_b + bias + effects; correction: omega_b = "
       "correction.matrix (y_g - correction.offset)"}};
  doc[keys::kAccel] = Sensor(r.calibration.AccelMatrix(), r.calibration.AccelBias(),
                        Correction(r.calibration.AccelMatrix(), r.calibration.AccelBias(), "f_b = matrix (y_a - offset)",
                                   ExtraEffects(r.calibration.model, model::Sensor::kAccel)));
  doc[keys::kGyro] =
      r.calibration.has_gyro ? Sensor(r.calibration.GyroMatrix(), r.calibration.GyroBias(),
                          Correction(r.calibration.GyroMatrix(), r.calibration.GyroBias(), "omega_b = matrix (y_g - offset)",
                                     ExtraEffects(r.calibration.model, model::Sensor::kGyro)))
                 : json(nullptr);
  doc["effects"] = EffectsJson(r);
  doc[keys::kParameters] = json::array();
  const double sigma_scale = estimation::SigmaScale(r.fit);
  for (const auto& p : r.calibration.parameters) {
    doc[keys::kParameters].push_back(ParameterJson(p, sigma_scale));
  }
  doc[keys::kCovariance] = CovarianceJson(r);
  AddBoardJson(r, doc);
  doc[keys::kFit] = FitJson(r);
  doc["gates"] = GatesJson(r.fit);
  doc[keys::kObservability] = ObservabilityJson(r.calibration.observability, sigma_scale);
  doc[keys::kSite] = SiteJson(r.calibration.site);
  doc[keys::kNoise] = NoiseJson(r);
  doc[keys::kSegments] = json::array();
  for (const auto& s : r.fit.still) {
    doc[keys::kSegments].push_back(StillJson(s, r.calibration.has_gyro));
  }
  doc["motion"] = json::array();
  for (const auto& m : r.fit.motion) doc["motion"].push_back(MotionJson(m));
  doc["not_turns"] = json::array();
  for (const auto& m : r.fit.not_turns) {
    json j = {{"from", m.from},
              {"to", m.to},
              {"t_begin_s", Number(m.t_begin_s)},
              {"t_end_s", Number(m.t_end_s)},
              {"limit_s", Number(m.limit_s)},
              {"reason", m.flown ? "log_says_flown" : m.gap ? "gap_in_samples" : "too_long"}};
    if (m.flown) j["log_motion"] = LogMotionJson(*m.flown);
    if (m.gap) {
      j["gap"] = {{"t_s", Number(m.gap->t_s)},
                  {"length_s", Number(m.gap->length_s)},
                  {"limit_s", Number(m.gap_limit_s)}};
    }
    doc["not_turns"].push_back(j);
  }
  doc["warnings"] = Messages(r.fit.warnings);  // the messages; the codes are not in SPEC 6
  if (!r.fit.notes.empty()) doc["notes"] = Messages(r.fit.notes);
  return doc;
}

json ToJson(const segmentation::SegmentationResult& s) {
  const auto& rep = s.report;
  const bool detected = rep.method != "given";
  json out{{"method", rep.method},
           {"segments", s.segments.size()},
           {"window_s", detected ? Number(rep.window_s) : json(nullptr)},
           {"min_still_s", detected ? Number(rep.min_still_s) : json(nullptr)},
           {"init_still_s", detected ? Number(rep.init_still_s) : json(nullptr)},
           {"threshold", detected ? Number(rep.threshold) : json(nullptr)},
           {"rejected_short", rep.rejected_short},
           {"notes", rep.notes}};
  out["noise"] = detected ? NoiseEstimateJson(s.noise) : json(nullptr);
  out["thresholds"] = detected ? DetectionJson(s.detail) : json(nullptr);
  return out;
}

json CalibrationJson(const estimation::CalibrationResult& result,
                     const segmentation::SegmentationResult& segmentation,
                     const std::vector<std::string>& inputs,
                     const std::vector<Notice>& input_warnings) {
  json doc = ToJson(result);
  doc["segmentation"] = ToJson(segmentation);
  doc[keys::kInputs] = inputs;
  std::vector<std::string> warnings = Messages(input_warnings);
  for (const Notice& w : result.fit.warnings) warnings.push_back(w.message);
  doc["warnings"] = warnings;
  return doc;
}

std::string JsonText(const json& document) {
  return document.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

void WriteJson(const std::string& path, const json& document) {
  io::WriteFileAtomic(path, JsonText(document));
}

}  // namespace plumb::report

#include "plumb/estimation/calibration_problem.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "plumb/core/error.h"
#include "plumb/estimation/turn_noise.h"
#include "plumb/residuals/bias_walk_residual.h"
#include "plumb/residuals/held_combination.h"
#include "plumb/residuals/manifolds.h"
#include "plumb/residuals/motion_residual.h"
#include "plumb/residuals/still_residuals.h"
#include "plumb/residuals/velocity_residual.h"

namespace plumb::estimation {
namespace {

/// Adds the diagonal of M diag(v) M^T to the variances behind `sqrt_info` (1 / sigma).
void AddVariance(Vec3& sqrt_info, const Mat3& M, const Vec3& v) {
  const Mat3 cov = M * v.asDiagonal() * M.transpose();
  for (int i = 0; i < 3; ++i) {
    sqrt_info[i] = 1.0 / std::sqrt(1.0 / (sqrt_info[i] * sqrt_info[i]) + cov(i, i));
  }
}

/// Shortest time a bias-walk factor spans, s: keeps its weight finite where two instants
/// coincide.
constexpr double kMinWalkSpan_s = 1e-3;

/// Dense copy of a Ceres CRS matrix.
Eigen::MatrixXd Dense(const ceres::CRSMatrix& crs) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int idx = crs.rows[static_cast<std::size_t>(row)];
         idx < crs.rows[static_cast<std::size_t>(row) + 1]; ++idx) {
      out(row, crs.cols[static_cast<std::size_t>(idx)]) = crs.values[static_cast<std::size_t>(idx)];
    }
  }
  return out;
}

/// Sparse (column-major) copy of a Ceres CRS matrix, which is Eigen's compressed row-major
/// layout.
Eigen::SparseMatrix<double> Sparse(const ceres::CRSMatrix& crs) {
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor, int>> rows(
      crs.num_rows, crs.num_cols, static_cast<Eigen::Index>(crs.values.size()), crs.rows.data(),
      crs.cols.data(), crs.values.data());
  return Eigen::SparseMatrix<double>(rows);
}

/// The typical size of parameter i of `info` in its column's unit: the catalogue's (SI), times
/// the output's sensitivity (the mean diagonal of F or E: about 1 on SI output, and what the
/// data show whatever the input's unit says, as on imu_tk's counts read as SI) where the
/// parameter is in output units (the linear stage, and EffectInfo::ScalesWithOutput's
/// additive terms).
double TypicalSize(const model::EffectInfo& info, int i, const Mat3& F, const Mat3& E) {
  const double typical = info.parameters[static_cast<std::size_t>(i)].typical;
  if (!info.linear_stage && !info.ScalesWithOutput(i)) return typical;
  return typical * (info.sensor == model::Sensor::kAccel ? F : E).diagonal().cwiseAbs().mean();
}

}  // namespace

CalibrationProblem::CalibrationProblem(const ImuSeries& series, model::Model model,
                                       const geo::Site& site, StillSet still,
                                       model::ParameterBlocks theta, const NoiseModel& noise,
                                       const StartingValues& start,
                                       const CalibrationOptions& options)
    : series_(series),
      model_(std::move(model)),
      site_(site),
      options_(options),
      still_(std::move(still)),
      noise_(noise),
      start_(start) {
  has_gyro_ = model_.has_gyro();
  for (const auto& block : theta) {
    block_offset_.push_back(values_.size());
    values_.insert(values_.end(), block.begin(), block.end());
  }
  q_offset_ = values_.size();
  for (const auto& s : still_.poses) values_.insert(values_.end(), s.q.begin(), s.q.end());
  walk_offset_ = values_.size();
  wander_ = noise_.Wander(has_gyro_);
  values_.resize(values_.size() + 6 * wander_.size() * still_.poses.size(), 0.0);
  still_gyro_ = has_gyro_ && options_.use_still_gyro;
  bool needs_velocity = false;
  for (const auto& term : model_.terms()) {
    needs_velocity = needs_velocity || term.effect->info().excitation.angular_acceleration;
  }
  const bool motion_on = options_.use_motion && has_gyro_;
  velocity_on_ = motion_on && options_.accel_in_motion.value_or(needs_velocity);
  SetMeasurements(noise);
  SetMotionSamples();
  velocity_info_.assign(still_.motions.size(), Vec3::Ones());
  SetMotionWeights(Mat3::Identity() / start_.gyro_rad_per_unit,
                   Mat3::Identity() * start_.accel.scale);
}

void CalibrationProblem::SetMeasurements(const NoiseModel& noise) {
  for (auto& s : still_.poses) {
    const double n = static_cast<double>(s.stats.count);
    residuals::StillMeasurement m;
    m.dt_s = s.stats.t_mid_s - model_.t_ref_s;
    m.dtemp_c = std::isfinite(s.stats.temp_mean_c) ? s.stats.temp_mean_c - model_.temp_ref_c : 0.0;
    m.mean = s.stats.acc_mean;
    for (int i = 0; i < 3; ++i) m.sqrt_info[i] = std::sqrt(n / noise.tau_acc[i]) / noise.sigma_acc[i];
    // Each wander process has a state at both ends of the segment; its bridge between them
    // adds BridgeMeanVariance (the walk's K^2 T / 12) to the variance of the segment's mean.
    const double T = s.stats.t_end_s - s.stats.t_begin_s;
    // Quantisation (IEEE Q) adds 2 Q^2 / T^2 (noise_model.h).
    auto add_bridges = [&](Vec3& sqrt_info, model::Sensor sensor) {
      Vec3 var = sqrt_info.cwiseAbs2().cwiseInverse();
      for (const WanderProcess& w : wander_) {
        if (w.sensor == sensor) var += w.BridgeMeanVariance(T);
      }
      const Vec3& Q = sensor == model::Sensor::kAccel ? noise.quantisation_acc : noise.quantisation_gyr;
      if (T > 0) var += Q.cwiseAbs2() * (2.0 / (T * T));
      sqrt_info = var.cwiseSqrt().cwiseInverse();
    };
    add_bridges(m.sqrt_info, model::Sensor::kAccel);
    s.acc_measurement = m;
    if (still_gyro_) {
      m.mean = s.stats.gyr_mean;
      for (int i = 0; i < 3; ++i) m.sqrt_info[i] = std::sqrt(n / noise.tau_gyr[i]) / noise.sigma_gyr[i];
      add_bridges(m.sqrt_info, model::Sensor::kGyro);
      s.gyr_measurement = m;
    }
  }
}

void CalibrationProblem::SetMotionSamples() {
  const ImuSeries& series = series_;
  for (const auto& mo : still_.motions) {
    residuals::MotionSamples ms;
    std::vector<Vec3> dy;
    const std::size_t n = mo.last + 1 - mo.first;
    ms.dt_s.reserve(n);
    ms.acc.reserve(n);
    ms.gyr.reserve(n);
    ms.dtemp_c.reserve(n);
    dy.reserve(n);
    for (std::size_t i = mo.first; i <= mo.last; ++i) {
      ms.dt_s.push_back(series.t_s[i] - model_.t_ref_s);
      ms.acc.push_back(series.acc[i].cast<double>());
      ms.gyr.push_back(series.gyr[i].cast<double>());
      ms.dtemp_c.push_back(series.has_temperature() ? series.temp_c[i] - model_.temp_ref_c : 0.0);
      const std::size_t a = i > 0 ? i - 1 : i, b = std::min(i + 1, series.size() - 1);
      const double h = series.t_s[b] - series.t_s[a];
      dy.push_back(h > 0 ? Vec3((series.gyr[b] - series.gyr[a]).cast<double>() / h) : Vec3::Zero());
    }
    ms.alpha_b.resize(dy.size());
    motion_samples_.push_back(std::make_shared<residuals::MotionSamples>(std::move(ms)));
    output_rate_.push_back(std::move(dy));
  }
}

// The angular acceleration input of the effects (time_offset, accel_size_effect) is the
// derivative of the corrected rate, E^-1 d y_g / dt (central differences). The velocity
// residual's variance: the accelerometer's white noise or the turn's measured vibration summed
// over the steps, and gravity tilted by the attitude random walk of the gyroscope's (mean over
// the axes), which moves the velocity only across gravity (turn_noise.h).
void CalibrationProblem::SetMotionWeights(const Mat3& E, const Mat3& F) {
  const auto& motions = still_.motions;
  const Mat3 E_inv = E.inverse();
  const Mat3 F_inv = F.inverse();
  const Mat3 cov_f = F_inv * noise_.sigma_acc.cwiseAbs2().asDiagonal() * F_inv.transpose();
  const Mat3 cov_rate = E_inv * noise_.sigma_gyr.cwiseAbs2().asDiagonal() * E_inv.transpose();
  const double g = site_.gravity();
  TurnNoise turn_noise;
  turn_noise.measure_vibration = options_.turn_vibration;
  turn_noise.cov_f = cov_f;
  turn_noise.tau_acc = noise_.tau_acc;
  turn_noise.var_rate = cov_rate.trace() / 3.0 * noise_.tau_gyr.mean();
  for (std::size_t k = 0; k < motions.size(); ++k) {
    // New samples (problems built before keep reading theirs).
    auto samples = std::make_shared<residuals::MotionSamples>(*motion_samples_[k]);
    for (std::size_t i = 0; i < output_rate_[k].size(); ++i) {
      samples->alpha_b[i] = E_inv * output_rate_[k][i];
    }
    const auto& mo = motions[k];
    const double steps = static_cast<double>(mo.last - mo.first);
    const double dt = (series_.t_s[mo.last] - series_.t_s[mo.first]) / std::max(1.0, steps);
    for (int i = 0; i < 3; ++i) {
      const double sigma_rate = std::sqrt(cov_rate(i, i));  // rad/s per sample
      samples->sqrt_info[i] =
          1.0 / (sigma_rate * dt * std::sqrt(std::max(1.0, steps) * noise_.tau_gyr[i]));
    }
    // Each gyroscope wander process about the line from e_k to s_k+1 integrates to an angle:
    // a Brownian bridge over the interval T to K^2 T^3 / 12 per sensor axis, through E^-1.
    // The instability is taken as the walk of equal short-time spread, K^2 = 2 s^2 / tau
    // (exact for T << tau; turns last seconds, correlation times tens of seconds and more).
    const double T = series_.t_s[mo.last] - series_.t_s[mo.first];
    for (std::size_t p : WanderOf(model::Sensor::kGyro)) {
      AddVariance(samples->sqrt_info, E_inv, wander_[p].ShortTimeWalk2() * (T * T * T / 12.0));
    }
    // Quantisation: the integrated angle carries 2 Q^2 (noise_model.h).
    AddVariance(samples->sqrt_info, E_inv, 2.0 * noise_.quantisation_gyr.cwiseAbs2());
    // The velocity residual, where the fit has one (a pass over the turn's samples): the white
    // noise or the turn's measured vibration (turn_noise.h), then each accelerometer wander
    // process about its line (the velocity residual takes the line off): its bridge's mean
    // over T, times T, through F^-1; the instability as the walk of equal short-time spread,
    // as for the rotation above.
    if (velocity_on_) {
      const Vec3 var_v = TurnVelocityVariance(*samples, E_inv, F_inv, turn_noise,
                                              start_.Down(still_.poses[mo.from]), g);
      velocity_info_[k] = var_v.cwiseSqrt().cwiseInverse();
      for (std::size_t p : WanderOf(model::Sensor::kAccel)) {
        AddVariance(velocity_info_[k], F_inv, wander_[p].ShortTimeWalk2() * (T * T * T / 12.0));
      }
    }
    motion_samples_[k] = std::move(samples);
  }
}

void CalibrationProblem::SetMotionWeightsFromSolution() {
  const std::vector<const double*> blocks = ModelBlocks();
  const auto linear = model_.Predict(blocks.data(), model::SensorInput<double>());
  SetMotionWeights(linear.E, linear.F);
}

std::vector<const double*> CalibrationProblem::ModelBlocks() const {
  std::vector<const double*> out;
  for (int t = 0; t < model_.num_terms(); ++t) out.push_back(block(t));
  return out;
}

model::ParameterBlocks CalibrationProblem::theta() const {
  model::ParameterBlocks out;
  for (int t = 0; t < model_.num_terms(); ++t) out.emplace_back(block(t), block(t) + block_size(t));
  return out;
}

Quat CalibrationProblem::R_n_b(std::size_t k) const {
  const double* v = q(k);
  return Quat(v[3], v[0], v[1], v[2]);
}

void CalibrationProblem::AddParameterBlocks(BuiltProblem& built,
                                            const std::vector<ParameterIndex>& held_extra,
                                            bool free_probes) {
  ceres::Problem* problem = built.problem.get();
  for (int t = 0; t < model_.num_terms(); ++t) {
    double* values = block(t);
    const int size = block_size(t);
    const auto& term = model_.terms()[static_cast<std::size_t>(t)];
    problem->AddParameterBlock(values, size);
    if (free_probes && term.probe) continue;
    std::vector<int> held;
    for (std::size_t i = 0; i < term.fixed.size(); ++i) {
      const bool extra = std::find(held_extra.begin(), held_extra.end(),
                                   std::make_pair(t, static_cast<int>(i))) != held_extra.end();
      if (term.fixed[i] || extra) held.push_back(static_cast<int>(i));
    }
    if (static_cast<int>(held.size()) == size) {
      problem->SetParameterBlockConstant(values);
    } else if (!held.empty()) {
      built.manifolds.push_back(std::make_unique<ceres::SubsetManifold>(size, held));
      problem->SetManifold(values, built.manifolds.back().get());
    }
  }
  for (std::size_t k = 0; k < still_.poses.size(); ++k) {
    const StillPose& s = still_.poses[k];
    problem->AddParameterBlock(q(k), 4);
    if (s.known) {
      problem->SetParameterBlockConstant(q(k));
    } else {
      built.manifolds.push_back(s.heading_only ? residuals::HeadingManifold()
                                : s.chain_head ? residuals::TiltManifold()
                                               : residuals::AttitudeManifold());
      problem->SetManifold(q(k), built.manifolds.back().get());
    }
  }
  for (std::size_t k = 0; k < still_.poses.size(); ++k) {
    for (std::size_t p = 0; p < wander_.size(); ++p) {
      for (bool end : {false, true}) problem->AddParameterBlock(wander(k, p, end), 3);
    }
  }
}

void CalibrationProblem::AddResiduals(BuiltProblem& built) {
  using residuals::StillResidual;
  ceres::Problem* problem = built.problem.get();
  const auto acc_terms = StillResidual::TermsOf(model_, model::Sensor::kAccel);
  const auto gyr_terms = StillResidual::TermsOf(model_, model::Sensor::kGyro);
  auto blocks_of = [&](const std::vector<int>& terms, double* q_k) {
    std::vector<double*> blocks = {q_k};
    for (int t : terms) blocks.push_back(block(t));
    return blocks;
  };
  std::vector<double*> all_terms;
  for (int t = 0; t < model_.num_terms(); ++t) all_terms.push_back(block(t));
  const std::vector<std::size_t> acc_wander = WanderOf(model::Sensor::kAccel);
  const std::vector<std::size_t> gyr_wander = WanderOf(model::Sensor::kGyro);
  for (std::size_t k = 0; k < still_.poses.size(); ++k) {
    const StillPose& s = still_.poses[k];
    std::vector<double*> acc_blocks = blocks_of(acc_terms, q(k));
    std::vector<double*> gyr_blocks = blocks_of(gyr_terms, q(k));
    const double T = s.stats.t_end_s - s.stats.t_begin_s;
    std::vector<double> acc_weights, gyr_weights;
    for (std::size_t p : acc_wander) {
      acc_blocks.insert(acc_blocks.end(), {wander(k, p, false), wander(k, p, true)});
      acc_weights.push_back(wander_[p].BridgeMeanWeight(T));
    }
    for (std::size_t p : gyr_wander) {
      gyr_blocks.insert(gyr_blocks.end(), {wander(k, p, false), wander(k, p, true)});
      gyr_weights.push_back(wander_[p].BridgeMeanWeight(T));
    }
    built.acc.push_back(
        s.spinning ? nullptr
                   : problem->AddResidualBlock(
                         StillResidual::Create(model_, model::Sensor::kAccel, s.acc_measurement,
                                               site_.g_n, site_.omega_ie_n, Vec3::Zero(),
                                               acc_weights),
                         nullptr, acc_blocks));
    built.gyr.push_back(
        still_gyro_ ? problem->AddResidualBlock(
                          StillResidual::Create(model_, model::Sensor::kGyro, s.gyr_measurement,
                                                site_.g_n, site_.omega_ie_n,
                                                s.segment.known_omega_eb_b.value_or(Vec3::Zero()),
                                                gyr_weights),
                          nullptr, gyr_blocks)
                    : nullptr);
  }
  const auto& motions = still_.motions;
  for (std::size_t k = 0; k < motions.size(); ++k) {
    const auto& mo = motions[k];
    std::vector<double*> blocks = {q(mo.from), q(mo.from + 1)};
    blocks.insert(blocks.end(), all_terms.begin(), all_terms.end());
    for (std::size_t p : gyr_wander) {
      blocks.insert(blocks.end(), {wander(mo.from, p, true), wander(mo.from + 1, p, false)});
    }
    auto* motion = new residuals::MotionResidual(model_, motion_samples_[k], site_.omega_ie_n,
                                                 static_cast<int>(gyr_wander.size()));
    built.motion.push_back(problem->AddResidualBlock(motion, nullptr, blocks));
    if (built.evaluation) {
      built.evaluation->Add(motion, blocks, static_cast<double>(motion_samples_[k]->size()));
    }
    if (velocity_on_) {
      std::vector<double*> vblocks = {q(mo.from)};
      vblocks.insert(vblocks.end(), all_terms.begin(), all_terms.end());
      for (const auto* processes : {&acc_wander, &gyr_wander}) {
        for (std::size_t p : *processes) {
          vblocks.insert(vblocks.end(), {wander(mo.from, p, true), wander(mo.from + 1, p, false)});
        }
      }
      built.velocity.push_back(problem->AddResidualBlock(
          residuals::VelocityResidual::Create(model_, motion_samples_[k], site_.g_n,
                                              site_.omega_ie_n, velocity_info_[k],
                                              static_cast<int>(acc_wander.size()),
                                              static_cast<int>(gyr_wander.size())),
          nullptr, vblocks));
    }
  }
}

std::vector<std::size_t> CalibrationProblem::WanderOf(model::Sensor sensor) const {
  std::vector<std::size_t> out;
  for (std::size_t p = 0; p < wander_.size(); ++p) {
    if (wander_[p].sensor == sensor) out.push_back(p);
  }
  return out;
}

void CalibrationProblem::AddWanderFactors(BuiltProblem& built, std::size_t p) {
  const WanderProcess& w = wander_[p];
  auto add = [&](double* from, double* to, double span_s) {
    const double dt = std::max(span_s, kMinWalkSpan_s);
    const Vec3 inv_sigma = w.StepSigma(dt).cwiseInverse();
    built.walk.push_back(
        from == nullptr
            ? built.problem->AddResidualBlock(
                  residuals::BiasWalkResidual::CreateAnchor(inv_sigma), nullptr, to)
            : built.problem->AddResidualBlock(
                  residuals::BiasWalkResidual::Create(inv_sigma, w.Phi(dt)), nullptr, from, to));
    built.walk_process.push_back(p);
  };
  const auto& poses = still_.poses;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const auto& stats = poses[k].stats;
    if (k == 0) {
      add(nullptr, wander(0, p, false), stats.t_begin_s - model_.t_ref_s);
    } else {
      add(wander(k - 1, p, true), wander(k, p, false),
          stats.t_begin_s - poses[k - 1].stats.t_end_s);
    }
    add(wander(k, p, false), wander(k, p, true), stats.t_end_s - stats.t_begin_s);
  }
}

BuiltProblem CalibrationProblem::Build(const Gauge& gauge, bool free_probes) {
  BuiltProblem built;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  if (!still_.motions.empty()) {
    built.evaluation = std::make_unique<ParallelEvaluation>(options_.run_jobs);
    problem_options.evaluation_callback = built.evaluation.get();
  }
  built.problem = std::make_unique<ceres::Problem>(problem_options);
  if (built.evaluation) built.evaluation->SetProblem(built.problem.get());
  AddParameterBlocks(built, gauge.parameters, free_probes);
  AddResiduals(built);
  for (std::size_t p = 0; p < wander_.size(); ++p) AddWanderFactors(built, p);
  AddHeldCombinations(built, gauge.combinations);
  return built;
}

void CalibrationProblem::AddHeldCombinations(BuiltProblem& built,
                                             const std::vector<Gauge::Combination>& held) {
  for (const Gauge::Combination& c : held) {
    std::vector<int> terms_of_block;  // the model terms whose blocks the residual takes
    std::vector<residuals::HeldTerm> terms;
    for (const auto& [place, coefficient] : c.terms) {
      auto at = std::find(terms_of_block.begin(), terms_of_block.end(), place.first);
      if (at == terms_of_block.end()) at = terms_of_block.insert(terms_of_block.end(), place.first);
      terms.push_back({static_cast<int>(at - terms_of_block.begin()), place.second, coefficient,
                       block(place.first)[place.second]});
    }
    std::vector<int> sizes;
    std::vector<double*> blocks;
    for (int t : terms_of_block) {
      sizes.push_back(block_size(t));
      blocks.push_back(block(t));
    }
    built.held.push_back(built.problem->AddResidualBlock(
        new residuals::HeldCombination(sizes, std::move(terms), kHeldCombinationWidth * c.sigma),
        nullptr, blocks));
  }
}

UnknownColumns CalibrationProblem::Columns(const ceres::Problem& problem,
                                           const std::vector<ParameterIndex>& held) {
  UnknownColumns out;
  const std::vector<const double*> blocks = ModelBlocks();
  const auto linear = model_.Predict(blocks.data(), model::SensorInput<double>());
  for (int t = 0; t < model_.num_terms(); ++t) {
    double* values = block(t);
    if (problem.IsParameterBlockConstant(values)) continue;
    out.blocks.push_back(values);
    const auto& term = model_.terms()[static_cast<std::size_t>(t)];
    const auto& info = term.effect->info();
    for (int i = 0; i < info.size(); ++i) {
      if (term.fixed[static_cast<std::size_t>(i)] ||
          std::find(held.begin(), held.end(), ParameterIndex(t, i)) != held.end()) {
        continue;
      }
      out.names.push_back(info.ParameterName(i));
      out.values.push_back(info.parameters[static_cast<std::size_t>(i)].nominal + values[i]);
      out.typical.push_back(TypicalSize(info, i, linear.F, linear.E));
      out.is_model.push_back(true);
      out.model_index.emplace_back(t, i);
    }
  }
  const char* kTangentName[3] = {"north", "east", "down"};
  for (std::size_t k = 0; k < still_.poses.size(); ++k) {
    const StillPose& s = still_.poses[k];
    if (s.known) continue;
    out.blocks.push_back(q(k));
    const int first = s.heading_only ? 2 : 0;
    const int dims = s.heading_only ? 1 : s.chain_head ? 2 : 3;
    for (int i = first; i < first + dims; ++i) {
      out.names.push_back("attitude[" + std::to_string(k) + "]." + kTangentName[i]);
      out.values.push_back(std::nan(""));
      out.typical.push_back(0.0);
      out.is_model.push_back(false);
      out.model_index.emplace_back(-1, static_cast<int>(k));
    }
  }
  out.first_wander = out.names.size();
  for (std::size_t k = 0; k < still_.poses.size(); ++k) {
    for (std::size_t p = 0; p < wander_.size(); ++p) {
      const WanderProcess& w = wander_[p];
      for (bool end : {false, true}) {
        out.blocks.push_back(wander(k, p, end));
        for (int i = 0; i < 3; ++i) {
          out.names.push_back(
              std::string(w.kind == WanderProcess::Kind::kWalk ? "walk[" : "instability[") +
              std::to_string(k) + "]." +
              (w.sensor == model::Sensor::kGyro ? "gyro." : "accel.") +
              (end ? "end." : "start.") + kAxisName[i]);
          out.values.push_back(std::nan(""));
          out.typical.push_back(0.0);
          out.is_model.push_back(false);
          out.model_index.emplace_back(-1, static_cast<int>(k));
        }
      }
    }
  }
  return out;
}

Eigen::MatrixXd CalibrationProblem::Jacobian(ceres::Problem& problem,
                                             const UnknownColumns& columns, double* cost,
                                             std::vector<double>* residuals) const {
  ceres::Problem::EvaluateOptions eval;
  eval.parameter_blocks = columns.blocks;
  ceres::CRSMatrix crs;
  problem.Evaluate(eval, cost, residuals, nullptr, &crs);
  return Dense(crs);
}

Eigen::SparseMatrix<double> CalibrationProblem::SparseJacobian(
    ceres::Problem& problem, const UnknownColumns& columns, double* cost,
    std::vector<double>* residuals) const {
  ceres::Problem::EvaluateOptions eval;
  eval.parameter_blocks = columns.blocks;
  ceres::CRSMatrix crs;
  problem.Evaluate(eval, cost, residuals, nullptr, &crs);
  return Sparse(crs);
}

ProbeJacobian CalibrationProblem::ProbeColumns(const BuiltProblem& probe,
                                               const UnknownColumns& columns) {
  ProbeJacobian out;
  out.unknown_names = columns.names;
  out.unknown_is_model = columns.is_model;
  std::vector<double*> blocks = columns.blocks;
  for (int t = 0; t < model_.num_terms(); ++t) {
    const auto& term = model_.terms()[static_cast<std::size_t>(t)];
    if (!term.probe) continue;
    blocks.push_back(block(t));
    for (int i = 0; i < term.effect->info().size(); ++i) {
      out.probe_names.push_back(term.effect->info().ParameterName(i));
      out.probe_term.push_back(t);
    }
  }
  ceres::Problem::EvaluateOptions eval;
  eval.parameter_blocks = blocks;
  auto add_rows = [&](ceres::ResidualBlockId id, ProbeJacobian::RowKind kind, int index) {
    if (id == nullptr) return;
    eval.residual_blocks.push_back(id);
    for (int axis = 0; axis < 3; ++axis) {
      out.row_kind.push_back(kind);
      out.row_index.push_back(index);
      out.row_axis.push_back(axis);
    }
  };
  for (std::size_t k = 0; k < probe.acc.size(); ++k) {
    add_rows(probe.acc[k], ProbeJacobian::RowKind::kStillAccel, static_cast<int>(k));
    add_rows(probe.gyr[k], ProbeJacobian::RowKind::kStillGyro, static_cast<int>(k));
  }
  for (std::size_t k = 0; k < probe.motion.size(); ++k) {
    add_rows(probe.motion[k], ProbeJacobian::RowKind::kMotion, static_cast<int>(k));
  }
  for (std::size_t k = 0; k < probe.velocity.size(); ++k) {
    add_rows(probe.velocity[k], ProbeJacobian::RowKind::kVelocity, static_cast<int>(k));
  }
  for (std::size_t k = 0; k < probe.walk.size(); ++k) {
    add_rows(probe.walk[k], ProbeJacobian::RowKind::kBiasWalk, static_cast<int>(k));
  }
  std::vector<double> r;
  ceres::CRSMatrix crs;
  probe.problem->Evaluate(eval, nullptr, &r, nullptr, &crs);
  const Eigen::SparseMatrix<double> all = Sparse(crs);
  const auto n_free = static_cast<Eigen::Index>(columns.names.size());
  out.r = Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
  out.J = all.leftCols(n_free);
  out.first_wander = columns.first_wander;
  out.Z = Eigen::MatrixXd(all.rightCols(all.cols() - n_free));
  return out;
}

void CalibrationProblem::ReportResiduals(const BuiltProblem& built, FitReport& fit) const {
  const ceres::Problem& problem = *built.problem;
  // The parameters stay as they are: only the first block's evaluation lets the evaluation
  // callback prepare (all motion residuals at once, parallel_evaluation.h); asking it again
  // per block would compare every block's values per block.
  bool prepared = false;
  auto evaluate = [&](ceres::ResidualBlockId id, double* w) {
    if (prepared) {
      problem.EvaluateResidualBlockAssumingParametersUnchanged(id, false, nullptr, w, nullptr);
    } else {
      problem.EvaluateResidualBlock(id, false, nullptr, w, nullptr);
      prepared = true;
    }
  };
  Vec3 ss_acc = Vec3::Zero(), ss_gyr = Vec3::Zero(), ss_mot = Vec3::Zero(), ss_vel = Vec3::Zero();
  for (std::size_t k = 0; k < still_.poses.size(); ++k) {
    const StillPose& s = still_.poses[k];
    StillSegmentFit f;
    f.segment = s.segment;
    f.t_mid_s = s.stats.t_mid_s;
    f.count = s.stats.count;
    f.acc_mean = s.stats.acc_mean;
    if (has_gyro_) f.gyr_mean = s.stats.gyr_mean;
    f.R_n_b = R_n_b(k);
    f.attitude_known = s.known;
    const double T = s.stats.t_end_s - s.stats.t_begin_s;
    for (std::size_t p = 0; p < wander_.size(); ++p) {
      const Vec3 mean = wander_[p].BridgeMeanWeight(T) *
                        (Eigen::Map<const Vec3>(wander(k, p, false)) +
                         Eigen::Map<const Vec3>(wander(k, p, true)));
      (wander_[p].sensor == model::Sensor::kAccel ? f.acc_walk : f.gyr_walk) += mean;
    }
    // Residuals are measured minus predicted, whitened by sqrt_info: unwhiten to report them.
    double w[3];
    if (built.acc[k]) {
      evaluate(built.acc[k], w);
      f.acc_whitened = Vec3(w[0], w[1], w[2]);
      f.acc_residual = f.acc_whitened.cwiseQuotient(s.acc_measurement.sqrt_info);
      ss_acc += f.acc_residual.cwiseAbs2();
    }
    if (built.gyr[k]) {
      evaluate(built.gyr[k], w);
      f.gyr_whitened = Vec3(w[0], w[1], w[2]);
      f.gyr_residual = f.gyr_whitened.cwiseQuotient(s.gyr_measurement.sqrt_info);
      ss_gyr += f.gyr_residual.cwiseAbs2();
    }
    fit.still.push_back(f);
  }
  const auto& motions = still_.motions;
  for (std::size_t k = 0; k < motions.size(); ++k) {
    const MotionInterval& mo = motions[k];
    MotionFit f;
    f.from = mo.from;
    f.to = mo.from + 1;
    f.duration_s = series_.t_s[mo.last] - series_.t_s[mo.first];
    double w[3];
    evaluate(built.motion[k], w);
    f.whitened = Vec3(w[0], w[1], w[2]);
    f.rotation_residual = f.whitened.cwiseQuotient(motion_samples_[k]->sqrt_info);
    ss_mot += f.rotation_residual.cwiseAbs2();
    if (k < built.velocity.size()) {
      evaluate(built.velocity[k], w);
      f.has_velocity = true;
      f.velocity_whitened = Vec3(w[0], w[1], w[2]);
      f.velocity_residual = f.velocity_whitened.cwiseQuotient(velocity_info_[k]);
      ss_vel += f.velocity_residual.cwiseAbs2();
    }
    fit.motion.push_back(f);
  }
  const double ns = static_cast<double>(still_.poses.size());
  fit.rms_acc = (ss_acc / static_cast<double>(still_.AtRestMeans(false).size())).cwiseSqrt();
  if (still_gyro_) fit.rms_gyr = (ss_gyr / ns).cwiseSqrt();
  if (!motions.empty()) fit.rms_motion = (ss_mot / static_cast<double>(motions.size())).cwiseSqrt();
  fit.velocity_segments = static_cast<int>(built.velocity.size());
  if (fit.velocity_segments > 0) {
    fit.rms_velocity = (ss_vel / static_cast<double>(fit.velocity_segments)).cwiseSqrt();
  }
}

void CalibrationProblem::TakeValues(const CalibrationProblem& from) {
  if (from.values_.size() != values_.size() || from.q_offset_ != q_offset_ ||
      from.still_.poses.size() != still_.poses.size()) {
    throw Error("calibration problem: TakeValues between problems of different layouts");
  }
  std::copy(from.values_.begin(), from.values_.end(), values_.begin());
  for (std::size_t k = 0; k < still_.poses.size(); ++k) {
    if (still_.poses[k].known) std::copy(still_.poses[k].q.begin(), still_.poses[k].q.end(), q(k));
  }
}

void CalibrationProblem::SaveValues() { saved_values_ = values_; }

void CalibrationProblem::RestoreValues() {
  std::copy(saved_values_.begin(), saved_values_.end(), values_.begin());
}

}  // namespace plumb::estimation

#include "plumb/estimation/calibration_problem.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "plumb/core/error.h"
#include "plumb/estimation/board_turns.h"
#include "plumb/model/board_mount.h"
#include "plumb/residuals/bias_walk_residual.h"
#include "plumb/residuals/held_combination.h"
#include "plumb/residuals/manifolds.h"
#include "plumb/residuals/motion_residual.h"
#include "plumb/residuals/mounted_motion_residual.h"
#include "plumb/residuals/still_residuals.h"
#include "plumb/residuals/velocity_residual.h"

namespace plumb::estimation {
namespace {

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

ProblemImu CalibrationProblem::MakeImu(const ImuSeries& series, model::Model model,
                                       StillSet still, const NoiseModel& noise,
                                       const StartingValues& start, bool mounted) const {
  ProblemImu imu;
  imu.series = &series;
  imu.model = std::move(model);
  imu.still = std::move(still);
  imu.noise = noise;
  imu.start = start;
  imu.mounted = mounted;
  imu.has_gyro = imu.model.has_gyro();
  imu.wander = noise.Wander(imu.has_gyro);
  imu.still_gyro = imu.has_gyro && options_.use_still_gyro;
  bool needs_velocity = false;
  for (const auto& term : imu.model.terms()) {
    needs_velocity = needs_velocity || term.effect->info().excitation.angular_acceleration;
  }
  const bool motion_on = options_.use_motion && imu.has_gyro;
  // The board's other IMUs have no velocity residual: their accelerometers are compared with
  // IMU 0's in the turns instead, which sees their lever arms and time offsets, where IMU 0's
  // own accelerometer has no velocity residual in them (the two would share its noise).
  imu.velocity_on = !mounted && motion_on && options_.accel_in_motion.value_or(needs_velocity);
  imu.turns_compared = mounted && options_.use_motion && imus_[0].has_gyro &&
                       !imus_[0].velocity_on && !imu.still.motions.empty();
  imu.SetMeasurements();
  imu.SetMotionSamples();
  return imu;
}

CalibrationProblem::CalibrationProblem(const ImuSeries& series, model::Model model,
                                       const geo::Site& site, StillSet still,
                                       model::ParameterBlocks theta, const NoiseModel& noise,
                                       const StartingValues& start,
                                       const CalibrationOptions& options,
                                       std::vector<BoardImuInput> board)
    : site_(site), options_(options) {
  imus_.push_back(MakeImu(series, std::move(model), std::move(still), noise, start, false));
  std::vector<model::ParameterBlocks> starts = {std::move(theta)};
  for (BoardImuInput& other : board) {
    imus_.push_back(MakeImu(*other.series, std::move(other.model), std::move(other.still),
                            other.noise, other.start, true));
    imus_.back().instance = other.instance;
    imus_.back().name_prefix = "imu" + std::to_string(other.instance) + ".";
    model::ParameterBlocks blocks = std::move(other.theta);
    std::vector<double> mount(model::board_mount::kSize, 0.0);
    const Vec3 rho = so3::Log(other.R_b_i.toRotationMatrix());
    std::copy_n(rho.data(), 3, mount.begin() + model::board_mount::kRotation);
    blocks.push_back(std::move(mount));
    starts.push_back(std::move(blocks));
    ProblemImu& added = imus_.back();
    bool any_window = false;
    for (std::size_t k = 0; added.turns_compared && k < added.still.motions.size(); ++k) {
      auto windows = TurnWindows(*imus_[0].series, imus_[0].still.motions[k], imus_[0].model,
                                 *added.series, added.still.motions[k], added.model);
      for (const auto& w : windows) any_window = any_window || w.imu.count > 0;
      added.turn_windows.push_back(
          std::make_shared<const std::vector<residuals::BoardWindow>>(std::move(windows)));
    }
    added.turns_compared = any_window;
  }
  // The values: every IMU's term blocks, then the attitudes, then every IMU's wander states.
  int first_term = 0;
  for (std::size_t i = 0; i < imus_.size(); ++i) {
    imus_[i].first_term = first_term;
    first_term += imus_[i].num_terms();
    for (const auto& block : starts[i]) {
      imus_[i].block_offset.push_back(values_.size());
      values_.insert(values_.end(), block.begin(), block.end());
    }
  }
  q_offset_ = values_.size();
  for (const auto& s : imus_[0].still.poses) values_.insert(values_.end(), s.q.begin(), s.q.end());
  for (ProblemImu& imu : imus_) {
    imu.walk_offset = values_.size();
    values_.resize(values_.size() + 6 * imu.wander.size() * imu.still.poses.size(), 0.0);
  }
  SetMotionWeights(Mat3::Identity() / start.gyro_rad_per_unit, Mat3::Identity() * start.accel.scale);
  for (std::size_t i = 1; i < imus_.size(); ++i) {
    const StartingValues& s = imus_[i].start;
    imus_[i].SetMotionWeights(Mat3::Identity() / s.gyro_rad_per_unit,
                              Mat3::Identity() * s.accel.scale, site_.gravity(),
                              options_.turn_vibration);
    SetTurnWeights(i);
  }
}

void CalibrationProblem::SetMotionWeights(const Mat3& E, const Mat3& F) {
  imus_[0].SetMotionWeights(E, F, site_.gravity(), options_.turn_vibration);
}

void CalibrationProblem::SetMotionWeightsFromSolution() {
  for (std::size_t i = 0; i < imus_.size(); ++i) {
    const std::vector<const double*> blocks = TermBlocks(i);
    const auto linear = imus_[i].model.Predict(blocks.data(), model::SensorInput<double>());
    imus_[i].SetMotionWeights(linear.E, linear.F, site_.gravity(), options_.turn_vibration);
  }
  for (std::size_t i = 1; i < imus_.size(); ++i) SetTurnWeights(i);
}

std::pair<std::size_t, int> CalibrationProblem::TermOf(int t) const {
  std::size_t i = imus_.size() - 1;
  while (i > 0 && t < imus_[i].first_term) --i;
  return {i, t - imus_[i].first_term};
}

std::vector<const double*> CalibrationProblem::TermBlocks(std::size_t imu) const {
  std::vector<const double*> out;
  for (std::size_t offset : imus_[imu].block_offset) out.push_back(values_.data() + offset);
  return out;
}

std::vector<const double*> CalibrationProblem::ModelBlocks() const {
  std::vector<const double*> out = TermBlocks(0);
  return out;
}

model::ParameterBlocks CalibrationProblem::theta() const {
  model::ParameterBlocks out;
  for (int t = 0; t < model().num_terms(); ++t) out.emplace_back(block(t), block(t) + block_size(t));
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
  for (int t = 0; t < num_terms(); ++t) {
    const auto [imu, local] = TermOf(t);
    const ProblemImu& u = imus_[imu];
    double* values = block(t);
    const int size = block_size(t);
    problem->AddParameterBlock(values, size);
    const bool probe = local < u.model.num_terms() &&
                       u.model.terms()[static_cast<std::size_t>(local)].probe;
    if (free_probes && probe) continue;
    std::vector<int> held;
    for (int i = 0; i < size; ++i) {
      const bool extra = std::find(held_extra.begin(), held_extra.end(),
                                   std::make_pair(t, i)) != held_extra.end();
      if (u.Fixed(local, i) || extra) held.push_back(i);
    }
    if (static_cast<int>(held.size()) == size) {
      problem->SetParameterBlockConstant(values);
    } else if (!held.empty()) {
      built.manifolds.push_back(std::make_unique<ceres::SubsetManifold>(size, held));
      problem->SetManifold(values, built.manifolds.back().get());
    }
  }
  for (std::size_t k = 0; k < still().poses.size(); ++k) {
    const StillPose& s = still().poses[k];
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
  for (std::size_t i = 0; i < imus_.size(); ++i) {
    for (std::size_t k = 0; k < still().poses.size(); ++k) {
      for (std::size_t p = 0; p < imus_[i].wander.size(); ++p) {
        for (bool end : {false, true}) problem->AddParameterBlock(wander(i, k, p, end), 3);
      }
    }
  }
}

void CalibrationProblem::AddResiduals(BuiltProblem& built, std::size_t imu) {
  using residuals::StillResidual;
  const ProblemImu& u = imus_[imu];
  const bool mounted = u.mounted;
  ceres::Problem* problem = built.problem.get();
  BuiltProblem::ImuBlocks own;
  auto& acc_ids = mounted ? own.acc : built.acc;
  auto& gyr_ids = mounted ? own.gyr : built.gyr;
  auto& motion_ids = mounted ? own.motion : built.motion;
  // The IMU's term blocks: its model's (all, or those of one sensor), after its attitude
  // blocks and, for another IMU of the board, its mount.
  std::vector<double*> model_blocks;
  for (int local = 0; local < u.model.num_terms(); ++local) {
    model_blocks.push_back(block(u.first_term + local));
  }
  auto blocks_of = [&](const std::vector<int>& terms, std::vector<double*> leading) {
    if (mounted) leading.push_back(mount(imu));
    for (int t : terms) leading.push_back(model_blocks[static_cast<std::size_t>(t)]);
    return leading;
  };
  const auto acc_terms = StillResidual::TermsOf(u.model, model::Sensor::kAccel);
  const auto gyr_terms = StillResidual::TermsOf(u.model, model::Sensor::kGyro);
  std::vector<int> all_terms(static_cast<std::size_t>(u.model.num_terms()));
  std::iota(all_terms.begin(), all_terms.end(), 0);
  const std::vector<std::size_t> acc_wander = u.WanderOf(model::Sensor::kAccel);
  const std::vector<std::size_t> gyr_wander = u.WanderOf(model::Sensor::kGyro);
  auto make_still = mounted ? &StillResidual::CreateMounted : &StillResidual::Create;
  for (std::size_t k = 0; k < u.still.poses.size(); ++k) {
    const StillPose& s = u.still.poses[k];
    std::vector<double*> acc_blocks = blocks_of(acc_terms, {q(k)});
    std::vector<double*> gyr_blocks = blocks_of(gyr_terms, {q(k)});
    const double T = s.stats.t_end_s - s.stats.t_begin_s;
    std::vector<double> acc_weights, gyr_weights;
    for (std::size_t p : acc_wander) {
      acc_blocks.insert(acc_blocks.end(), {wander(imu, k, p, false), wander(imu, k, p, true)});
      acc_weights.push_back(u.wander[p].BridgeMeanWeight(T));
    }
    for (std::size_t p : gyr_wander) {
      gyr_blocks.insert(gyr_blocks.end(), {wander(imu, k, p, false), wander(imu, k, p, true)});
      gyr_weights.push_back(u.wander[p].BridgeMeanWeight(T));
    }
    const bool spinning = still().poses[k].spinning;
    acc_ids.push_back(spinning ? nullptr
                               : problem->AddResidualBlock(
                                     make_still(u.model, model::Sensor::kAccel, s.acc_measurement,
                                                site_.g_n, site_.omega_ie_n, Vec3::Zero(),
                                                acc_weights),
                                     nullptr, acc_blocks));
    gyr_ids.push_back(
        u.still_gyro
            ? problem->AddResidualBlock(
                  make_still(u.model, model::Sensor::kGyro, s.gyr_measurement, site_.g_n,
                             site_.omega_ie_n,
                             still().poses[k].segment.known_omega_eb_b.value_or(Vec3::Zero()),
                             gyr_weights),
                  nullptr, gyr_blocks)
            : nullptr);
  }
  const auto& motions = u.still.motions;
  for (std::size_t k = 0; k < motions.size(); ++k) {
    const auto& mo = motions[k];
    std::vector<double*> blocks = blocks_of(all_terms, {q(mo.from), q(mo.from + 1)});
    for (std::size_t p : gyr_wander) {
      blocks.insert(blocks.end(), {wander(imu, mo.from, p, true), wander(imu, mo.from + 1, p, false)});
    }
    const int processes = static_cast<int>(gyr_wander.size());
    residuals::CachedCostFunction* motion =
        mounted ? static_cast<residuals::CachedCostFunction*>(new residuals::MountedMotionResidual(
                      u.model, u.motion_samples[k], site_.omega_ie_n, processes))
                : new residuals::MotionResidual(u.model, u.motion_samples[k], site_.omega_ie_n,
                                                processes);
    motion_ids.push_back(problem->AddResidualBlock(motion, nullptr, blocks));
    if (built.evaluation) {
      built.evaluation->Add(motion, blocks, static_cast<double>(u.motion_samples[k]->size()));
    }
    if (u.velocity_on) {
      std::vector<double*> vblocks = blocks_of(all_terms, {q(mo.from)});
      for (const auto* processes_of : {&acc_wander, &gyr_wander}) {
        for (std::size_t p : *processes_of) {
          vblocks.insert(vblocks.end(), {wander(imu, mo.from, p, true), wander(imu, mo.from + 1, p, false)});
        }
      }
      built.velocity.push_back(problem->AddResidualBlock(
          residuals::VelocityResidual::Create(u.model, u.motion_samples[k], site_.g_n,
                                              site_.omega_ie_n, u.velocity_info[k],
                                              static_cast<int>(acc_wander.size()),
                                              static_cast<int>(gyr_wander.size())),
          nullptr, vblocks));
    }
  }
  if (mounted) {
    AddTurnComparison(built, imu, own);
    built.board.push_back(std::move(own));
  }
}

void CalibrationProblem::AddWanderFactors(BuiltProblem& built, std::size_t imu, std::size_t p) {
  const ProblemImu& u = imus_[imu];
  const WanderProcess& w = u.wander[p];
  std::vector<ceres::ResidualBlockId>& ids = imu == 0 ? built.walk : built.board[imu - 1].walk;
  auto add = [&](double* from, double* to, double span_s) {
    const double dt = std::max(span_s, kMinWalkSpan_s);
    const Vec3 inv_sigma = w.StepSigma(dt).cwiseInverse();
    ids.push_back(
        from == nullptr
            ? built.problem->AddResidualBlock(
                  residuals::BiasWalkResidual::CreateAnchor(inv_sigma), nullptr, to)
            : built.problem->AddResidualBlock(
                  residuals::BiasWalkResidual::Create(inv_sigma, w.Phi(dt)), nullptr, from, to));
    if (imu == 0) built.walk_process.push_back(p);
  };
  const auto& poses = u.still.poses;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const auto& stats = poses[k].stats;
    if (k == 0) {
      add(nullptr, wander(imu, 0, p, false), stats.t_begin_s - u.model.t_ref_s);
    } else {
      add(wander(imu, k - 1, p, true), wander(imu, k, p, false),
          stats.t_begin_s - poses[k - 1].stats.t_end_s);
    }
    add(wander(imu, k, p, false), wander(imu, k, p, true), stats.t_end_s - stats.t_begin_s);
  }
}

BuiltProblem CalibrationProblem::Build(const Gauge& gauge, bool free_probes) {
  BuiltProblem built;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  if (!still().motions.empty()) {
    built.evaluation = std::make_unique<ParallelEvaluation>(options_.run_jobs);
    problem_options.evaluation_callback = built.evaluation.get();
  }
  built.problem = std::make_unique<ceres::Problem>(problem_options);
  if (built.evaluation) built.evaluation->SetProblem(built.problem.get());
  AddParameterBlocks(built, gauge.parameters, free_probes);
  for (std::size_t i = 0; i < imus_.size(); ++i) AddResiduals(built, i);
  // IMU 0's wander factors last before the held combinations: walk_estimate.cc reads them as
  // the last rows.
  for (std::size_t i = imus_.size(); i-- > 0;) {
    for (std::size_t p = 0; p < imus_[i].wander.size(); ++p) AddWanderFactors(built, i, p);
  }
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

void CalibrationProblem::AddTermColumns(const ceres::Problem& problem,
                                        const std::vector<ParameterIndex>& held,
                                        std::size_t imu, TermRange locals,
                                        UnknownColumns& out) {
  const ProblemImu& u = imus_[imu];
  const std::vector<const double*> blocks = TermBlocks(imu);
  const auto linear = u.model.Predict(blocks.data(), model::SensorInput<double>());
  for (int local = locals.first; local < locals.end; ++local) {
    const int t = u.first_term + local;
    double* values = block(t);
    if (problem.IsParameterBlockConstant(values)) continue;
    out.blocks.push_back(values);
    const model::EffectInfo& info = u.TermInfo(local);
    for (int i = 0; i < info.size(); ++i) {
      if (u.Fixed(local, i) ||
          std::find(held.begin(), held.end(), ParameterIndex(t, i)) != held.end()) {
        continue;
      }
      out.names.push_back(u.ParameterName(local, i));
      out.values.push_back(info.parameters[static_cast<std::size_t>(i)].nominal + values[i]);
      out.typical.push_back(TypicalSize(info, i, linear.F, linear.E));
      out.is_model.push_back(true);
      out.model_index.emplace_back(t, i);
    }
  }
}

void CalibrationProblem::AddWanderColumns(std::size_t imu, UnknownColumns& out) {
  const ProblemImu& u = imus_[imu];
  for (std::size_t k = 0; k < u.still.poses.size(); ++k) {
    for (std::size_t p = 0; p < u.wander.size(); ++p) {
      const WanderProcess& w = u.wander[p];
      for (bool end : {false, true}) {
        out.blocks.push_back(wander(imu, k, p, end));
        for (int i = 0; i < 3; ++i) {
          out.names.push_back(
              u.name_prefix +
              (w.kind == WanderProcess::Kind::kWalk ? "walk[" : "instability[") +
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
}

UnknownColumns CalibrationProblem::Columns(const ceres::Problem& problem,
                                           const std::vector<ParameterIndex>& held) {
  UnknownColumns out;
  // The mounts first: where the data cannot determine a mount (a rotation about gravity seen
  // in one pose), its own rotation is held as the gauge (observability.h: pivots in column
  // order) rather than a combination of its gyroscope's matrix that turns it far away.
  for (std::size_t i = 0; i < imus_.size(); ++i) {
    AddTermColumns(problem, held, i, {imus_[i].model.num_terms(), imus_[i].num_terms()}, out);
  }
  for (std::size_t i = 0; i < imus_.size(); ++i) {
    AddTermColumns(problem, held, i, {0, imus_[i].model.num_terms()}, out);
  }
  const char* kTangentName[3] = {"north", "east", "down"};
  for (std::size_t k = 0; k < still().poses.size(); ++k) {
    const StillPose& s = still().poses[k];
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
  for (std::size_t i = 0; i < imus_.size(); ++i) AddWanderColumns(i, out);
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
  for (int t = 0; t < model().num_terms(); ++t) {
    const auto& term = model().terms()[static_cast<std::size_t>(t)];
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
  for (std::size_t k = 0; k < still().poses.size(); ++k) {
    const StillPose& s = still().poses[k];
    StillSegmentFit f;
    f.segment = s.segment;
    f.t_mid_s = s.stats.t_mid_s;
    f.count = s.stats.count;
    f.acc_mean = s.stats.acc_mean;
    if (imus_[0].has_gyro) f.gyr_mean = s.stats.gyr_mean;
    f.R_n_b = R_n_b(k);
    f.attitude_known = s.known;
    const double T = s.stats.t_end_s - s.stats.t_begin_s;
    for (std::size_t p = 0; p < imus_[0].wander.size(); ++p) {
      const Vec3 mean = imus_[0].wander[p].BridgeMeanWeight(T) *
                        (Eigen::Map<const Vec3>(wander(0, k, p, false)) +
                         Eigen::Map<const Vec3>(wander(0, k, p, true)));
      (imus_[0].wander[p].sensor == model::Sensor::kAccel ? f.acc_walk : f.gyr_walk) += mean;
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
  const auto& motions = still().motions;
  for (std::size_t k = 0; k < motions.size(); ++k) {
    const MotionInterval& mo = motions[k];
    MotionFit f;
    f.from = mo.from;
    f.to = mo.from + 1;
    f.duration_s = imus_[0].series->t_s[mo.last] - imus_[0].series->t_s[mo.first];
    double w[3];
    evaluate(built.motion[k], w);
    f.whitened = Vec3(w[0], w[1], w[2]);
    f.rotation_residual = f.whitened.cwiseQuotient(imus_[0].motion_samples[k]->sqrt_info);
    ss_mot += f.rotation_residual.cwiseAbs2();
    if (k < built.velocity.size()) {
      evaluate(built.velocity[k], w);
      f.has_velocity = true;
      f.velocity_whitened = Vec3(w[0], w[1], w[2]);
      f.velocity_residual = f.velocity_whitened.cwiseQuotient(imus_[0].velocity_info[k]);
      ss_vel += f.velocity_residual.cwiseAbs2();
    }
    fit.motion.push_back(f);
  }
  const double ns = static_cast<double>(still().poses.size());
  fit.rms_acc = (ss_acc / static_cast<double>(still().AtRestMeans(false).size())).cwiseSqrt();
  if (imus_[0].still_gyro) fit.rms_gyr = (ss_gyr / ns).cwiseSqrt();
  if (!motions.empty()) fit.rms_motion = (ss_mot / static_cast<double>(motions.size())).cwiseSqrt();
  fit.velocity_segments = static_cast<int>(built.velocity.size());
  if (fit.velocity_segments > 0) {
    fit.rms_velocity = (ss_vel / static_cast<double>(fit.velocity_segments)).cwiseSqrt();
  }
}

void CalibrationProblem::TakeValues(const CalibrationProblem& from) {
  if (from.values_.size() != values_.size() || from.q_offset_ != q_offset_ ||
      from.still().poses.size() != still().poses.size()) {
    throw Error("calibration problem: TakeValues between problems of different layouts");
  }
  std::copy(from.values_.begin(), from.values_.end(), values_.begin());
  for (std::size_t k = 0; k < still().poses.size(); ++k) {
    if (still().poses[k].known) std::copy(still().poses[k].q.begin(), still().poses[k].q.end(), q(k));
  }
}

void CalibrationProblem::SaveValues() { saved_values_ = values_; }

void CalibrationProblem::RestoreValues() {
  std::copy(saved_values_.begin(), saved_values_.end(), values_.begin());
}

}  // namespace plumb::estimation

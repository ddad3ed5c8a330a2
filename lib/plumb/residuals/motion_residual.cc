#include "plumb/residuals/motion_residual.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

#include "plumb/core/so3.h"
#include "plumb/model/effects/accel_linear.h"
#include "plumb/model/effects/gyro_linear.h"

namespace plumb::residuals {
using so3::Skew;
namespace {

/// Newton steps of the general model's correction, at most: each shrinks the error by about
/// twice the relative size of the nonlinear effects (a 1e-3 scale nonlinearity at 5 rad/s:
/// 1e-2), so they reach the fixed point to rounding (kNewtonTolerance, relative) and the
/// implicit derivative is the derivative of the rates computed.
constexpr int kNewtonSteps = 8;
constexpr double kNewtonTolerance = 1e-15;

/// Whether some term of `model` writes the accelerometer's output.
bool HasAccelTerms(const model::Model& model) {
  for (const auto& t : model.terms()) {
    if (t.effect->info().sensor == model::Sensor::kAccel) return true;
  }
  return false;
}


/// What a catalogue term reads of the output the terms before it wrote: the linear stage's F
/// and E, or the outputs summed so far (effect.h: terms add to the outputs; the built-in ones
/// read F or E at most). Found by applying the term on doubles at generic values, once with F,
/// E and the outputs as the identity model leaves them and once changed: a term whose
/// increment does not move (beyond rounding) does not read them, on the inputs this residual
/// gives.
struct TermReads {
  bool linear_stage = false;  ///< the increment depends on F or E
  bool outputs = false;       ///< the increment depends on acc or gyr as summed so far
};

TermReads ProbeTermReads(const model::Effect& effect) {
  const int size = effect.info().size();
  std::vector<double> theta(static_cast<std::size_t>(size));
  for (int j = 0; j < size; ++j) theta[static_cast<std::size_t>(j)] = 1e-3 * (1.0 + 0.37 * j);
  model::SensorInput<double> in;
  in.f_b = Vec3(0.31, -0.42, 9.7);
  in.omega_b = Vec3(0.23, -0.61, 0.47);
  in.alpha_b = Vec3(1.3, -0.7, 0.9);
  in.dt_s = 12.5;
  in.dtemp_c = 3.25;
  // R_b_n stays zero: the attitude is not known inside a motion interval, and this residual
  // never gives it (earth_rate's term, E R_b_n omega_n, is then zero here whatever E).
  auto increment = [&](const model::SensorOutput<double>& before) {
    model::SensorOutput<double> out = before;
    effect.Apply(theta.data(), in, out);
    Eigen::Matrix<double, 6, 1> d;
    d << out.acc - before.acc, out.gyr - before.gyr;
    return d;
  };
  const model::SensorOutput<double> identity;
  model::SensorOutput<double> stage = identity, summed = identity;
  stage.F += 0.1 * so3::Skew(Vec3(0.7, -0.3, 0.5)) + 0.05 * Mat3::Identity();
  stage.E += 0.1 * so3::Skew(Vec3(-0.4, 0.6, 0.2)) - 0.03 * Mat3::Identity();
  summed.acc = Vec3(1.7, -2.3, 9.1);
  summed.gyr = Vec3(-0.9, 0.4, 1.3);
  const Eigen::Matrix<double, 6, 1> base = increment(identity);
  auto moved = [&](const Eigen::Matrix<double, 6, 1>& d) {
    return (d - base).cwiseAbs().maxCoeff() > 1e-12 * (1.0 + base.cwiseAbs().maxCoeff());
  };
  return TermReads{moved(increment(stage)), moved(increment(summed))};
}

/// The closed form's share of the propagated sensitivities without Earth rate: the sums over
/// samples of G_i w_i,c, G_i and a_i G_i, multiplied by E^-1 once at the end (E^-1 is the
/// same for every sample).
struct GyroStageSums {
  std::array<Mat3, 3> by_rate = {Mat3::Zero(), Mat3::Zero(), Mat3::Zero()};
  Mat3 total = Mat3::Zero();  ///< sum_i G_i
  Mat3 to = Mat3::Zero();     ///< sum_i a_i G_i (the walk's b_to weight)

  void Add(const Mat3& G, const Vec3& w, double a) {
    for (int c = 0; c < 3; ++c) by_rate[static_cast<std::size_t>(c)] += w[c] * G;
    total += G;
    if (a != 0.0) to += a * G;  // without a walk (a = 0) nothing to add
  }
  /// Subtracts the sums times E^-1 from the gyroscope's 12 leading columns of A and, when
  /// `walk_from` >= 0, from the walk's b_from and b_to columns there.
  void SubtractFrom(const Mat3& E_inv, int walk_from,
                    Eigen::Matrix<double, 3, Eigen::Dynamic>& A) const {
    model::gyro_linear::SubtractSummedRateJacobian(E_inv, by_rate, total,
                                                   A.leftCols(model::gyro_linear::kSize));
    if (walk_from < 0) return;
    A.middleCols<3>(walk_from).noalias() -= (total - to) * E_inv;
    A.middleCols<3>(walk_from + 3).noalias() -= to * E_inv;
  }
};

using Jet = model::Jet;

/// The model's terms on Jets at the samples of one interval, for the implicit derivative of the
/// corrected rates (MotionResidual::ImplicitRateJacobians): theta as Jets, constants with up to
/// kJetStride parameters seeded, and the inputs at sample i (the corrected f_i and w_i,
/// differentiated if asked). The input and the output are kept from sample to sample (a 3 x 3
/// matrix of Jets is 81 values to set): every input is set anew; when the terms are split
/// (catalogue terms only read F and E), F and E are the linear stage's, set once per pass (the
/// linear stage's terms, first in stage_readers_, overwrite them) and the outputs are zeroed;
/// otherwise the output starts afresh.
class TermJets {
 public:
  /// `parameter_of`: per parameter of the P, its (term, index); `at_zero`: the model's output
  /// at zero input (its F and E). Every argument must outlive the object.
  TermJets(const model::Model& model, double const* const* theta,
           const std::vector<std::pair<int, int>>& parameter_of, bool terms_split,
           const model::SensorOutput<double>& at_zero, const MotionSamples& samples,
           const std::vector<Vec3>& f, const std::vector<Vec3>& w)
      : model_(model), theta_(theta), parameter_of_(parameter_of), terms_split_(terms_split),
        F_(at_zero.F.cast<Jet>()), E_(at_zero.E.cast<Jet>()), s_(samples), f_(f), w_(w),
        blocks_(static_cast<std::size_t>(model.num_terms())), ptr_(blocks_.size()) {
    for (std::size_t t = 0; t < blocks_.size(); ++t) {
      blocks_[t].resize(static_cast<std::size_t>(model.terms()[t].effect->info().size()));
      ptr_[t] = blocks_[t].data();
    }
  }

  /// Starts a pass with the parameters `seeded` (indices among the P) differentiated.
  void Start(const std::vector<int>& seeded) {
    for (std::size_t t = 0; t < blocks_.size(); ++t) {
      for (std::size_t j = 0; j < blocks_[t].size(); ++j) blocks_[t][j] = Jet(theta_[t][j]);
    }
    for (std::size_t slot = 0; slot < seeded.size(); ++slot) {
      const auto [t, j] = parameter_of_[static_cast<std::size_t>(seeded[slot])];
      blocks_[static_cast<std::size_t>(t)][static_cast<std::size_t>(j)].v[slot] = 1.0;
    }
    if (terms_split_) {
      z_.F = F_;
      z_.E = E_;
    }
  }

  /// The terms `terms` applied at sample i, the inputs f_i and w_i differentiated (the first
  /// six slots) when `differentiate`.
  const model::SensorOutput<Jet>& Predict(std::size_t i, bool differentiate,
                                          const std::vector<int>& terms) {
    for (int k = 0; k < 3; ++k) {
      in_.f_b[k] = Jet(f_[i][k]);
      in_.omega_b[k] = Jet(w_[i][k]);
      in_.alpha_b[k] = Jet(s_.alpha_b[i][k]);
      if (differentiate) {
        in_.f_b[k].v[k] = 1.0;
        in_.omega_b[k].v[3 + k] = 1.0;
      }
    }
    in_.dt_s = Jet(s_.dt_s[i]);
    in_.dtemp_c = Jet(s_.dtemp_c[i]);
    if (terms_split_) {
      z_.acc.setZero();
      z_.gyr.setZero();
    } else {
      z_ = model::SensorOutput<Jet>();
    }
    for (int t : terms) {
      model_.terms()[static_cast<std::size_t>(t)].effect->Apply(ptr_[static_cast<std::size_t>(t)], in_, z_);
    }
    return z_;
  }

 private:
  const model::Model& model_;
  double const* const* theta_;
  const std::vector<std::pair<int, int>>& parameter_of_;
  bool terms_split_;
  Mat3T<Jet> F_, E_;
  const MotionSamples& s_;
  const std::vector<Vec3>& f_;
  const std::vector<Vec3>& w_;
  std::vector<std::vector<Jet>> blocks_;
  std::vector<const Jet*> ptr_;
  model::SensorInput<Jet> in_;
  model::SensorOutput<Jet> z_;
};

/// The rate rows of -D_x^-1 per sample, M = d w / d p: how w moves when p is added to the
/// predicted outputs (3 x 6; without accelerometer terms f is the output itself: d f = 0). With
/// D_x = [A B; C D] (A = d y_a / d f ~ F, D ~ E) and S = D - C A^-1 B: M = [S^-1 C A^-1, -S^-1].
/// D_x is the linear stage's F and E (when the terms are split) plus the Jets of `input_terms`.
/// `coupled`: set when some output depends on the other sensor's input at some sample.
std::vector<Eigen::Matrix<double, 3, 6>> RateRowsOfInverse(
    const model::Model& model, bool terms_split, const std::vector<int>& input_terms,
    const model::SensorOutput<double>& at_zero, std::size_t n, TermJets& jets, bool* coupled) {
  const bool accel = HasAccelTerms(model);
  const int a_term = model.BaseTerm(model::Sensor::kAccel);
  const int g_term = model.BaseTerm(model::Sensor::kGyro);
  std::vector<Eigen::Matrix<double, 3, 6>> dw_dp(n);
  jets.Start({});
  *coupled = false;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Zero();
    if (terms_split) {
      if (a_term >= 0) D.topLeftCorner<3, 3>() = at_zero.F;
      if (g_term >= 0) D.bottomRightCorner<3, 3>() = at_zero.E;
    }
    if (!input_terms.empty()) {
      const model::SensorOutput<Jet>& z = jets.Predict(i, true, input_terms);
      for (int r = 0; r < 3; ++r) {
        D.row(r) += z.acc[r].v.head<6>().transpose();
        D.row(3 + r) += z.gyr[r].v.head<6>().transpose();
      }
    }
    if (!accel) D.topRows<3>() << Mat3::Identity(), Mat3::Zero();
    *coupled = *coupled || !D.block<3, 3>(3, 0).isZero(0.0) || !D.block<3, 3>(0, 3).isZero(0.0);
    const Mat3 A_inv = D.topLeftCorner<3, 3>().inverse();
    const Mat3 S_inv =
        (D.bottomRightCorner<3, 3>() - D.bottomLeftCorner<3, 3>() * A_inv * D.topRightCorner<3, 3>())
            .inverse();
    dw_dp[i] << S_inv * D.bottomLeftCorner<3, 3>() * A_inv, -S_inv;
  }
  return dw_dp;
}

}  // namespace

Eigen::Matrix<double, 4, 3> LeftPlusJacobian(const Quat& q) {
  // (0, a) (x) (w, v) = (-a.v, w a + a x v); Exp(delta) ~ (1, delta / 2).
  Eigen::Matrix<double, 4, 3> P;
  const Vec3 v = q.vec();
  for (int j = 0; j < 3; ++j) {
    const Vec3 a = Vec3::Unit(j);
    P.block<3, 1>(0, j) = 0.5 * (q.w() * a + a.cross(v));
    P(3, j) = -0.5 * v[j];
  }
  return P;
}

MotionResidual::MotionResidual(const model::Model& model, SharedMotionSamples samples,
                               const Vec3& omega_ie_n, int wander_processes)
    : model_(&model), samples_(std::move(samples)), s_(*samples_), omega_ie_n_(omega_ie_n),
      wander_(wander_processes) {
  for (int t = 0; t < model.num_terms(); ++t) {
    block_offset_.push_back(num_model_parameters_);
    const int size = model.terms()[static_cast<std::size_t>(t)].effect->info().size();
    for (int j = 0; j < size; ++j) parameter_of_.emplace_back(t, j);
    num_model_parameters_ += size;
  }
  for (int t = 0; t < model.num_terms(); ++t) {
    all_terms_.push_back(t);
    const model::Effect& effect = *model.terms()[static_cast<std::size_t>(t)].effect;
    if (effect.info().linear_stage) {
      linear_terms_.push_back(t);
      continue;
    }
    catalogue_terms_.push_back(t);
    const TermReads reads = ProbeTermReads(effect);
    if (reads.outputs) terms_split_ = false;
    if (reads.linear_stage) stage_readers_.push_back(t);
  }
  if (!stage_readers_.empty()) stage_readers_.insert(stage_readers_.begin(), linear_terms_.begin(), linear_terms_.end());
  const int g = model.BaseTerm(model::Sensor::kGyro);
  if (g >= 0) bias_offset_ = block_offset_[static_cast<std::size_t>(g)] + model::gyro_linear::kBias;
  set_num_residuals(3);
  mutable_parameter_block_sizes()->push_back(4);
  mutable_parameter_block_sizes()->push_back(4);
  for (const auto& t : model.terms()) mutable_parameter_block_sizes()->push_back(t.effect->info().size());
  if (wander_ > 0) {
    for (int b = 0; b < 2 * wander_; ++b) mutable_parameter_block_sizes()->push_back(3);
    const double span = s_.dt_s.back() - s_.dt_s.front();
    for (std::size_t i = 0; i < s_.size(); ++i) {
      walk_weight_.push_back(span > 0 ? (s_.dt_s[i] - s_.dt_s.front()) / span : 0.0);
    }
  }
}

bool MotionResidual::LinearAt(double const* const* theta, double** jacobians) const {
  if (!model_->AtLinearStage(theta)) return false;
  for (int t = 0; jacobians != nullptr && t < model_->num_terms(); ++t) {
    const auto& info = model_->terms()[static_cast<std::size_t>(t)].effect->info();
    if (!info.linear_stage && jacobians[2 + t] != nullptr) return false;
  }
  return true;
}

void MotionResidual::CorrectedRates(double const* const* theta, const std::vector<Vec3>& gyr,
                                    bool linear, std::vector<Vec3>* w,
                                    RateJacobians* W) const {
  const std::size_t n = s_.size();
  const int P = num_model_parameters_;
  w->resize(n);
  const model::SensorOutput<double> at_zero = model_->Predict(theta, model::SensorInput<double>());
  const Mat3 F_inv = at_zero.F.inverse();
  const Mat3 E_inv = at_zero.E.inverse();
  const Vec3 b_g = at_zero.gyr;  // E * 0 + b_g (+ terms that vanish at zero input)

  if (linear) {
    // w = E^-1 (y - b_g): dw/db_g = -E^-1, dw/dE_rc = -E^-1 e_r w_c.
    if (W) W->Reset(n, 0, P);
    const int g = model_->BaseTerm(model::Sensor::kGyro);
    const int off = g >= 0 ? block_offset_[static_cast<std::size_t>(g)] : 0;
    for (std::size_t i = 0; i < n; ++i) {
      (*w)[i] = E_inv * (gyr[i] - b_g);
      if (!W || g < 0) continue;
      model::gyro_linear::SubtractRateJacobian(
          E_inv, (*w)[i], (*W)[i].middleCols(off, model::gyro_linear::kSize));
    }
    return;
  }

  // General model: Model::Correct (Newton on the forward model). Its rates satisfy
  // y = Predict(theta, x), x = (f, w), so dw/dtheta is implicit: with D_x = d Predict / d x
  // (6 x 6) and D_theta = d Predict / d theta from one Jet pass of the forward model each,
  // dx/dtheta = -D_x^-1 D_theta (instead of Jets through every Newton step). The rates are
  // taken to the fixed point (kNewtonSteps) so that this is their derivative.
  std::vector<Vec3> f(n);
  for (std::size_t i = 0; i < n; ++i) {
    model::SensorInput<double> in;
    in.alpha_b = s_.alpha_b[i];
    in.dt_s = s_.dt_s[i];
    in.dtemp_c = s_.dtemp_c[i];
    std::tie(f[i], (*w)[i]) = model_->CorrectToFixedPoint(theta, s_.acc[i], gyr[i], in, F_inv,
                                                          E_inv, kNewtonSteps, kNewtonTolerance);
  }
  if (W) ImplicitRateJacobians(theta, at_zero, f, *w, *W);
}

// The general model's d w_i / d theta by implicit differentiation (see CorrectedRates): with
// D_x = d Predict / d x (6 x 6) and D_theta = d Predict / d theta at the fixed point,
// d x / d theta = -D_x^-1 D_theta. The linear stage's share of both is closed-form (D_x gets F
// and E; D_theta is e_r f_c, e_r w_c and I, the linear residuals' columns); the catalogue terms'
// share comes from Jets, one pass per 8 parameters through the term that owns them alone, on
// the linear stage's F and E (terms add to the outputs and read only those). Where a term reads
// F or E, the linear stage's parameters go through Jets too (with the terms that read them);
// where one reads more than that (terms_split_ false), every pass runs the whole model.
void MotionResidual::ImplicitRateJacobians(double const* const* theta,
                                           const model::SensorOutput<double>& at_zero,
                                           const std::vector<Vec3>& f, const std::vector<Vec3>& w,
                                           RateJacobians& W) const {
  constexpr int kStride = model::kJetStride;
  static_assert(kStride >= 6, "one Jet pass differentiates the six inputs");
  const std::size_t n = s_.size();
  TermJets jets(*model_, theta, parameter_of_, terms_split_, at_zero, s_, f, w);
  bool coupled = false;
  std::vector<Eigen::Matrix<double, 3, 6>> dw_dp = RateRowsOfInverse(
      *model_, terms_split_, terms_split_ ? catalogue_terms_ : all_terms_, at_zero, n, jets,
      &coupled);
  const bool linear_closed = terms_split_ && stage_readers_.empty();
  // Stored: the other terms' columns alone when the linear stage's are closed-form (they come
  // first in block order), else every column.
  const int first = linear_closed ? (catalogue_terms_.empty() ? num_model_parameters_
                                                              : block_offset_[static_cast<std::size_t>(catalogue_terms_.front())])
                                  : 0;
  W.Reset(n, first, num_model_parameters_ - first);
  for (const auto& [seeded, terms] : JetPasses(coupled, linear_closed)) {
    jets.Start(seeded);
    for (std::size_t i = 0; i < n; ++i) {
      const model::SensorOutput<Jet>& z = jets.Predict(i, false, terms);
      Eigen::Matrix<double, 6, kStride> D_theta;
      for (int r = 0; r < 3; ++r) {
        D_theta.row(r) = z.acc[r].v.transpose();  // zero without accelerometer terms
        D_theta.row(3 + r) = z.gyr[r].v.transpose();
      }
      const Eigen::Matrix<double, 3, kStride> dw = dw_dp[i] * D_theta;
      for (std::size_t slot = 0; slot < seeded.size(); ++slot) {
        W[i].col(seeded[slot] - first) = dw.col(static_cast<Eigen::Index>(slot));
      }
    }
  }
  // The linear stage in closed form (applied by Evaluate through d w / d p).
  if (linear_closed) W.SetLinearStage(std::move(dw_dp), f, coupled);
}

std::vector<std::pair<std::vector<int>, std::vector<int>>> MotionResidual::JetPasses(
    bool coupled, bool linear_closed) const {
  constexpr std::size_t kStride = model::kJetStride;
  // The parameters that can move the rates: with the sensors uncoupled at every sample, D_x is
  // block diagonal and the accelerometer's terms (which write y_a alone) leave w alone: their
  // columns stay zero without a pass.
  auto moves = [&](int t) {
    return coupled ||
           model_->terms()[static_cast<std::size_t>(t)].effect->info().sensor == model::Sensor::kGyro;
  };
  std::vector<std::pair<std::vector<int>, std::vector<int>>> passes;
  auto add_passes = [&](const std::vector<int>& params, const std::vector<int>& terms) {
    for (std::size_t first = 0; first < params.size(); first += kStride) {
      const auto last = std::min(params.size(), first + kStride);
      passes.emplace_back(std::vector<int>(params.begin() + static_cast<std::ptrdiff_t>(first),
                                           params.begin() + static_cast<std::ptrdiff_t>(last)),
                          terms);
    }
  };
  auto params_of = [&](const std::vector<int>& terms) {
    std::vector<int> params;
    for (int t : terms) {
      if (!moves(t)) continue;
      const int size = model_->terms()[static_cast<std::size_t>(t)].effect->info().size();
      for (int j = 0; j < size; ++j) params.push_back(block_offset_[static_cast<std::size_t>(t)] + j);
    }
    return params;
  };
  if (!terms_split_) {
    add_passes(params_of(all_terms_), all_terms_);
  } else {
    for (int t : catalogue_terms_) add_passes(params_of({t}), {t});
    if (!linear_closed) add_passes(params_of(linear_terms_), stage_readers_);
  }
  return passes;
}

bool MotionResidual::EvaluateUncached(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  const Quat q_k(parameters[0][3], parameters[0][0], parameters[0][1], parameters[0][2]);
  const Quat q_k1(parameters[1][3], parameters[1][0], parameters[1][1], parameters[1][2]);
  const Mat3 R_k = q_k.normalized().toRotationMatrix();
  const Mat3 R_k1 = q_k1.normalized().toRotationMatrix();
  double const* const* theta = parameters + 2;
  const bool want_jacobians = jacobians != nullptr;
  const int P = num_model_parameters_;
  const bool walk = wander_ > 0;

  // The outputs with the bias walk taken off (the samples themselves without a walk).
  std::vector<Vec3> walked;
  const std::vector<double>& a = walk_weight_;
  if (walk) walked = WalkedOutputs(parameters);
  const std::vector<Vec3>& gyr = walk ? walked : s_.gyr;

  std::vector<Vec3> w;
  RateJacobians W;
  // For the base model dw/dtheta has a closed form used on the fly (no per-sample storage):
  // w = E^-1 (y - b_g), dw/dE_rc = -E^-1 e_r w_c, dw/db_g = -E^-1. It also holds when every
  // other effect is at zero and its Jacobian is not asked for (e.g. diagnose's probes).
  const bool closed_form = LinearAt(theta, jacobians);
  CorrectedRates(theta, gyr, closed_form, &w, want_jacobians && !closed_form ? &W : nullptr);
  Mat3 E_inv = Mat3::Identity();
  int gyro_offset = -1;  // the gyroscope's linear block among the P (closed form, Jacobians)
  if (closed_form && want_jacobians) std::tie(E_inv, gyro_offset) = ClosedFormGyro(theta);
  // Columns of the propagated sensitivities: the model parameters that move the rates (all P
  // in general; in closed form the gyroscope's linear block only, the others' columns being
  // zero), the left perturbation of R_k, then (wander) b_from and b_to.
  const int rate_cols = !closed_form ? P : gyro_offset >= 0 ? model::gyro_linear::kSize : 0;
  const int att = rate_cols;
  const int from = rate_cols + 3;
  const int U = rate_cols + 3 + (walk ? 6 : 0);
  const int a_term = model_->BaseTerm(model::Sensor::kAccel);
  const int g_term = model_->BaseTerm(model::Sensor::kGyro);
  const int a_size =
      a_term >= 0 ? model_->terms()[static_cast<std::size_t>(a_term)].effect->info().size() : 0;
  // The linear gyroscope stage's share of K dw_i/dtheta, given KE = -K d w_i / d p_g (K E^-1
  // for the base model, w = E^-1 (y_g - b_g)): the 12 columns of E and b_g from `g_col` and,
  // with a walk, those of b_from and b_to (d w_i / d b_g weighted by 1 - a_i and a_i).
  auto add_gyro_stage = [&](const Mat3& KE, std::size_t i, int g_col,
                            Eigen::Matrix<double, 3, Eigen::Dynamic>& out) {
    model::gyro_linear::SubtractRateJacobian(KE, w[i], out.middleCols(g_col, model::gyro_linear::kSize));
    if (walk) {
      out.middleCols<3>(from).noalias() -= (1.0 - a[i]) * KE;
      out.middleCols<3>(from + 3).noalias() -= a[i] * KE;
    }
  };
  // Adds K dw_i/dtheta to the first rate_cols columns of `out` and, with a walk, K dw_i/d
  // b_from and K dw_i/d b_to to the walk's columns.
  auto add_rate_jacobian = [&](const Mat3& K, std::size_t i,
                               Eigen::Matrix<double, 3, Eigen::Dynamic>& out) {
    if (closed_form) {
      if (gyro_offset >= 0) add_gyro_stage(K * E_inv, i, 0, out);
      return;
    }
    if (W.linear_stage_closed()) {
      // The other terms' stored columns, then the linear stage's through d w / d p: d p_g /
      // d E_rc = e_r w_c, d p_g / d b_g = I, and the same for F, b_a and f when the sensors are
      // coupled (the linear residuals' column functions, with K F^-1 = -K d w / d p_a).
      if (W.columns() > 0) out.middleCols(W.first(), W.columns()).noalias() += K * W[i];
      if (g_term >= 0) {
        add_gyro_stage(Mat3(-K * W.dw_dp(i).rightCols<3>()), i,
                       block_offset_[static_cast<std::size_t>(g_term)], out);
      }
      if (a_term >= 0 && W.coupled()) {
        model::accel_linear::SubtractForceJacobian(
            Mat3(-(K * W.dw_dp(i).leftCols<3>())), W.f(i), a_size == model::accel_linear::kSizeFull,
            out.middleCols(block_offset_[static_cast<std::size_t>(a_term)], a_size));
      }
      return;
    }
    out.leftCols(P).noalias() += K * W[i];
    if (walk) {
      const Mat3 K_dw_db = K * W[i].middleCols<3>(bias_offset_);
      out.middleCols<3>(from).noalias() += (1.0 - a[i]) * K_dw_db;
      out.middleCols<3>(from + 3).noalias() += a[i] * K_dw_db;
    }
  };

  const bool earth = omega_ie_n_.squaredNorm() > 0.0;  // without a site: e = 0, no att terms
  if (!want_jacobians && !earth) {
    const Vec3 r = so3::Log(IntegratedRotation(w).transpose() * R_k.transpose() * R_k1);
    for (int i = 0; i < 3; ++i) residuals[i] = s_.sqrt_info[i] * r[i];
    return true;
  }
  const Vec3 omega_k = R_k.transpose() * omega_ie_n_;  // Earth rate in b_k
  const Mat3 d_omega_k = R_k.transpose() * Skew(omega_ie_n_);  // d omega_k / d delta_k
  Mat3 dR = Mat3::Identity();
  // A = d(right perturbation of dR)/d(unknowns), propagated step by step (the header's
  // "Propagation": with Earth rate in the body frame, without it in the start frame).
  Eigen::Matrix<double, 3, Eigen::Dynamic> A = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, U);
  Eigen::Matrix<double, 3, Eigen::Dynamic> A_next(3, U);
  GyroStageSums sums;
  auto add_sample = [&](const Mat3& G, std::size_t i) {
    if (closed_form) {
      sums.Add(G, w[i], walk ? a[i] : 0.0);
    } else {
      add_rate_jacobian(G, i, A);
    }
  };
  Mat3 G_next = Mat3::Zero();  // the share of W_i+1 from step i
  for (std::size_t i = 0; i + 1 < s_.size(); ++i) {
    const double h = s_.dt_s[i + 1] - s_.dt_s[i];
    // Earth rate at the start of the step, held over the step.
    const Vec3 e = earth ? Vec3(dR.transpose() * omega_k) : Vec3::Zero();
    const Vec3 u0 = w[i] - e, u1 = w[i + 1] - e;
    const Vec3 phi = so3::ConingIncrement(u0, u1, h);
    if (!want_jacobians) {  // a value with Earth rate
      dR = dR * so3::Exp(phi);
      continue;
    }
    Mat3 Ex, Jr;
    so3::ExpAndRightJacobian(phi, &Ex, &Jr);
    const Mat3 dR_next = dR * Ex;
    const double c0 = 0.5 * h, c1 = h * h / 12.0;  // C0 = c0 I - c1 [u1]x, C1 = c0 I + c1 [u0]x
    if (earth) {
      const Mat3 K0 = c0 * Jr - c1 * so3::TimesSkew(Jr, u1);
      const Mat3 K1 = c0 * Jr + c1 * so3::TimesSkew(Jr, u0);
      const Mat3 K = K0 + K1;
      A_next.noalias() = (Ex.transpose() - K * Skew(e)) * A;
      A_next.middleCols<3>(att).noalias() -= K * (dR.transpose() * d_omega_k);
      add_rate_jacobian(K0, i, A_next);
      add_rate_jacobian(K1, i + 1, A_next);
      A.swap(A_next);
    } else {
      const Mat3 D = dR_next * Jr;
      add_sample(G_next + c0 * D - c1 * so3::TimesSkew(D, u1), i);
      G_next = c0 * D + c1 * so3::TimesSkew(D, u0);
    }
    dR = dR_next;
  }
  if (want_jacobians && !earth) {
    if (s_.size() >= 2) add_sample(G_next, s_.size() - 1);
    if (closed_form && gyro_offset >= 0) sums.SubtractFrom(E_inv, walk ? from : -1, A);
    A = (dR.transpose() * A).eval();
  }
  const Mat3 M = dR.transpose() * R_k.transpose();
  const Vec3 r = so3::Log(M * R_k1);
  for (int i = 0; i < 3; ++i) residuals[i] = s_.sqrt_info[i] * r[i];
  if (!want_jacobians) return true;

  WriteJacobians(r, M, A, closed_form ? std::max(gyro_offset, 0) : 0, rate_cols, q_k, q_k1,
                 jacobians);
  return true;
}

std::pair<Mat3, int> MotionResidual::ClosedFormGyro(double const* const* theta) const {
  const int g = model_->BaseTerm(model::Sensor::kGyro);
  if (g < 0) return {Mat3::Identity(), -1};
  return {model_->Predict(theta, model::SensorInput<double>()).E.inverse(),
          block_offset_[static_cast<std::size_t>(g)]};
}

std::vector<Vec3> MotionResidual::WalkedOutputs(double const* const* parameters) const {
  Vec3 b_from = Vec3::Zero(), b_to = Vec3::Zero();
  for (int p = 0; p < wander_; ++p) {
    b_from += Eigen::Map<const Vec3>(parameters[2 + model_->num_terms() + 2 * p]);
    b_to += Eigen::Map<const Vec3>(parameters[3 + model_->num_terms() + 2 * p]);
  }
  std::vector<Vec3> walked(s_.size());
  for (std::size_t i = 0; i < s_.size(); ++i) {
    const double a = walk_weight_[i];
    walked[i] = s_.gyr[i] - ((1.0 - a) * b_from + a * b_to);
  }
  return walked;
}

Mat3 MotionResidual::IntegratedRotation(const std::vector<Vec3>& w) const {
  Quat dR = Quat::Identity();
  for (std::size_t i = 0; i + 1 < s_.size(); ++i) {
    dR *= so3::ExpQuat(so3::ConingIncrement(w[i], w[i + 1], s_.dt_s[i + 1] - s_.dt_s[i]));
  }
  return dR.normalized().toRotationMatrix();
}

void MotionResidual::WriteJacobians(const Vec3& r, const Mat3& M,
                                    const Eigen::Matrix<double, 3, Eigen::Dynamic>& A,
                                    int rate_first, int rate_cols, const Quat& q_k,
                                    const Quat& q_k1, double** jacobians) const {
  const int P = num_model_parameters_;
  const int att = rate_cols;
  const int from = rate_cols + 3;
  const Mat3 Jli = so3::LeftJacobianInverse(r);
  const Eigen::DiagonalMatrix<double, 3> Wsi(s_.sqrt_info);
  // Tangent Jacobians (left perturbations in NED for the attitudes), then ambient ones
  // J_amb = J_tan 4 P^T, which satisfy J_amb P = J_tan since P^T P = I / 4.
  const Mat3 J_k = Wsi * (-Jli * (M + A.middleCols<3>(att)));
  const Mat3 J_k1 = Wsi * (Jli * M);
  auto ambient = [](const Mat3& J_tan, const Quat& q, double* out) {
    const Eigen::Matrix<double, 3, 4> J = J_tan * 4.0 * LeftPlusJacobian(q).transpose();
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> J_out(out);
    J_out = J;
  };
  if (jacobians[0]) ambient(J_k, q_k, jacobians[0]);
  if (jacobians[1]) ambient(J_k1, q_k1, jacobians[1]);
  Eigen::Matrix<double, 3, Eigen::Dynamic> J_theta = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, P);
  J_theta.middleCols(rate_first, rate_cols) =
      Wsi * (-Jli * A.leftCols(rate_cols));
  for (int t = 0; t < model_->num_terms(); ++t) {
    double* out = jacobians[t + 2];
    if (!out) continue;
    const int size = model_->terms()[static_cast<std::size_t>(t)].effect->info().size();
    Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>> J_out(out, 3, size);
    J_out = J_theta.middleCols(block_offset_[static_cast<std::size_t>(t)], size);
  }
  for (int b = 0; b < 2 * wander_; ++b) {
    double* out = jacobians[2 + model_->num_terms() + b];
    if (!out) continue;
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> J_out(out);
    J_out = Wsi * (-Jli * A.middleCols<3>(from + 3 * (b % 2)));
  }
}

Quat MotionResidual::Integrate(const double* q_k, const model::ParameterBlocks& theta) const {
  // Residual with R_k+1 = R_k: r = Log(dR^T), so dR = Exp(-r).
  std::vector<const double*> p = {q_k, q_k};
  for (const auto& b : theta) p.push_back(b.data());
  const double zero[3] = {0.0, 0.0, 0.0};
  for (int b = 0; b < 2 * wander_; ++b) p.push_back(zero);
  double r[3];
  Evaluate(p.data(), r, nullptr);
  const Vec3 rv = Vec3(r[0], r[1], r[2]).cwiseQuotient(s_.sqrt_info);
  return Quat(so3::Exp(-rv));
}

}  // namespace plumb::residuals

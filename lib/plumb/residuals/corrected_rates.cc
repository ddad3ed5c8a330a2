// plumb/residuals/corrected_rates.cc — see corrected_rates.h.
#include "plumb/residuals/corrected_rates.h"

#include <Eigen/LU>
#include <algorithm>
#include <tuple>

#include "plumb/core/so3.h"
#include "plumb/model/effects/accel_linear.h"
#include "plumb/model/effects/gyro_linear.h"

namespace plumb::residuals {
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

using autodiff::Jet;

/// The model's terms on Jets at the samples of one interval, for the implicit derivative of the
/// corrected rates (RateCorrection::ImplicitRateJacobians): theta as Jets, constants with up to
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
  TermJets(const autodiff::DifferentiableModel& model, double const* const* theta,
           const std::vector<std::pair<int, int>>& parameter_of, bool terms_split,
           const model::SensorOutput<double>& at_zero, const MotionSamples& samples,
           const std::vector<Vec3>& f, const std::vector<Vec3>& w)
      : model_(model), theta_(theta), parameter_of_(parameter_of), terms_split_(terms_split),
        F_(at_zero.F.cast<Jet>()), E_(at_zero.E.cast<Jet>()), s_(samples), f_(f), w_(w),
        blocks_(static_cast<std::size_t>(model.num_terms())), ptr_(blocks_.size()) {
    for (std::size_t t = 0; t < blocks_.size(); ++t) {
      blocks_[t].resize(static_cast<std::size_t>(model.term(static_cast<int>(t)).effect().info().size()));
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
      model_.term(t).Apply(ptr_[static_cast<std::size_t>(t)], in_, z_);
    }
    return z_;
  }

 private:
  const autodiff::DifferentiableModel& model_;
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

ModelColumns::ModelColumns(const model::Model& model) {
  for (int t = 0; t < model.num_terms(); ++t) {
    block_offset.push_back(parameters);
    const int size = model.terms()[static_cast<std::size_t>(t)].effect->info().size();
    for (int j = 0; j < size; ++j) parameter_of.emplace_back(t, j);
    parameters += size;
  }
}

RateCorrection::RateCorrection(const model::Model& model)
    : model_(&model), differentiable_(model), columns_(model), accel_term_(model.BaseTerm(model::Sensor::kAccel)),
      gyro_term_(model.BaseTerm(model::Sensor::kGyro)) {
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
  if (!stage_readers_.empty()) {
    stage_readers_.insert(stage_readers_.begin(), linear_terms_.begin(), linear_terms_.end());
  }
}

CorrectedRates RateCorrection::Correct(double const* const* theta, const MotionSamples& samples,
                                       const std::vector<Vec3>& gyr,
                                       const Options& options) const {
  const std::size_t n = samples.size();
  CorrectedRates out;
  out.w_b.resize(n);
  const model::SensorOutput<double> at_zero = model_->Predict(theta, model::SensorInput<double>());
  const Mat3 F_inv = at_zero.F.inverse();
  const Mat3 E_inv = at_zero.E.inverse();
  if (options.closed_form) {
    const Vec3 b_g = at_zero.gyr;  // E * 0 + b_g (+ terms that vanish at zero input)
    for (std::size_t i = 0; i < n; ++i) out.w_b[i] = E_inv * (gyr[i] - b_g);
    return out;
  }
  // The general model, to the fixed point (kNewtonSteps) so that the implicit derivative is
  // the derivative of the rates computed (file comment).
  std::vector<Vec3> f(n);
  for (std::size_t i = 0; i < n; ++i) {
    model::SensorInput<double> in;
    in.alpha_b = samples.alpha_b[i];
    in.dt_s = samples.dt_s[i];
    in.dtemp_c = samples.dtemp_c[i];
    std::tie(f[i], out.w_b[i]) = model_->CorrectToFixedPoint(
        theta, samples.acc[i], gyr[i], in, F_inv, E_inv, kNewtonSteps, kNewtonTolerance);
  }
  if (options.jacobians) {
    out.w_H_theta = ImplicitRateJacobians(theta, at_zero, samples, f, out.w_b);
  }
  return out;
}

Mat3 RateCorrection::AddRateJacobian(const CorrectedRates& rates, const Mat3& K, std::size_t i,
                                     Eigen::Matrix<double, 3, Eigen::Dynamic>& out) const {
  const RateJacobians& W = rates.w_H_theta;
  if (!W.linear_stage_closed()) {
    out.leftCols(columns_.parameters).noalias() += K * W[i];
    if (gyro_term_ < 0) return Mat3::Zero();
    return K * W[i].middleCols<3>(columns_.Offset(gyro_term_) + model::gyro_linear::kBias);
  }
  // The other terms' stored columns, then the linear stage's through d w / d p: d p_g / d E_rc
  // = e_r w_c, d p_g / d b_g = I, and the same for F, b_a and f when the sensors are coupled
  // (the linear residuals' column functions, with K E^-1 = -K d w / d p_g, K F^-1 = -K d w / d
  // p_a).
  if (W.columns() > 0) out.middleCols(W.first(), W.columns()).noalias() += K * W[i];
  if (accel_term_ >= 0 && W.coupled()) {
    const int size = model_->terms()[static_cast<std::size_t>(accel_term_)].effect->info().size();
    model::accel_linear::SubtractForceJacobian(
        Mat3(-(K * W.dw_dp(i).leftCols<3>())), W.f(i), size == model::accel_linear::kSizeFull,
        out.middleCols(columns_.Offset(accel_term_), size));
  }
  if (gyro_term_ < 0) return Mat3::Zero();
  const Mat3 KE = -K * W.dw_dp(i).rightCols<3>();
  model::gyro_linear::SubtractRateJacobian(
      KE, rates.w_b[i], out.middleCols(columns_.Offset(gyro_term_), model::gyro_linear::kSize));
  return -KE;
}

// The general model's d w_i / d theta by implicit differentiation (file comment): with
// D_x = d Predict / d x (6 x 6) and D_theta = d Predict / d theta at the fixed point,
// d x / d theta = -D_x^-1 D_theta. The linear stage's share of both is closed-form (D_x gets F
// and E; D_theta is e_r f_c, e_r w_c and I, the linear residuals' columns); the catalogue terms'
// share comes from Jets, one pass per 8 parameters through the term that owns them alone, on
// the linear stage's F and E (terms add to the outputs and read only those). Where a term reads
// F or E, the linear stage's parameters go through Jets too (with the terms that read them);
// where one reads more than that (terms_split_ false), every pass runs the whole model.
RateJacobians RateCorrection::ImplicitRateJacobians(double const* const* theta,
                                                   const model::SensorOutput<double>& at_zero,
                                                   const MotionSamples& samples,
                                                   const std::vector<Vec3>& f,
                                                   const std::vector<Vec3>& w) const {
  constexpr int kStride = autodiff::kJetStride;
  static_assert(kStride >= 6, "one Jet pass differentiates the six inputs");
  const std::size_t n = samples.size();
  TermJets jets(differentiable_, theta, columns_.parameter_of, terms_split_, at_zero, samples, f, w);
  bool coupled = false;
  std::vector<Eigen::Matrix<double, 3, 6>> dw_dp = RateRowsOfInverse(
      *model_, terms_split_, terms_split_ ? catalogue_terms_ : all_terms_, at_zero, n, jets,
      &coupled);
  const bool linear_closed = terms_split_ && stage_readers_.empty();
  // Stored: the other terms' columns alone when the linear stage's are closed-form (they come
  // first in block order), else every column.
  const int P = columns_.parameters;
  const int first =
      linear_closed ? (catalogue_terms_.empty() ? P : columns_.Offset(catalogue_terms_.front())) : 0;
  RateJacobians W;
  W.Reset(n, first, P - first);
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
  // The linear stage in closed form (applied by the caller through d w / d p).
  if (linear_closed) W.SetLinearStage(std::move(dw_dp), f, coupled);
  return W;
}

std::vector<std::pair<std::vector<int>, std::vector<int>>> RateCorrection::JetPasses(
    bool coupled, bool linear_closed) const {
  constexpr std::size_t kStride = autodiff::kJetStride;
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
      for (int j = 0; j < size; ++j) params.push_back(columns_.Offset(t) + j);
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

}  // namespace plumb::residuals

// plumb/residuals/corrected_rates.h — the error model inverted on the samples of an interval:
// the corrected angular rates w_i and their Jacobians with respect to the model's parameters,
// which the strapdown propagation (residuals/strapdown.h) carries into the attitude change.
//
// Where the model acts as its linear stage (every other effect at zero: model::Model::
// AtLinearStage) the rates have a closed form, w = E^-1 (y_g - b_g), and so do their Jacobians
// (model/effects/gyro_linear.h), which the caller applies on the fly. Otherwise the rates come
// from Model::CorrectToFixedPoint (Newton on the forward model, taken to the fixed point) and
// satisfy y = Predict(theta, x), x = (f, w), so d w / d theta is implicit: with D_x = d Predict /
// d x (6 x 6) and D_theta = d Predict / d theta, d x / d theta = -D_x^-1 D_theta (instead of Jets
// through every Newton step). The linear stage's share of both is closed-form; the catalogue
// terms' share comes from Jets (autodiff::kJetStride parameters per pass), through the term that
// owns them alone where the terms only read the linear stage's F and E.
#pragma once

#include <utility>
#include <vector>

#include "plumb/autodiff/differentiable_effect.h"
#include "plumb/model/model.h"
#include "plumb/residuals/measurements.h"

namespace plumb::residuals {

/// Where each block of a model sits among its P parameters (all blocks side by side, in model
/// order): the column layout of the Jacobians with respect to theta.
struct ModelColumns {
  explicit ModelColumns(const model::Model& model);
  int parameters = 0;                 ///< P
  std::vector<int> block_offset;      ///< per term: the offset of its block
  std::vector<std::pair<int, int>> parameter_of;  ///< per parameter: (term, index in block)
  /// The offset of term t's block.
  int Offset(int t) const { return block_offset[static_cast<std::size_t>(t)]; }
};

/// d w_i / d theta of every sample of an interval, 3 x P each. Stored either whole (columns
/// [0, P), side by side in one allocation) or, when the linear stage's share has its closed
/// form, as the columns [first, P) of the other terms plus, per sample, d w / d p (3 x 6, the
/// rate rows of -D_x^-1: how w moves when p is added to the predicted outputs y_a, y_g at a
/// fixed measurement, -d w / d y) and the corrected force f: the linear stage's columns are
/// then d w / d p times d p / d theta (e_r f_c and I for F and b_a, e_r w_c and I for E and
/// b_g), applied by the caller with the linear residuals' own column functions.
class RateJacobians {
 public:
  void Reset(std::size_t samples, int first, int columns) {
    first_ = first;
    P_ = columns;
    columns_.setZero(3, static_cast<Eigen::Index>(samples) * P_);
    dw_dp_.clear();
    f_.clear();
  }
  /// The stored columns of sample i (those from first()).
  auto operator[](std::size_t i) { return columns_.middleCols(static_cast<Eigen::Index>(i) * P_, P_); }
  auto operator[](std::size_t i) const {
    return columns_.middleCols(static_cast<Eigen::Index>(i) * P_, P_);
  }
  int first() const { return static_cast<int>(first_); }
  int columns() const { return static_cast<int>(P_); }
  /// Gives the linear stage's share by d w / d p per sample (see above).
  void SetLinearStage(std::vector<Eigen::Matrix<double, 3, 6>> dw_dp, std::vector<Vec3> f,
                      bool coupled) {
    dw_dp_ = std::move(dw_dp);
    f_ = std::move(f);
    coupled_ = coupled;
  }
  bool linear_stage_closed() const { return !dw_dp_.empty(); }
  const Eigen::Matrix<double, 3, 6>& dw_dp(std::size_t i) const { return dw_dp_[i]; }
  const Vec3& f(std::size_t i) const { return f_[i]; }
  /// Some rate depends on the accelerometer's input (its columns are then not zero).
  bool coupled() const { return coupled_; }

 private:
  Eigen::Index first_ = 0, P_ = 0;
  Eigen::Matrix<double, 3, Eigen::Dynamic> columns_;
  std::vector<Eigen::Matrix<double, 3, 6>> dw_dp_;
  std::vector<Vec3> f_;
  bool coupled_ = false;
};

/// The corrected rates of an interval and, when asked, their Jacobians.
struct CorrectedRates {
  std::vector<Vec3> w_b;        ///< per sample, rad/s, body frame
  RateJacobians w_H_theta;      ///< per sample d w_i / d theta (general model, when asked)
};

/// The model's inverse on an interval's samples (file comment). Analyses the model's terms once
/// (which read the linear stage, which are split); distinct calls may run on distinct threads.
class RateCorrection {
 public:
  /// How the rates are corrected.
  struct Options {
    /// The model acts as its linear stage at theta: the closed form (the caller applies its
    /// Jacobians; none are stored).
    bool closed_form = false;
    /// Store d w_i / d theta (general model only).
    bool jacobians = false;
  };

  /// The model must outlive the object.
  explicit RateCorrection(const model::Model& model);

  /// The rates of the gyroscope outputs `gyr` (one per sample of `samples`, whose other fields
  /// give the accelerometer output, angular acceleration, time and temperature) at theta.
  CorrectedRates Correct(double const* const* theta, const MotionSamples& samples,
                         const std::vector<Vec3>& gyr, const Options& options) const;

  /// Adds K d w_i / d theta to the first P columns of `out` (3 x at least P) from the stored
  /// Jacobians of `rates` (Options::jacobians), and returns K d w_i / d b_g (zero without a
  /// gyroscope term), which columns that enter like the gyroscope's bias (the walk) take.
  Mat3 AddRateJacobian(const CorrectedRates& rates, const Mat3& K, std::size_t i,
                       Eigen::Matrix<double, 3, Eigen::Dynamic>& out) const;

  const ModelColumns& columns() const { return columns_; }

 private:
  /// The general model's d w_i / d theta at the corrected inputs (f_i, w_i), given the model's
  /// output at zero input (its F and E).
  RateJacobians ImplicitRateJacobians(double const* const* theta,
                                      const model::SensorOutput<double>& at_zero,
                                      const MotionSamples& samples, const std::vector<Vec3>& f,
                                      const std::vector<Vec3>& w) const;
  /// The Jet passes of ImplicitRateJacobians: (parameters seeded, at most autodiff::kJetStride of
  /// the P; the terms applied), one per kJetStride parameters of a term that can move the
  /// rates (`coupled`: the sensors' inputs are coupled somewhere, so accelerometer terms can),
  /// through that term alone when the terms are split, and the linear stage's with the terms
  /// that read it unless it is closed-form (`linear_closed`).
  std::vector<std::pair<std::vector<int>, std::vector<int>>> JetPasses(bool coupled,
                                                                       bool linear_closed) const;

  const model::Model* model_;
  autodiff::DifferentiableModel differentiable_;  // the model's terms on Jets
  ModelColumns columns_;
  int accel_term_ = -1, gyro_term_ = -1;  // the linear stage's terms (-1: none)
  // The model's terms: all, the linear stage's, the catalogue's; the linear stage's followed
  // by the catalogue terms that read its F or E (empty when none does); false when some
  // catalogue term reads the outputs summed before it (every Jet pass then runs every term).
  std::vector<int> all_terms_, linear_terms_, catalogue_terms_, stage_readers_;
  bool terms_split_ = true;
};

}  // namespace plumb::residuals

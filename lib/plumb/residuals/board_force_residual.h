// plumb/residuals/board_force_residual.h — another IMU's accelerometer against IMU 0's in the
// turns: where on the rigid board the IMU sits (its lever arm) and when it samples (its time
// offset).
//
// IMU i sits in the body at R_b_i, at the lever arm r_i from IMU 0 (body frame, m), and its
// stamp t is the body's instant t + dt_i (model/board_mount.h):
//
//   f_i(t) = R_b_i^T (f_b + alpha_b x r_i + omega_b x (omega_b x r_i))(t + dt_i).
//
// A turn is cut into short windows of IMU 0's samples (BoardWindow, estimation/board_turns.h),
// which tile it: window w spans [e_w, e_w+1], its edges halfway between samples. With f_0,w and
// f_i,w the corrected specific forces at each IMU's mean outputs in it (its own model's
// inverse, model::Model::Correct, after its accelerometer's wander line is taken off the
// outputs; IMU i's from its samples stamped in the window) and omega_w IMU 0's corrected rate:
//
//   r_w = L_w^-1 ( R_b_i f_i,w - g_w - (dt_i + l_w) gdot_w ),          m/s^2, body frame
//
//   g_w = f_0,w + A_w r_i,  A_w = [alpha_w]x + mean_w([omega]x [omega]x)
//                               = [alpha_w]x + omega_w omega_w^T + C_w - (|omega_w|^2 + tr C_w) I,
//
// C_w = E_0^-1 S_w E_0^-T the spread of IMU 0's rates about their mean in the window (S_w its
// outputs' covariance there), l_w IMU i's mean stamp there minus IMU 0's (zero on a shared
// clock's common stamps), and alpha_w, gdot_w the window's mean angular acceleration and mean
// rate of change of g, the specific force at IMU i's place: the difference of omega's (g's)
// values at its edges over its width. A shift dt of a window's mean moves it by dt times that
// mean rate, to first order. The edge values come from the windows' means as finite-volume
// schemes reconstruct them: the derivative at the edge of the polynomial through the primitive at
// the four windows around it, exact for a cubic motion (fewer windows where the turn has fewer).
// Both IMUs see gravity, the hand's translation and its turn alike, so none of them enters: only
// the board's geometry and clocks remain, and the residual takes no attitude. Taking the mean
// outputs' correction for the mean correction is exact where the model acts as its linear stage,
// and second order in the window's spread elsewhere. A window in which IMU i has no sample gives
// no residual (its IMU 0 means still give the edges).
//
// L_w L_w^T is the covariance of the bracket (estimation/board_turns.h sets it): each IMU's
// window mean of its white noise, scaled by the turn's measured vibration, through its F^-1
// (and R_b_i), plus each accelerometer wander process's bridge at the window.
// The noise of alpha_w and gdot_w enters multiplied by r_i (centimetres) and dt_i (milliseconds)
// and is left out.
//
// Jacobians: central differences as ceres::DynamicNumericDiffCostFunction takes them (the same
// steps and quotients, so the same bits), only over the blocks the solver asks for, and not over
// IMU i's gyroscope terms where both models act as their linear stage (its force then reads none
// of them: those columns are zero; the corrections are then closed-form too, F^-1 (y - b_a)).
// A column recomputes only what its block enters: IMU i's blocks its force alone, the mount
// the force at IMU i's place and the whitening, IMU 0's blocks the turn as IMU 0 saw it.
//
// Parameter blocks, in order: IMU i's board_mount block (7), every block of IMU i's model in
// model order, every block of IMU 0's model in model order, then per accelerometer wander process
// of IMU i its b_from (3) and b_to (3), then the same per accelerometer process of IMU 0
// (sensor units: the values at the end of still pose k and the start of k+1).
#pragma once

#include <ceres/cost_function.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "plumb/core/types.h"
#include "plumb/model/model.h"

namespace plumb::residuals {

/// One IMU's samples in a window of a turn.
struct WindowMeans {
  Vec3 acc = Vec3::Zero();  ///< mean accelerometer output, sensor units
  Vec3 gyr = Vec3::Zero();  ///< mean gyroscope output, sensor units
  double dt_s = 0.0;        ///< mean stamp minus the model's t_ref, s
  double dtemp_c = 0.0;     ///< mean temperature minus the model's temp_ref, degC (0 if none)
  /// Where the mean stamp lies along the turn, 0 at its first sample and 1 at its last: the
  /// fraction of the way from b_from to b_to of the accelerometer's wander line.
  double line = 0.0;
  int count = 0;            ///< samples averaged
};

/// A window of a turn as both IMUs sampled it.
struct BoardWindow {
  WindowMeans imu0, imu;     ///< IMU 0's and IMU i's samples (IMU i's count may be 0)
  Mat3 gyr0_spread = Mat3::Zero();  ///< covariance of IMU 0's gyroscope outputs in it, units^2
  double t_begin_s = 0.0, t_end_s = 0.0;  ///< its edges e_w, e_w+1 (IMU 0's clock), s
  double stamp_lag_s = 0.0;  ///< l_w: IMU i's mean stamp minus IMU 0's, s
  Mat3 sqrt_info = Mat3::Identity();  ///< L_w^-1 (file comment), s^2/m
};

/// A turn's windows, shared by the residuals of every problem built on them (only read).
using SharedBoardWindows = std::shared_ptr<const std::vector<BoardWindow>>;

/// The residual's functor (file comment): 3 values per window with samples of IMU i.
class BoardForceResidual {
 public:
  /// The models must outlive the functor. `accel_wander` and `accel_wander0` count IMU i's and
  /// IMU 0's accelerometer wander processes.
  BoardForceResidual(const model::Model& model, const model::Model& model0,
                     SharedBoardWindows windows, int accel_wander, int accel_wander0);

  /// The cost function: the functor's central differences (Differentiate) over the blocks the
  /// file comment lists.
  static ceres::CostFunction* Create(const model::Model& model, const model::Model& model0,
                                     SharedBoardWindows windows, int accel_wander,
                                     int accel_wander0);

  bool operator()(double const* const* parameters, double* residuals) const;

  /// The residuals, and the central-difference Jacobian (Ceres's relative step kRelativeStep,
  /// at least sqrt(epsilon); row-major, rows x block size) of every block whose `jacobians`
  /// entry is not null. `block_sizes` are the blocks' sizes, in the file comment's order.
  void Differentiate(double const* const* parameters, const std::vector<int32_t>& block_sizes,
                     double* residuals, double** jacobians) const;

  /// ceres::NumericDiffOptions::relative_step_size's default, which the columns take.
  static constexpr double kRelativeStep = 1e-6;

 private:
  /// The parameter blocks by role (file comment's order).
  struct Blocks {
    const double* mount = nullptr;
    double const* const* theta = nullptr;    ///< IMU i's model
    double const* const* theta0 = nullptr;   ///< IMU 0's model
    double const* const* wander = nullptr;   ///< IMU i's accelerometer wander (from, to)
    double const* const* wander0 = nullptr;  ///< IMU 0's
  };
  Blocks Split(double const* const* parameters) const;
  /// The turn as IMU 0 saw it, per window: its corrected force f_0,w, the mean angular
  /// acceleration alpha_w and A_w (file comment), body frame.
  struct Imu0Turn {
    std::vector<Vec3> f0, alpha_b;
    std::vector<Mat3> A;
  };
  Imu0Turn TurnOfImu0(const Blocks& b) const;
  /// g_w = f_0,w + A_w r_i, the specific force at IMU i's place, and its mean rate gdot_w.
  struct ForceAtImu {
    std::vector<Vec3> g, rate;
  };
  ForceAtImu AtImu(const Imu0Turn& turn, const Blocks& b) const;
  /// f_i,w: IMU i's corrected specific force per window, in its frame.
  std::vector<Vec3> ForceOfImu(const Imu0Turn& turn, const Blocks& b) const;
  /// The whitened residuals (3 per window with samples of IMU i).
  void Whiten(const Blocks& b, const ForceAtImu& g, const std::vector<Vec3>& f,
              double* residuals) const;

  /// Each window's corrected specific force and rate of one IMU (IMU 0's means when `imu0`),
  /// from its blocks `theta`, the accelerometer wander blocks `wander` (b_from, b_to per
  /// process) and the angular acceleration per window in its frame, rad/s^2.
  void Correct(const model::Model& model, double const* const* theta, double const* const* wander,
               int processes, bool imu0, const std::vector<Vec3>& alpha, std::vector<Vec3>& f,
               std::vector<Vec3>& w) const;

  /// Per edge of the windows (n + 1), the weights of the windows' means that give a quantity's
  /// value there (file comment): those of windows first, first + 1, ...
  struct EdgeStencils {
    std::vector<std::size_t> first;
    std::vector<std::vector<double>> weights;
  };
  static EdgeStencils Stencils(const std::vector<BoardWindow>& windows);
  /// Each window's mean rate of change of x (a value per window): the difference of its edge
  /// values over its width.
  std::vector<Vec3> MeanRate(const std::vector<Vec3>& x) const;

  const model::Model* model_;
  const model::Model* model0_;
  SharedBoardWindows windows_;
  EdgeStencils stencils_;
  int accel_wander_, accel_wander0_;
  bool reads_alpha_, reads_alpha0_;  // some term of IMU i's (IMU 0's) model reads alpha_b
};

}  // namespace plumb::residuals

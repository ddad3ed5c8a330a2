// plumb/residuals/mounted_motion_residual.h — the motion residual of another IMU of the board.
//
// Another IMU of the same board (SPEC 6, "Several IMUs of one board") sits in the body at a
// rotation R_b_i, its frame into the body frame that IMU 0's accelerometer defines
// (model/board_mount.h: R_b_i = Exp(rho), rho the block's rotation vector). Rigidly
// mounted, it is an IMU at the attitude R_n_i = R_n_b R_b_i, so between still poses k and k+1
// its own gyroscope integrates, in its own frame, to
//
//   r_i = W_i Log(dR_i^T (R_k R_b_i)^T R_k+1 R_b_i)                                   (rad)
//
// with dR_i its corrected rate integrated as residuals/motion_residual.h says (Earth rate seen
// in its frame, R_n_i^T omega_ie_n), W_i its own propagated noise. That is MotionResidual at
// the attitudes R_k R_b_i and R_k+1 R_b_i, which this cost function evaluates; the angular
// rate does not depend on where on the rigid body the IMU is, so its lever arm does not enter.
//
// The time offset is left out: the intervals start and end at rest, where a millisecond's shift
// of the window moves the integrated rotation by nothing measurable.
//
// Jacobians: with the left perturbations of the attitudes' manifolds (residuals/manifolds.h),
//   Exp(d_k) R_k R_b_i      = Exp(d_k) R_n_i            -> r_i_H_d_k = r_i_H_dn_i(k)
//   R_k Exp(d_b) R_b_i      = Exp(R_k d_b) R_n_i(k)     -> r_i_H_d_b = sum_j r_i_H_dn_i(j) R_j
// over j in {k, k+1}, and Exp(rho + d_rho) = Exp(J_l(rho) d_rho) Exp(rho), so
// r_i_H_rho = r_i_H_d_b J_l(rho). The inner residual's tangent Jacobians are read back from its
// ambient ones (J_amb P(q) = J_tan, P = LeftPlusJacobian) and the attitudes' written ambient the
// same way (J_tan 4 P^T).
//
// Parameter blocks, in order: q_k (4), q_k+1 (4) (Eigen order x y z w), IMU i's board_mount
// block (7), then every block of IMU i's model in model order, then per wander process its
// b_from (3) and b_to (3), as MotionResidual has them.
#pragma once

#include "plumb/residuals/motion_residual.h"

namespace plumb::residuals {

class MountedMotionResidual final : public CachedCostFunction {
 public:
  /// The arguments of MotionResidual's, for IMU i's model and samples (its own frame, units
  /// and stamps). The model must outlive the cost function.
  MountedMotionResidual(const model::Model& model, SharedMotionSamples samples,
                        const Vec3& omega_ie_n, int wander_processes = 0);

  bool EvaluateUncached(double const* const* parameters, double* residuals,
                        double** jacobians) const override;

 private:
  MotionResidual inner_;  // evaluated at the IMU's attitudes R_k R_b_i, R_k+1 R_b_i
};

}  // namespace plumb::residuals

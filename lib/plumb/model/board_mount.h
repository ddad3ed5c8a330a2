// plumb/model/board_mount.h — where another IMU of the board sits (SPEC 6, "Several IMUs of one
// board"), and its parameter block, owned here: nothing outside this file indexes it by hand.
//
// IMU 0's accelerometer triad defines the body frame. IMU i sits in the body at a rotation
// R_b_i (its frame into the body frame), a lever arm r_i from IMU 0 and a time offset dt_i
// added to its stamps. Its inputs, in its own frame, at its stamp t:
//
//   f_i(t)     = R_b_i^T (f_b + alpha_b x r_i + omega_b x (omega_b x r_i))(t + dt_i)
//   omega_i(t) = R_b_i^T omega_b(t + dt_i)
//
// and its own error model (an upper-triangular F of its own: the rotation is R_b_i's alone)
// turns them into its outputs. Still, only R_b_i enters; the lever arm and the time offset are
// seen only in turns.
//
// Block layout (7 values; all zero = IMU i where IMU 0 is):
//   [0..2]  rotation.x, .y, .z: the rotation vector of R_b_i = Exp(rho), rad
//   [3..5]  lever_arm.x, .y, .z: r_i, m, body frame
//   [6]     time_offset: dt_i, s
#pragma once

#include "plumb/core/so3.h"
#include "plumb/core/types.h"
#include "plumb/model/effect.h"

namespace plumb::model::board_mount {

inline constexpr int kRotation = 0;    ///< offset of the rotation vector rho, rad
inline constexpr int kLeverArm = 3;    ///< offset of r_i, m
inline constexpr int kTimeOffset = 6;  ///< offset of dt_i, s
inline constexpr int kSize = 7;

/// The block's description: names without a prefix ("rotation.x", "lever_arm.z",
/// "time_offset"), SI units, typical sizes of a flight controller's IMUs (a degree, a few
/// centimetres, a millisecond), what excites each.
EffectInfo Describe();

/// The rotation vector rho of a block.
template <typename T>
Vec3T<T> RotationVector(const T* block) {
  return Vec3T<T>(block[kRotation], block[kRotation + 1], block[kRotation + 2]);
}

/// R_b_i of a block.
inline Quat Rotation(const double* block) { return so3::ExpQuat(RotationVector(block)); }

/// d R_b_i / d rho as a left perturbation: Exp(rho + d) = Exp(J_l(rho) d) Exp(rho), J_l the
/// left Jacobian of SO(3) (the right one's transpose).
inline Mat3 LeftPerturbation_H_rotation(const double* block) {
  return so3::RightJacobian(RotationVector(block)).transpose();
}

}  // namespace plumb::model::board_mount

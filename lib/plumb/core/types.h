// plumb/core/types.h — Eigen aliases shared by every module.
//
// Conventions (SPEC section 1): SI units inside (m/s^2, rad/s, s, degC); degrees only at the
// edges with `_deg` in names. Frames appear in names: `R_n_b` maps body vectors into NED,
// `f_b` is specific force in the body frame, `omega_b` the angular rate in the body frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plumb {

template <typename Scalar>
using Vec3T = Eigen::Matrix<Scalar, 3, 1>;
template <typename Scalar>
using Mat3T = Eigen::Matrix<Scalar, 3, 3>;

using Vec3 = Vec3T<double>;
using Mat3 = Mat3T<double>;
using Vec3f = Eigen::Vector3f;
using Quat = Eigen::Quaterniond;

/// Axis index helpers: 0 = x, 1 = y, 2 = z.
inline constexpr const char* kAxisName[3] = {"x", "y", "z"};

}  // namespace plumb

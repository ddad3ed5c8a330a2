// plumb/core/so3.h — SO(3) helpers on doubles (Sophus conventions): Skew, Exp, Log and the
// Jacobians used by the motion residual. Exp(phi) is the rotation by |phi| rad about phi.
//
//   Exp(phi + d) = Exp(phi) Exp(J_r(phi) d)     (to first order in d)
//   Log(Exp(d) R) = Log(R) + J_l^-1(Log R) d
#pragma once

#include <cmath>

#include "plumb/core/types.h"

namespace plumb::so3 {

inline Mat3 Skew(const Vec3& v) {
  Mat3 S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

/// sin(a)/a, (1 - cos a)/a^2 and, if `C` is given, (a - sin a)/a^3 from a2 = a^2, by series
/// below 0.05 rad (error < 1e-17; no square root) to avoid sincos on the many small steps of
/// an integration. Exp(phi) = I + A S + B S^2 and J_r(phi) = I - B S + C S^2, S = [phi]x.
inline void ExpCoefficients(double a2, double* A, double* B, double* C = nullptr) {
  if (a2 < 0.05 * 0.05) {
    *A = 1.0 - a2 / 6.0 * (1.0 - a2 / 20.0 * (1.0 - a2 / 42.0));
    *B = 0.5 - a2 / 24.0 * (1.0 - a2 / 30.0 * (1.0 - a2 / 56.0));
    if (C) *C = 1.0 / 6.0 - a2 / 120.0 * (1.0 - a2 / 42.0 * (1.0 - a2 / 72.0));
  } else {
    const double a = std::sqrt(a2);
    *A = std::sin(a) / a;
    *B = (1.0 - std::cos(a)) / a2;
    if (C) *C = (a - std::sin(a)) / (a2 * a);
  }
}

/// Rotation matrix Exp(phi), phi a rotation vector in rad.
inline Mat3 Exp(const Vec3& phi) {
  const double a2 = phi.squaredNorm();
  double A, B;
  ExpCoefficients(a2, &A, &B);
  // Rodrigues with S^2 = phi phi^T - |phi|^2 I.
  Mat3 R = B * (phi * phi.transpose());
  R.diagonal().array() += 1.0 - B * a2;
  R(0, 1) -= A * phi.z();
  R(1, 0) += A * phi.z();
  R(0, 2) += A * phi.y();
  R(2, 0) -= A * phi.y();
  R(1, 2) -= A * phi.x();
  R(2, 1) += A * phi.x();
  return R;
}

/// Unit quaternion of Exp(phi).
inline Quat ExpQuat(const Vec3& phi) {
  const double a2 = phi.squaredNorm();
  if (a2 < 0.05 * 0.05) {
    // sin(a/2)/a and cos(a/2) by series for small angles (no square root).
    const double x2 = 0.25 * a2;
    const double s = 0.5 * (1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0)));
    const double c = 1.0 - x2 / 2.0 * (1.0 - x2 / 12.0 * (1.0 - x2 / 30.0));
    return Quat(c, s * phi.x(), s * phi.y(), s * phi.z());
  }
  const double a = std::sqrt(a2);
  const double s = std::sin(0.5 * a) / a;
  return Quat(std::cos(0.5 * a), s * phi.x(), s * phi.y(), s * phi.z());
}

/// Rotation vector of R, rad, angle in [0, pi].
inline Vec3 Log(const Mat3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

/// Right Jacobian J_r(phi).
inline Mat3 RightJacobian(const Vec3& phi) {
  double A, B, C;
  ExpCoefficients(phi.squaredNorm(), &A, &B, &C);
  const Mat3 S = Skew(phi);
  return Mat3::Identity() - B * S + C * S * S;
}

/// Exp(phi) and J_r(phi) together (one set of coefficients and one S^2 for both).
inline void ExpAndRightJacobian(const Vec3& phi, Mat3* Ex, Mat3* Jr) {
  const double a2 = phi.squaredNorm();
  double A, B, C;
  ExpCoefficients(a2, &A, &B, &C);
  const Mat3 S = Skew(phi);
  Mat3 S2 = phi * phi.transpose();  // S^2 = phi phi^T - |phi|^2 I
  S2.diagonal().array() -= a2;
  *Ex = Mat3::Identity() + A * S + B * S2;
  *Jr = Mat3::Identity() - B * S + C * S2;
}

/// D [u]x, by columns (no 3 x 3 product).
inline Mat3 TimesSkew(const Mat3& D, const Vec3& u) {
  Mat3 out;
  out.col(0) = u.z() * D.col(1) - u.y() * D.col(2);
  out.col(1) = u.x() * D.col(2) - u.z() * D.col(0);
  out.col(2) = u.y() * D.col(0) - u.x() * D.col(1);
  return out;
}

/// Rotation vector of one integration step of a rate varying linearly from u0 to u1 over h
/// seconds, with the coning correction (third order in h, like RK4 on SO(3)):
/// phi = (h/2) (u0 + u1) + (h^2/12) u0 x u1. u in rad/s, phi in rad.
inline Vec3 ConingIncrement(const Vec3& u0, const Vec3& u1, double h) {
  return 0.5 * h * (u0 + u1) + (h * h / 12.0) * u0.cross(u1);
}

/// Inverse of the left Jacobian, J_l^-1(phi).
inline Mat3 LeftJacobianInverse(const Vec3& phi) {
  const double a = phi.norm();
  const Mat3 S = Skew(phi);
  if (a < 1e-4) return Mat3::Identity() - 0.5 * S + S * S / 12.0;
  return Mat3::Identity() - 0.5 * S +
         (1.0 / (a * a) - (1 + std::cos(a)) / (2 * a * std::sin(a))) * S * S;
}

}  // namespace plumb::so3

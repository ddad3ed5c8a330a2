// plumb/residuals/manifolds.h — attitude manifolds for R_n_b stored as Eigen quaternions.
//
// Plus: q' = Exp(delta_n) (x) q, a rotation vector delta_n in rad in the navigation frame (NED)
// applied on the left. Tangent coordinates are therefore small rotations of the body about
// north, east and down, in rad, and attitude covariances read directly in rad.
//
// AttitudeManifold(): tangent (north, east, down), size 3.
// TiltManifold(): tangent (north, east), size 2 — a rotation about down (heading) is not a
// direction of this manifold. It fixes the gauge of SPEC section 3: with every R_k free, a
// common turn about the vertical is seen only through Earth rate, so the heading of the first
// segment of every chain of segments joined by motion is held.
// HeadingManifold(): tangent (down), size 1 — the tilt is known (a face of a calibration
// platform), only the heading about the vertical moves.
#pragma once

#include <ceres/manifold.h>

#include <memory>

namespace plumb::residuals {

std::unique_ptr<ceres::Manifold> AttitudeManifold();
std::unique_ptr<ceres::Manifold> TiltManifold();
std::unique_ptr<ceres::Manifold> HeadingManifold();

}  // namespace plumb::residuals

// plumb/signal/chi_square.h — quantiles for detection thresholds and confidence intervals,
// from Boost.Math's distributions (exact to double precision; no approximation of our own).
#pragma once

namespace plumb::signal {

/// Quantile of the standard normal distribution: z with P(Z <= z) = p (Boost.Math's normal
/// distribution). Throws plumb::Error when p is not in (0, 1).
double NormalQuantile(double p);

/// The quantile of the chi-square distribution with `dof` degrees of freedom (dof > 0,
/// need not be an integer): x with P(X <= x) = p, from Boost.Math's chi_squared distribution
/// (the inverse of the regularised incomplete gamma function, to double precision). Throws
/// plumb::Error when p is not in (0, 1) or dof is not positive and finite.
double ChiSquareQuantileExact(double p, double dof);

}  // namespace plumb::signal

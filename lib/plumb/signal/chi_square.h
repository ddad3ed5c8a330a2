// plumb/signal/chi_square.h — quantiles for detection thresholds and confidence intervals.
//
// Two chi-square quantiles: ChiSquareQuantile, the Wilson-Hilferty approximation the still
// detector's thresholds and the report's chi^2/dof band were made with (kept so that their
// numbers stay as they are), and ChiSquareQuantileExact (Boost.Math), for confidence intervals
// that must hold at small degrees of freedom (the Allan deviation's, signal/allan.h).
#pragma once

namespace plumb::signal {

/// Quantile of the standard normal distribution: z with P(Z <= z) = p, p in (0, 1).
/// Acklam's rational approximation refined by one Halley step on std::erfc (|error| < 1e-12).
/// Throws plumb::Error when p is not in (0, 1).
double NormalQuantile(double p);

/// Quantile of the chi-square distribution with `dof` degrees of freedom (dof > 0, need not be
/// an integer): x with P(X <= x) = p, by the Wilson-Hilferty cube-root approximation
/// x = dof (1 - 2/(9 dof) + z sqrt(2/(9 dof)))^3, z the normal quantile of p. Relative error
/// under 2% for dof >= 3 and p in [1e-3, 0.999] (1.7% at dof 3, p 0.999, on the high side),
/// under 0.2% for dof >= 100. Throws plumb::Error when p
/// is not in (0, 1) or dof <= 0.
double ChiSquareQuantile(double p, double dof);

/// The exact quantile of the chi-square distribution with `dof` degrees of freedom (dof > 0,
/// need not be an integer): x with P(X <= x) = p, from Boost.Math's chi_squared distribution
/// (the inverse of the regularised incomplete gamma function, to double precision). Throws
/// plumb::Error when p is not in (0, 1) or dof is not positive and finite.
double ChiSquareQuantileExact(double p, double dof);

}  // namespace plumb::signal

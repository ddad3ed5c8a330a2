#include "plumb/signal/chi_square.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <string>

#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb::signal {
namespace {

/// Acklam's approximation of the normal quantile, relative error about 1e-9.
double AcklamQuantile(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,
                             -2.759285104469687e+02, 1.383577518672690e+02,
                             -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02,
                             -1.556989798598866e+02, 6.680131188771972e+01,
                             -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01,
                             -2.400758277161838e+00, -2.549732539343734e+00,
                             4.374664141464968e+00, 2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01,
                             2.445134137142996e+00, 3.754408661907416e+00};
  const double p_low = 0.02425;
  if (p < p_low) {
    const double q = std::sqrt(-2.0 * std::log(p));
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  }
  if (p > 1.0 - p_low) return -AcklamQuantile(1.0 - p);
  const double q = p - 0.5;
  const double r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
}

}  // namespace

double NormalQuantile(double p) {
  if (!(p > 0.0 && p < 1.0)) {
    throw Error("normal quantile: probability " + std::to_string(p) + " is not in (0, 1)");
  }
  double z = AcklamQuantile(p);
  // One Halley step on F(z) - p with F(z) = erfc(-z / sqrt 2) / 2.
  const double e = 0.5 * std::erfc(-z / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(units::kTwoPi) * std::exp(0.5 * z * z);
  z -= u / (1.0 + 0.5 * z * u);
  return z;
}

double ChiSquareQuantile(double p, double dof) {
  if (!(dof > 0.0) || !std::isfinite(dof)) {
    throw Error("chi-square quantile: degrees of freedom " + std::to_string(dof) +
                " must be positive and finite");
  }
  const double z = NormalQuantile(p);
  const double h = 2.0 / (9.0 * dof);
  const double cube_root = std::max(0.0, 1.0 - h + z * std::sqrt(h));
  return dof * cube_root * cube_root * cube_root;
}

double ChiSquareQuantileExact(double p, double dof) {
  if (!(dof > 0.0) || !std::isfinite(dof)) {
    throw Error("chi-square quantile: degrees of freedom " + std::to_string(dof) +
                " must be positive and finite");
  }
  if (!(p > 0.0 && p < 1.0)) {
    throw Error("chi-square quantile: probability " + std::to_string(p) + " is not in (0, 1)");
  }
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), p);
}

}  // namespace plumb::signal

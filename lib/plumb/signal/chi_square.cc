#include "plumb/signal/chi_square.h"

#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <string>

#include "plumb/core/error.h"

namespace plumb::signal {

double NormalQuantile(double p) {
  if (!(p > 0.0 && p < 1.0)) {
    throw Error("normal quantile: probability " + std::to_string(p) + " is not in (0, 1)");
  }
  return boost::math::quantile(boost::math::normal_distribution<double>(0.0, 1.0), p);
}

double ChiSquareQuantileExact(double p, double dof) {
  if (!(dof > 0.0) || !std::isfinite(dof)) {
    throw Error("chi-square quantile: degrees of freedom " + Number(dof) +
                " must be positive and finite");
  }
  if (!(p > 0.0 && p < 1.0)) {
    throw Error("chi-square quantile: probability " + std::to_string(p) + " is not in (0, 1)");
  }
  return boost::math::quantile(boost::math::chi_squared_distribution<double>(dof), p);
}

}  // namespace plumb::signal

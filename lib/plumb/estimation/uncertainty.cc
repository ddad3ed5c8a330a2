#include "plumb/estimation/uncertainty.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace plumb::estimation {

double Chi2BandUpper(int dof) { return 1.0 + kChi2BandSigmas * std::sqrt(2.0 / std::max(dof, 1)); }

std::pair<double, double> Chi2Band(int dof) {
  if (dof <= 0) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan};
  }
  const double spread = kChi2BandSigmas * std::sqrt(2.0 / dof);
  return {std::max(0.0, 1.0 - spread), 1.0 + spread};
}

bool Chi2AboveBand(const FitReport& fit) {
  return fit.dof > 0 && fit.chi2_dof() > Chi2BandUpper(fit.dof);
}

bool MisfitBeyondNoise(const FitReport& fit) {
  return fit.dof > 0 && fit.chi2_dof() > kMisfitFactor * Chi2BandUpper(fit.dof);
}

TurnVelocityFit VelocityFit(const FitReport& fit) {
  TurnVelocityFit out;
  for (const MotionFit& m : fit.motion) {
    if (!m.has_velocity) continue;
    out.chi2 += m.velocity_whitened.squaredNorm();
    out.residuals += 3;
  }
  return out;
}

double SigmaScale(const FitReport& fit) {
  return Chi2AboveBand(fit) ? std::sqrt(fit.chi2_dof()) : 1.0;
}

NamedCovariance ParameterCovariance(const Calibration& calibration) {
  std::vector<Eigen::Index> rows;
  NamedCovariance out;
  const auto& params = calibration.parameters;
  for (std::size_t i = 0; i < params.size(); ++i) {
    if (params[i].fixed || !params[i].observable) continue;
    rows.push_back(static_cast<Eigen::Index>(i));
    out.names.push_back(params[i].name);
  }
  const auto n = static_cast<Eigen::Index>(rows.size());
  out.matrix = Eigen::MatrixXd::Zero(n, n);
  const Eigen::MatrixXd& C = calibration.covariance;
  for (Eigen::Index a = 0; a < n; ++a) {
    for (Eigen::Index b = 0; b < n; ++b) {
      if (rows[a] < C.rows() && rows[b] < C.cols()) out.matrix(a, b) = C(rows[a], rows[b]);
    }
  }
  out.matrix = 0.5 * (out.matrix + out.matrix.transpose()).eval();  // exactly symmetric
  return out;
}

NamedCovariance DeterminedCovariance(const Calibration& calibration) {
  const Observability& o = calibration.observability;
  NamedCovariance out;
  for (const auto& c : o.determined) out.names.push_back(c.text);
  const auto k = static_cast<Eigen::Index>(o.determined.size());
  const bool sized = o.determined_covariance.rows() == k && o.determined_covariance.cols() == k;
  out.matrix = sized ? o.determined_covariance : Eigen::MatrixXd::Zero(k, k);
  out.matrix = 0.5 * (out.matrix + out.matrix.transpose()).eval();
  return out;
}

}  // namespace plumb::estimation

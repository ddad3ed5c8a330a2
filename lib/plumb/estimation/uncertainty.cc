#include "plumb/estimation/uncertainty.h"

#include <cmath>
#include <map>

namespace plumb::estimation {

bool Chi2AboveBand(const FitReport& fit) {
  if (fit.dof <= 0) return false;
  return fit.chi2_dof() > 1.0 + kChi2BandSigmas * std::sqrt(2.0 / fit.dof);
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
  return out;
}

NamedCovariance DeterminedCovariance(const Calibration& calibration) {
  std::map<std::string, Eigen::Index> index;
  for (std::size_t i = 0; i < calibration.parameters.size(); ++i) {
    index[calibration.parameters[i].name] = static_cast<Eigen::Index>(i);
  }
  const Eigen::MatrixXd& C = calibration.covariance;
  const auto n = static_cast<Eigen::Index>(calibration.parameters.size());
  const auto& determined = calibration.observability.determined;
  const auto k = static_cast<Eigen::Index>(determined.size());
  Eigen::MatrixXd combos = Eigen::MatrixXd::Zero(n, k);  // one column per combination
  NamedCovariance out;
  for (Eigen::Index j = 0; j < k; ++j) {
    const Combination& c = determined[static_cast<std::size_t>(j)];
    out.names.push_back(c.text);
    for (std::size_t i = 0; i < c.names.size() && i < c.coefficients.size(); ++i) {
      const auto at = index.find(c.names[i]);
      if (at != index.end()) combos(at->second, j) = c.coefficients[i];
    }
  }
  out.matrix = (C.rows() == n && C.cols() == n) ? Eigen::MatrixXd(combos.transpose() * C * combos)
                                                : Eigen::MatrixXd::Zero(k, k);
  return out;
}

}  // namespace plumb::estimation

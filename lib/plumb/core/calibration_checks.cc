// See calibration_checks.h.
#include "plumb/core/calibration_checks.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <map>

#include "plumb/core/number_text.h"

namespace plumb {
namespace {

std::string Figure(double v) { return SignificantText(v, 3); }

}  // namespace

std::string NoSensorsProblem(double value, double nominal, double typical, const std::string& unit) {
  if (std::abs(value - nominal) <= kMaxTypicals * typical) return "";
  return SignificantText(value, 4) + " is no sensor's: more than " +
         SignificantText(kMaxTypicals, 1) + " times its typical magnitude (" +
         SignificantText(typical, 3) + " " + unit + ")";
}

std::optional<std::pair<std::size_t, std::size_t>> FirstRepeat(
    const std::vector<std::string>& names) {
  std::map<std::string, std::size_t> first;
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto [at, fresh] = first.emplace(names[k], k);
    if (!fresh) return std::pair<std::size_t, std::size_t>{k, at->second};
  }
  return std::nullopt;
}

std::string SensorMatrixProblem(const Mat3& m) {
  if (!m.allFinite()) return "not finite";
  const Eigen::JacobiSVD<Mat3> svd(m);
  const Vec3 s = svd.singularValues();
  if (!(s(2) > 0.0)) return "singular (it maps some input to zero)";
  const double condition = s(0) / s(2);
  if (condition > kMaxSensorMatrixCondition) {
    return "near-singular (condition number " + Figure(condition) + ", above " +
           Figure(kMaxSensorMatrixCondition) + "; a MEMS part's is about 1.1)";
  }
  return "";
}

std::string CovarianceProblem(const Eigen::MatrixXd& c) {
  if (c.rows() != c.cols()) return "the covariance is not square";
  if (c.size() == 0) return "";
  if (!c.allFinite()) return "the covariance is not finite";
  const double scale = c.cwiseAbs().maxCoeff();
  const double asymmetry = (c - c.transpose()).cwiseAbs().maxCoeff();
  if (asymmetry > 1e-9 * scale) {
    return "the covariance is not symmetric (entries differ from their transpose by up to " +
           Figure(asymmetry) + ")";
  }
  for (Eigen::Index i = 0; i < c.rows(); ++i) {
    if (c(i, i) < 0.0) {
      return "the covariance has a negative variance on row " + std::to_string(i) + " (" +
             Figure(c(i, i)) + ")";
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(c, Eigen::EigenvaluesOnly);
  const double smallest = eig.eigenvalues().minCoeff();
  const double largest = eig.eigenvalues().maxCoeff();
  if (smallest < -1e-9 * std::max(largest, 0.0)) {
    return "the covariance is not positive semidefinite (an eigenvalue " + Figure(smallest) +
           "; the largest " + Figure(largest) + ")";
  }
  return "";
}

}  // namespace plumb

#include "plumb/estimation/covariance.h"

#include "plumb/estimation/solve.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace plumb::estimation {
namespace {

/// ceres::Covariance over the free model blocks of `fitted` into `cov` (zero elsewhere);
/// false when Ceres finds the problem singular or there is nothing to compute.
bool CeresCovariance(ceres::Problem& fitted, const model::Model& model,
                     const std::vector<const double*>& fitted_blocks, Eigen::MatrixXd& cov) {
  std::vector<const double*> blocks;
  std::vector<int> block_term;
  for (int t = 0; t < model.num_terms(); ++t) {
    const double* b = fitted_blocks[static_cast<std::size_t>(t)];
    if (fitted.IsParameterBlockConstant(b)) continue;
    blocks.push_back(b);
    block_term.push_back(t);
  }
  std::vector<std::pair<const double*, const double*>> pairs;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    for (std::size_t j = i; j < blocks.size(); ++j) pairs.emplace_back(blocks[i], blocks[j]);
  }
  ceres::Covariance::Options cov_options;
  cov_options.algorithm_type = ceres::DENSE_SVD;
  cov_options.num_threads = 1;
  ceres::Covariance covariance(cov_options);
  if (pairs.empty() || !covariance.Compute(pairs, &fitted)) return false;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    for (std::size_t j = i; j < blocks.size(); ++j) {
      const auto ti = static_cast<std::size_t>(block_term[i]);
      const auto tj = static_cast<std::size_t>(block_term[j]);
      const int ni = model.terms()[ti].effect->info().size();
      const int nj = model.terms()[tj].effect->info().size();
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> C(ni, nj);
      covariance.GetCovarianceBlock(blocks[i], blocks[j], C.data());
      const int oi = model.FirstParameter(block_term[i]);
      const int oj = model.FirstParameter(block_term[j]);
      cov.block(oi, oj, ni, nj) = C;
      cov.block(oj, oi, nj, ni) = C.transpose();
    }
  }
  return true;
}

}  // namespace

// The catalogue's SI unit, or, for the base effects on unscaled sensor output, that output's
// unit (bias) and unit per SI input (matrix).
std::string ParameterUnit(const model::Model& model, model::ParameterPlace place,
                          const ImuSeries& series) {
  const model::EffectInfo& info = model.terms()[static_cast<std::size_t>(place.term)].effect->info();
  const int i = place.index;
  const std::string& si = info.parameters[static_cast<std::size_t>(i)].unit;
  const bool accel = info.sensor == model::Sensor::kAccel;
  const std::string& out = accel ? series.acc_unit : series.gyr_unit;
  const std::string in = accel ? "m/s^2" : "rad/s";
  if (out == in || info.input_side) return si;
  if (!info.linear_stage) {
    // Additive terms are in output units: "rad/s per m/s^2" becomes "counts per m/s^2".
    return info.ScalesWithOutput(i) ? out + si.substr(in.size()) : si;
  }
  const bool matrix = model.Role(place) != model::ParameterRole::kBias;
  return matrix ? out + " per " + in : out;
}

std::vector<ParameterEstimate> ReportParameters(const model::Model& model,
                                                const model::ParameterBlocks& theta,
                                                const ImuSeries& series,
                                                const UnknownColumns& columns,
                                                const ObservabilityAnalysis& analysis,
                                                std::vector<Eigen::Index>& column_of) {
  const auto values = model::ReportedValues(model, theta);
  std::vector<ParameterEstimate> out;
  column_of.assign(values.size(), -1);
  int flat = 0;
  for (int t = 0; t < model.num_terms(); ++t) {
    const auto& term = model.terms()[static_cast<std::size_t>(t)];
    const auto& info = term.effect->info();
    for (int i = 0; i < info.size(); ++i, ++flat) {
      ParameterEstimate p;
      p.name = info.ParameterName(i);
      p.place = {t, i};
      p.unit = ParameterUnit(model, p.place, series);
      p.value = values[static_cast<std::size_t>(flat)];
      p.fixed = term.fixed[static_cast<std::size_t>(i)];
      const auto& index = columns.model_index;
      const auto col = std::find(index.begin(), index.end(), std::make_pair(t, i));
      if (col != index.end()) {
        const auto c = col - index.begin();
        column_of[static_cast<std::size_t>(flat)] = c;
        p.observable = analysis.observable[static_cast<std::size_t>(c)];
      }
      out.push_back(p);
    }
  }
  return out;
}

void ComputeCovariance(ceres::Problem& fitted, const std::vector<const double*>& fitted_blocks,
                       const ObservabilityAnalysis& analysis,
                       const std::vector<Eigen::Index>& column_of,
                       const CalibrationOptions& options, Calibration& calibration,
                       std::vector<Notice>& warnings) {
  const auto n = static_cast<Eigen::Index>(calibration.parameters.size());
  calibration.covariance = Eigen::MatrixXd::Zero(n, n);
  // With the bias-wander states (more than kDenseUnknowns unknowns) the analysis's covariance,
  // the wander eliminated by Eigen's sparse Cholesky (solve.h): ceres::Covariance would need
  // SuiteSparseQR, whose BLAS kernels make the last bits depend on the heap layout.
  const bool dense = fitted.NumParameters() <= kDenseUnknowns;
  // With weak combinations held the fitted problem's covariance would be the one conditional
  // on them, too small for the parameters their hold at a guess moves: the analysis's is not.
  const bool weak = !analysis.weak.empty();
  const bool from_ceres =
      options.use_ceres_covariance && dense && !weak &&
      CeresCovariance(fitted, calibration.model, fitted_blocks, calibration.covariance);
  if (!from_ceres) {
    if (options.use_ceres_covariance && dense && !weak && calibration.model.num_free_parameters() > 0) {
      warnings.push_back(Notice{"covariance_singular",
                                "ceres::Covariance found the problem singular; sigmas are from "
                                "the pseudo-inverse of the column-scaled Jacobian",
                                {}});
    }
    for (Eigen::Index a = 0; a < n; ++a) {
      for (Eigen::Index b = 0; b < n; ++b) {
        const auto ca = column_of[static_cast<std::size_t>(a)];
        const auto cb = column_of[static_cast<std::size_t>(b)];
        if (ca >= 0 && cb >= 0) calibration.covariance(a, b) = analysis.covariance(ca, cb);
      }
    }
  }
  for (std::size_t i = 0; i < calibration.parameters.size(); ++i) {
    auto& p = calibration.parameters[i];
    const auto ii = static_cast<Eigen::Index>(i);
    p.sigma = (p.observable && !p.fixed)
                  ? std::sqrt(std::max(0.0, calibration.covariance(ii, ii)))
                  : std::numeric_limits<double>::quiet_NaN();
  }
  calibration.sigma_source = from_ceres ? "ceres::Covariance (DENSE_SVD)"
                             : dense    ? "pseudo-inverse"
                                        : "pseudo-inverse (bias-wander states eliminated)";
}

}  // namespace plumb::estimation

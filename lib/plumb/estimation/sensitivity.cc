#include "plumb/estimation/sensitivity.h"

#include <Eigen/SparseCholesky>
#include <cmath>
#include <limits>

#include "plumb/core/error.h"
#include "plumb/estimation/fitted_problem.h"
#include "plumb/estimation/still_set.h"

namespace plumb::estimation {
namespace {

/// The whitened residuals of the fitted solution in a problem built on `segments` and `site`
/// (the same structure as the fitted one, in the same order).
Eigen::VectorXd ResidualsUnder(const ImuSeries& series, const std::vector<StillSegment>& segments,
                               const geo::Site& site, const model::Model& model,
                               const CalibrationOptions& options, FittedProblem& fitted) {
  const bool has_gyro = model.has_gyro();
  const bool earth_rate_seen = site.known && has_gyro && options.use_still_gyro;
  const bool motion_on = options.use_motion && has_gyro;
  StillSet still = MakeStillSet(series, segments, earth_rate_seen, motion_on, options);
  model::ParameterBlocks unused = model.ZeroParameters();
  Initialize(series, model, site.gravity(), has_gyro, options.first_heading_deg, still, unused);
  AssignHeadingGauge(still, has_gyro);
  CalibrationProblem problem(series, model, site, std::move(still), fitted.problem->theta(),
                             fitted.noise, fitted.start, options);
  problem.TakeValues(*fitted.problem);
  problem.SetMotionWeightsFromSolution();
  BuiltProblem built = problem.Build(fitted.solution.gauge);
  double cost = 0.0;
  std::vector<double> r;
  built.problem->Evaluate(ceres::Problem::EvaluateOptions{}, &cost, &r, nullptr, nullptr);
  return Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
}

/// d(parameter)/d(change) at the fitted solution (file comment).
Sensitivities SensitivityAt(const ImuSeries& series, const std::vector<StillSegment>& segments,
                            const CalibrationOptions& options, FittedProblem& fitted,
                            const model::Model& model,
                            const std::vector<AssumptionChange>& changes) {
  Sensitivities out;
  out.names = model.ParameterNames();
  if (changes.empty()) return out;  // nothing to differentiate: no Jacobian, no factorisation
  CalibrationProblem& problem = *fitted.problem;
  ceres::Problem& at = fitted.solution.fitted();
  const UnknownColumns columns = problem.Columns(at, fitted.solution.gauge.parameters);
  const Eigen::SparseMatrix<double> J = problem.SparseJacobian(at, columns, nullptr, nullptr);
  const Eigen::SparseMatrix<double> normal = Eigen::SparseMatrix<double>(J.transpose()) * J;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(normal);
  if (ldlt.info() != Eigen::Success) {
    throw Error("sensitivity: the normal matrix at the solution cannot be factored");
  }
  // The reported parameters: term by term, in the model's order.
  std::vector<Eigen::Index> offset;
  Eigen::Index n = 0;
  for (const auto& term : model.terms()) {
    offset.push_back(n);
    n += term.effect->info().size();
  }
  out.d_dp = Eigen::MatrixXd::Constant(n, static_cast<Eigen::Index>(changes.size()),
                                       std::numeric_limits<double>::quiet_NaN());
  for (std::size_t c = 0; c < changes.size(); ++c) {
    const AssumptionChange& change = changes[c];
    if (!(change.step > 0.0) || change.segments_minus.size() != segments.size() ||
        change.segments_plus.size() != segments.size()) {
      throw Error("sensitivity: change '" + change.name + "' needs a step > 0 and the session's segments");
    }
    const Eigen::VectorXd minus =
        ResidualsUnder(series, change.segments_minus, change.site_minus, model, options, fitted);
    const Eigen::VectorXd plus =
        ResidualsUnder(series, change.segments_plus, change.site_plus, model, options, fitted);
    if (minus.size() != J.rows() || plus.size() != J.rows()) {
      throw Error("sensitivity: change '" + change.name + "' changes the problem's structure");
    }
    const Eigen::VectorXd dr = (plus - minus) / (2.0 * change.step);
    const Eigen::VectorXd dx = -ldlt.solve(Eigen::VectorXd(J.transpose() * dr));
    for (std::size_t col = 0; col < columns.is_model.size(); ++col) {
      if (!columns.is_model[col]) continue;
      const auto [t, i] = columns.model_index[col];
      out.d_dp(offset[static_cast<std::size_t>(t)] + i, static_cast<Eigen::Index>(c)) =
          dx[static_cast<Eigen::Index>(col)];
    }
  }
  return out;
}

}  // namespace

SensitiveCalibration CalibrateWithSensitivities(const ImuSeries& series,
                                                const std::vector<StillSegment>& segments,
                                                const model::Model& model_in,
                                                const geo::Site& site,
                                                const CalibrationOptions& options,
                                                const std::vector<AssumptionChange>& changes) {
  SensitiveCalibration out;
  FittedProblem fitted = FitProblem(series, segments, model_in, site, options, out.result);
  FinishCalibration(series, segments, options, fitted, out.result);
  out.sensitivities = SensitivityAt(series, segments, options, fitted,
                                    out.result.calibration.model, changes);
  return out;
}

Sensitivities AssumptionSensitivity(const ImuSeries& series,
                                    const std::vector<StillSegment>& segments,
                                    const model::Model& model, const geo::Site& site,
                                    const CalibrationOptions& options,
                                    const std::vector<AssumptionChange>& changes) {
  return CalibrateWithSensitivities(series, segments, model, site, options, changes).sensitivities;
}

}  // namespace plumb::estimation

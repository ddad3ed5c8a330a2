// plumb/estimation/covariance.h — stage 6 of the backend: the reported parameters, their
// covariance and sigmas.
//
// The covariance is computed by ceres::Covariance (DENSE_SVD) on the problem with the null
// directions' pivots held (solve.h), full rank by construction. For every observable parameter
// and every determined combination (estimable functions) the variance does not depend on which
// member of a null direction is held, so it equals the observability analysis's pseudo-inverse
// (tests/estimation checks this); held pivots get zero rows and columns. Should Ceres find the
// held problem singular, or options.use_ceres_covariance be off, the pseudo-inverse is used.
//
// INTERNAL to plumb::estimation (not installed): it works on Ceres's problem
// (calibration_problem.h); what it reports is in calibration.h and uncertainty.h.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/observability.h"
#include "plumb/estimation/options.h"

namespace plumb::estimation {

/// Every parameter of the model with its value, unit (the sensor's output units where the
/// series is not SI), fixed and observable flags; sigma is left NaN. `column_of` receives,
/// per parameter, its column among `columns` (-1 when it has none: fixed, or its block held).
/// The unit of the parameter at `place` of `model` as reported for `series`'s outputs (SI, or
/// the output's unit where the parameter is in it).
std::string ParameterUnit(const model::Model& model, model::ParameterPlace place,
                          const ImuSeries& series);

std::vector<ParameterEstimate> ReportParameters(const model::Model& model,
                                                const model::ParameterBlocks& theta,
                                                const ImuSeries& series,
                                                const UnknownColumns& columns,
                                                const ObservabilityAnalysis& analysis,
                                                std::vector<Eigen::Index>& column_of);

/// Stage 6 (file comment): fills `calibration.covariance`, `sigma_source` and every
/// parameter's sigma (NaN for fixed and unobservable ones). `fitted` is the problem the fit
/// was made on and `fitted_blocks` where it keeps each term's block
/// (CalibrationProblem::ModelBlocks());
/// warnings go to `warnings`.
void ComputeCovariance(ceres::Problem& fitted, const std::vector<const double*>& fitted_blocks,
                       const ObservabilityAnalysis& analysis,
                       const std::vector<Eigen::Index>& column_of,
                       const CalibrationOptions& options, Calibration& calibration,
                       std::vector<Notice>& warnings);

}  // namespace plumb::estimation

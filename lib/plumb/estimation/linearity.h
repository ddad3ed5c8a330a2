// plumb/estimation/linearity.h — does the linearised covariance describe the fit's cost?
//
// The covariance (covariance.h) is the inverse of the Gauss-Newton normal matrix at the
// solution: it assumes chi^2 is quadratic in the unknowns over the confidence region. Where
// the model is strongly nonlinear there — a curved valley of equally good fits, as with only
// the six faces and free attitudes, where the accelerometer's cross-axis terms are tied to
// the gyroscope's matrix through the turns alone — the linear ellipse is tangent to a banana,
// and the estimate's error across the ellipse's narrow axes can be hundreds of their sigma
// while each parameter's own sigma still covers it (NEES 1e5 over the full covariance).
//
// The check measures the curvature (Bates and Watts) instead of expanding it. With C the
// model parameters' covariance (attitudes and wander states marginalised), D its sigmas and
// R = D^-1 C D^-1 = V diag(mu) V^T its correlation matrix, each d_k = D v_k sqrt(mu_k) (of the
// loosest, kLinearityDirections below) is one
// sigma in the fit's own metric (d_k^T C^-1 d_k = 1). The step +-c d_k, with the other
// unknowns at their conditional optimum (-N_rr^-1 N_rm c d_k, N = J^T J), raises chi^2 by
// exactly c^2 in a linear model. The actual rise, through the problem's own residuals and
// manifolds, over c^2 is the direction's ratio: 1 where the covariance holds, far above 1
// where the model curves away within c sigma (LinearityReport, fit_report.h).
//
// INTERNAL to plumb::estimation (not installed): it works on Ceres's problem
// (calibration_problem.h); its report is fit_report.h's LinearityReport.
#pragma once

#include <ceres/ceres.h>

#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/elimination.h"
#include "plumb/estimation/fit_report.h"

namespace plumb::estimation {

/// The step c of the check, in sigma: far enough out to meet the curvature that moves a
/// 95 % region (a 21-parameter region reaches 5.6 sigma along its axes, one direction's
/// 2 sigma), near enough that a well-posed fit stays quadratic (ratios 1.00-1.2 on the
/// simulated multi-pose and benchmark sessions of the tests; 1.00 on mikoff's and imu_tk's
/// sessions, 1.06 on changhyeonkim93's imu_good2; imu_good1, 7 poses, gives 6.3).
inline constexpr double kLinearityStepSigmas = 2.0;

/// Directions checked: the kLinearityDirections loosest of the correlation matrix (largest mu).
/// A curved valley of near-equal fits runs along the loose directions: on the six faces with
/// free attitudes the largest ratios (1e5-1e7) are at the two largest mu, and every ratio
/// above 2 within the six largest; the tight combinations stay quadratic. Each direction costs
/// two evaluations of the residuals.
inline constexpr int kLinearityDirections = 6;

/// The check of the file comment on `problem` (built by `calibration` with `held` held, at
/// its solution: Solution::fitted() and its gauge's parameters), with steps of `step_sigmas` sigma; the
/// problem's values are not touched. Not checked
/// (LinearityReport::checked false) without free model parameters or when the reduced normal
/// matrix is not positive definite (the observability analysis then says why).
/// `jacobian` (optional): the whitened Jacobian of `problem` at its solution over
/// calibration.Columns(problem, held), and `cost` its cost there, when the caller has them
/// (the analysis's, FinishCalibration), so as not to evaluate them again; `eliminated`
/// (optional, with `jacobian`): the analysis's elimination of every column after the model's
/// (AnalysedSolution::eliminated), so as not to factorise again. The points of the check are
/// evaluated at once through `run_jobs` (core/jobs.h); the report is the same either way.
LinearityReport CheckLinearity(CalibrationProblem& calibration, ceres::Problem& problem,
                               const std::vector<ParameterIndex>& held,
                               double step_sigmas = kLinearityStepSigmas,
                               const Eigen::SparseMatrix<double>* jacobian = nullptr,
                               double cost = 0.0, const EliminatedJacobian* eliminated = nullptr,
                               const JobRunner& run_jobs = {});

}  // namespace plumb::estimation

// plumb/study/run.h — one Monte Carlo run of a study point: simulate the point's design with
// its own seed (study.h, RunSeed), fit it with the generalized method, and score the estimate
// against the truth.
//
// Truth of a fitted parameter: the simulated model's value of the parameter of that name, or
// the fitted model's nominal value when the simulated model does not have it (an effect fitted
// but not simulated is truly zero). A simulated effect the fit lacks shows only as the error it
// leaves in the fitted parameters. Attitudes are unknown to the fit except on the paper's
// static design, where the fit assumes level, x north (the truth may be off by
// level_error_deg and heading_error_deg). The fit is given the simulated site,
// off by fit_lat_error_deg in latitude, and fit_gravity_m_s2 instead of WGS84 gravity when > 0.
//
// NEES = e^T C^-1 e over the parameters that are free and observable (C their block of the
// reported covariance, solved by LDLT); NaN when C is not positive definite. Where the data
// determine no parameter alone (one pose), the combinations they do determine are the rows
// (named by their text, e.g. "accel.bias.z - 9.78 accel.matrix.zz") and the NEES is over
// their covariance.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "plumb/sim/schedule.h"
#include "plumb/study/study.h"

namespace plumb::study {

/// The poses and timing of a real session (schedule "session"), from the calibration
/// document `doc` (SPEC section 6) read from `path`: each still segment's fitted attitude held for the
/// segment's length, joined by single-axis turns lasting the gap to the next segment (at least
/// 0.5 s). The sample interval comes from the segments' mid times and sample indices. Throws
/// plumb::InputError naming `path` when the document has fewer than 2 segments or a segment
/// lacks its attitude, indices or time.
sim::Schedule TemplateSchedule(const nlohmann::json& doc, const std::string& path);

struct RunOutcome {
  bool failed = false;   ///< the fit threw or did not converge
  std::string failure;   ///< why, when failed
  bool flagged = false;  ///< the fit failed a gate (estimation/gates.h)
  std::vector<std::string> names, units;  ///< the fitted model's parameters, in order
  std::vector<double> error;  ///< estimate - truth per parameter; NaN: fixed or unobservable
  std::vector<double> sigma;  ///< the reported sigma; NaN where none
  double nees = std::numeric_limits<double>::quiet_NaN();
  int nees_dof = 0;  ///< parameters in the NEES
  double chi2_dof = std::numeric_limits<double>::quiet_NaN();
  /// The analytic sensitivity of every parameter (rows as `names`) to each of the study's
  /// fit-side factors (SensitivityFactors), estimation/sensitivity.h: d_dp[f][i], per unit of
  /// the factor. Empty unless the study has such factors and the method is generalized.
  std::vector<std::vector<double>> d_dp;
};

/// The study's factors whose analytic sensitivity a run computes, in Study::factors order:
/// fit_gravity_m_s2 and fit_lat_error_deg (what the fit is told; estimation/sensitivity.h),
/// level_error_deg and heading_error_deg on the paper_static schedule (the attitude the fit
/// assumes, moved the other way: to first order the same mismatch between hold and fit),
/// and truth.PARAMETER of an effect the fitted model lacks (the bias a missing effect leaves
/// per unit of it, from the effect's probe columns).
std::vector<std::string> SensitivityFactors(const Study& study);

/// Run `run` of `point` (file comment). Never throws for a failed fit (failed, failure say
/// it); throws plumb::Error for a study that cannot be simulated (an unknown model spec or
/// truth parameter).
RunOutcome RunOnce(const Study& study, const Point& point, int run);

}  // namespace plumb::study

// plumb/estimation/uncertainty.h — the covariance as outputs give it (SPEC section 6): over
// the free, observable parameters with their names, over the determined combinations where
// the full one is singular, and the factor the sigmas are scaled by when chi^2/dof is
// significantly above its band.
//
// chi^2/dof of a fit whose model and noise are right has mean 1 and standard deviation
// sqrt(2 / dof). Above 1 + kChi2BandSigmas sqrt(2 / dof) the residuals exceed the noise the
// fit was whitened with, so the formal covariance (the inverse of the whitened normal matrix)
// is too small; the usual remedy (Birge ratio) scales it by chi^2/dof, the sigmas by
// sqrt(chi^2/dof). Outputs that give "the" sigma give the scaled one then, and the formal one
// beside it (report/json_report.h, report/calibration_text.h).
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"

namespace plumb::estimation {

/// Width of chi^2/dof's band, in its standard deviations sqrt(2 / dof).
inline constexpr double kChi2BandSigmas = 3.0;

/// The upper edge of chi^2/dof's band, 1 + kChi2BandSigmas sqrt(2 / dof) (dof >= 1).
double Chi2BandUpper(int dof);

/// chi^2/dof's band under a complete model, 1 -+ kChi2BandSigmas sqrt(2 / dof) (the lower edge
/// at least 0): the one meaning of "consistent with the noise" for every output (the
/// terminal's verdict, the report page, the sigmas' scaling). {NaN, NaN} when dof <= 0.
std::pair<double, double> Chi2Band(int dof);

/// chi^2/dof is above Chi2BandUpper (false without degrees of freedom).
bool Chi2AboveBand(const FitReport& fit);

/// chi^2/dof more than kMisfitFactor times the band's upper edge: the misfit is a missing
/// effect or bad segments, not noise, and even the scaled sigma (which assumes the misfit is
/// random) is not to be trusted; another session of the same sensor can differ by more.
inline constexpr double kMisfitFactor = 3.0;
bool MisfitBeyondNoise(const FitReport& fit);

/// The velocity residuals of the turns in a fit (3 per turn that has one): their chi^2 and
/// count. Weighted by the white noise or each turn's measured vibration (turn_noise.h), they
/// sit at their noise when the model explains the accelerometer during the turns; above
/// their band they carry what it lacks, and what only they determine (the effects that need
/// the accelerometer in motion: time_offset, accel_size_effect) is not to be trusted.
struct TurnVelocityFit {
  double chi2 = 0.0;
  int residuals = 0;
  double per_residual() const { return residuals > 0 ? chi2 / residuals : 0.0; }
  /// chi^2 per residual above Chi2BandUpper(residuals) (false without any).
  bool above_band() const { return residuals > 0 && per_residual() > Chi2BandUpper(residuals); }
};
TurnVelocityFit VelocityFit(const FitReport& fit);

/// sqrt(chi^2/dof) when Chi2AboveBand(fit), else 1: the factor on every reported sigma.
double SigmaScale(const FitReport& fit);

/// A covariance matrix with the names of its rows (and columns).
struct NamedCovariance {
  std::vector<std::string> names;
  Eigen::MatrixXd matrix;  ///< formal (not scaled), SI units (sensor units for counts)
};

/// The covariance of the free, observable parameters, in model order.
NamedCovariance ParameterCovariance(const Calibration& calibration);

/// The covariance of the determined combinations (calibration.observability.determined),
/// c_i^T C c_j with C the observability analysis's covariance, the one their sigmas come from
/// (Observability::determined_covariance), so that its diagonal is their sigma squared.
NamedCovariance DeterminedCovariance(const Calibration& calibration);

}  // namespace plumb::estimation

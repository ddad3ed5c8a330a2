// plumb/report/calibration_text.h — a calibration and its fit as text for a terminal (the
// library formats; only the command prints).
#pragma once

#include <string>

#include "plumb/estimation/result.h"

namespace plumb::report {

/// A few lines: method, model, chi^2/dof, rank, convergence.
std::string BriefReport(const estimation::CalibrationResult& result);
/// When chi^2/dof is above its band (estimation::Chi2AboveBand): what that means for the
/// sigma, the factor of the scaled sigma, which sigma the JSON and the exports carry, and,
/// beyond estimation::kMisfitFactor times the band, not to trust the parameters to it; ""
/// otherwise. One line per sentence group, each ending in '\n'.
std::string OverDispersionNote(const estimation::FitReport& fit);
/// BriefReport, the site, residual RMS and noise, the parameter table with sigmas, the
/// observability section and the warnings.
std::string FullReport(const estimation::CalibrationResult& result);

}  // namespace plumb::report

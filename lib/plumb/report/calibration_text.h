// plumb/report/calibration_text.h — a calibration and its fit as text for a terminal (the
// library formats; only the command prints).
#pragma once

#include <string>

#include "plumb/estimation/result.h"

namespace plumb::report {

/// A few lines: method, model, chi^2/dof, rank, convergence.
std::string BriefReport(const estimation::CalibrationResult& result);
/// BriefReport, the site, residual RMS and noise, the parameter table with sigmas, the
/// observability section and the warnings.
std::string FullReport(const estimation::CalibrationResult& result);

}  // namespace plumb::report

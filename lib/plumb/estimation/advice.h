// plumb/estimation/advice.h — stage 8 of the backend: what the data cannot determine and what
// to record, in words ("too little data: record ..."), and the warnings about the site and the
// heading gauge (SPEC section 3).
#pragma once

#include <vector>

#include "plumb/core/types.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/still_set.h"

namespace plumb::estimation {

/// Adds to `fit.warnings` what the data cannot determine (with what to record), the missing
/// site and the heading gauge. Throws plumb::InsufficientDataError instead when a parameter is
/// undetermined and options.on_insufficient is kError.
void AddAdvice(const Calibration& calibration, const StillSet& still,
               const CalibrationOptions& options, FitReport& fit);

}  // namespace plumb::estimation

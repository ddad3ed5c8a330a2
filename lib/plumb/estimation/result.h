// plumb/estimation/result.h — what one solve of the backend returns: the calibration and how
// the fit went, apart (SPEC sections 3 and 6). Text for a terminal is made in plumb/report
// (report/summary.h), JSON in report/json_report.h.
#pragma once

#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"

namespace plumb::estimation {

struct CalibrationResult {
  Calibration calibration;  ///< what the calibration is
  FitReport fit;            ///< how the fit went
};

}  // namespace plumb::estimation

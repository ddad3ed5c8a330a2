// plumb/estimation/sensitivity.h — how a calibration moves with an assumption the fit makes
// and the data do not estimate: the site it is given (gravity, Earth rate) and the attitudes it
// is told (a level, x-north hold), for sensitivity studies (plumb/study).
//
// At the solution theta (every free unknown: model, attitudes, bias-wander states), the
// normal equations J^T r = 0 hold; moving the assumption p moves the residuals r by dr/dp with
// theta fixed, and the solution by the implicit-function theorem (Gauss-Newton: the residuals'
// second derivatives left out, as the fit leaves them out):
//
//   d theta / d p = -(J^T J)^-1 J^T dr/dp
//
// J the whitened Jacobian of the fitted problem (the gauge and any unobservable direction's
// pivots held, as in the solve), dr/dp by central differences: the same solution evaluated in
// two problems built with the assumption at p - h and p + h (nothing is refitted). The first
// order prediction of the error an assumption off by dp leaves is (d theta / d p) dp.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/result.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"

namespace plumb::estimation {

/// An assumption moved by -h and +h: the site the fit is given and the segments with the
/// attitudes it is told, at each side.
struct AssumptionChange {
  std::string name;
  double step = 0.0;  ///< h, in the assumption's unit (> 0)
  geo::Site site_minus, site_plus;
  std::vector<StillSegment> segments_minus, segments_plus;
};

struct Sensitivities {
  std::vector<std::string> names;  ///< the calibration's parameters (Calibration::parameters)
  /// d(parameter)/d(assumption): a row per parameter, a column per change (none without
  /// changes); NaN for a
  /// parameter the fit holds (fixed, or a held pivot of an unobservable direction).
  Eigen::MatrixXd d_dp;
};

struct SensitiveCalibration {
  CalibrationResult result;    ///< what Calibrate returns
  Sensitivities sensitivities;  ///< at that very solution
};

/// Calibrate(series, segments, model, site, options), then, on the same solution (one fit),
/// the derivative of every parameter with respect to each change (file comment). Throws what
/// Calibrate throws, and plumb::Error when a change's segments differ from `segments` in
/// anything but attitudes or the normal matrix cannot be factored.
SensitiveCalibration CalibrateWithSensitivities(const ImuSeries& series,
                                                const std::vector<StillSegment>& segments,
                                                const model::Model& model,
                                                const geo::Site& site,
                                                const CalibrationOptions& options,
                                                const std::vector<AssumptionChange>& changes);

/// The sensitivities alone (CalibrateWithSensitivities(...).sensitivities).
Sensitivities AssumptionSensitivity(const ImuSeries& series,
                                    const std::vector<StillSegment>& segments,
                                    const model::Model& model, const geo::Site& site,
                                    const CalibrationOptions& options,
                                    const std::vector<AssumptionChange>& changes);

}  // namespace plumb::estimation

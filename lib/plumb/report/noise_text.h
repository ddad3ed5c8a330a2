// plumb/report/noise_text.h — what `plumb allan` prints and writes, and what `plumb report`
// shows of the sensor's noise: the IEEE Std 952 / 1293 terms of the still data
// (plumb/signal/noise_terms.h) per sensor and axis, with units, tau ranges and whether each is
// resolved or an upper bound, and the Allan deviation points with their intervals.
//
// Units. The value of a term is in the units of the samples (SI: m/s^2, rad/s), and again in a
// datasheet unit:
//   term  accelerometer                              gyroscope
//   Q     m/s                                        rad          (deg)
//   N     m/s^2/sqrt(Hz) = m/s/sqrt(s)  (ug/sqrt(Hz)) rad/s/sqrt(Hz) = rad/sqrt(s) (deg/sqrt(h))
//   B     m/s^2                         (ug)         rad/s        (deg/h)
//   K     m/s^3/sqrt(Hz) = m/s^2/sqrt(s) (ug/sqrt(s)) rad/s^2/sqrt(Hz) = rad/s/sqrt(s)
//                                                                 (deg/h/sqrt(h))
//   R     m/s^3                         (ug/s)       rad/s^2      (deg/h/h)
// with g = 9.80665 m/s^2 (core/units.h). Samples in other units (counts) get the same forms
// built from their unit ("counts/sqrt(Hz)") and no datasheet unit.
//
// StillNoiseJson keys:
//   schema_version (1), method {adev, intervals, edf, terms, resolved}   the methods, in words
//   confidence           two-sided confidence of the ADEV intervals
//   term_confidence      of the resolved test and the upper bounds
//   sample_interval_s, still {segments [{label, begin, end, t_start_s, t_end_s}], samples,
//                             duration_s, longest_s, notes []}
//   accel, gyro (when present): {unit, axes: {x, y, z: {
//       adev [{tau_s, m, adev, lower, upper, edf, noise, terms}],
//       fit {tau_min_s, tau_max_s, points, chi2, dof, iterations, misfit},
//       terms {Q, N, B, K, R: {name, value, unit, resolved, in_model, fitted, chi2_rise,
//                              upper_bound, bound_tau_s, tau_min_s, tau_max_s,
//                              datasheet {value, unit} (SI samples only)}}}}}
// Non-finite numbers are null.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "plumb/core/imu_series.h"
#include "plumb/signal/noise_terms.h"

namespace plumb::report {

/// How a term of one sensor is named and in which units it is shown.
struct NoiseTermLabel {
  std::string name;            ///< e.g. "velocity random walk", "angle random walk"
  std::string unit;            ///< unit of the value for samples in `sample_unit`
  std::string datasheet_unit;  ///< e.g. "deg/sqrt(h)"; empty when the samples are not SI
  double datasheet_scale = 0;  ///< value * scale is in datasheet_unit
};

NoiseTermLabel LabelNoiseTerm(signal::Sensor sensor, signal::NoiseTermKind kind,
                              const std::string& sample_unit);

/// The terminal text: the still data used, the methods in one line each, and per sensor a
/// table of the terms per axis (value, unit, datasheet unit, tau range; "<" marks an upper
/// bound), then each axis's fitted range.
std::string StillNoiseText(const signal::StillNoise& noise);

/// Why a misfit axis resolves nothing, in words (with its chi2 per point).
std::string MisfitWords(const signal::AxisNoise& axis, const signal::StillNoise& noise);

/// The JSON document (keys above). `series` gives the segments' times.
nlohmann::json StillNoiseJson(const signal::StillNoise& noise, const ImuSeries& series);

}  // namespace plumb::report

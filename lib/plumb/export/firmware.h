// plumb/export/firmware.h — plumb's calibration in the form a flight controller can load, and
// what that form loses, measured on the session itself (issue 5 point 5).
//
// plumb's model (SPEC sections 1-2) is forward: y_a = F f_b + b_a + effects, y_g = E omega_b +
// b_g + effects, and its correction is the inverse f_b = F^-1 (y_a - b_a - effects) (solved by
// model::Model::Correct when effects depend on the input). ArduPilot and PX4 both correct each
// axis on its own, after subtracting a temperature polynomial:
//
//   f_fw = S .* (y - o - h(clamp(T, T_min, T_max))),     h(T) = sum_k c_k (T - t0)^k, k = 0..3
//
// (ArduPilot AP_InertialSensor_Backend::_rotate_and_correct_accel / _gyro: temperature
// correction, then `accel -= offset`, then `accel.x *= scale.x` ...; PX4
// sensor_calibration::Accelerometer::Correct: (data - thermal_offset - offset).emult(scale),
// Gyroscope::Correct: data - thermal_offset - offset, no gyro scale; both then rotate by the
// board orientation, which plumb takes as identity.) A DiagonalCorrection is that form; the
// exporters (formats.h) turn it into each firmware's parameters and back.
//
// The diagonal chosen here (BestDiagonal): S = diag(F^-1) (for plumb's upper-triangular F
// this is 1 / diag(F); it is the closest diagonal matrix to F^-1 in the Frobenius norm, and
// exact when F is diagonal), o = b_a; for the gyroscope S = 1 (neither firmware has a gyro
// scale), o = b_g; h = plumb's temperature polynomial when the model has one. The choice does
// not depend on the session's poses, so the error it leaves (Evaluate) is not fitted to them.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/core/types.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"

namespace plumb::exporter {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A bias polynomial in temperature, per axis, in the sensor's output unit (SI):
///   h(T) = c[0] + c[1] (T - t0_c) + c[2] (T - t0_c)^2 + c[3] (T - t0_c)^3.
struct TemperaturePolynomial {
  double t0_c = 25.0;  ///< expansion point, degC (finite)
  /// c[k]: coefficient of (T - t0)^k per axis; unit (output unit)/degC^k.
  std::array<Vec3, 4> c = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};

  /// h(temp_c), output unit.
  Vec3 At(double temp_c) const;
};

/// The same polynomial expanded about `t0_c` instead (exact, by the binomial theorem):
///   c'_j = sum_{k >= j} c_k C(k, j) (t0_new - t0_old)^(k - j).
TemperaturePolynomial Rebase(const TemperaturePolynomial& p, double t0_c);

/// One sensor's per-axis correction, the form both firmwares apply (file comment):
///   out = scale .* (y - offset - h(clamp(T, temp_min_c, temp_max_c))).
struct DiagonalCorrection {
  Vec3 scale = Vec3::Ones();    ///< S, dimensionless (> 0)
  Vec3 offset = Vec3::Zero();   ///< o, output unit (m/s^2 or rad/s)
  bool has_thermal = false;     ///< h is applied
  TemperaturePolynomial thermal;  ///< h, output unit
  double temp_min_c = kNaN;     ///< clamp range of T for h, degC (used when has_thermal)
  double temp_max_c = kNaN;

  /// The corrected output for sensor output `y` at temperature `temp_c` (degC; ignored
  /// without has_thermal).
  Vec3 Apply(const Vec3& y, double temp_c) const;
};

/// Both sensors.
struct FirmwareCorrection {
  DiagonalCorrection accel;
  DiagonalCorrection gyro;
  bool has_gyro = false;
};

/// Temperature range seen in the session, degC; NaN when the session has no temperature.
struct TemperatureRange {
  double min_c = kNaN;
  double max_c = kNaN;
  bool known() const;
};
TemperatureRange SessionTemperatureRange(const ImuSeries& series);

/// plumb's calibration reduced to the firmware form (file comment). Throws plumb::Error when
/// the outputs are not in SI (counts: firmware parameters would be meaningless) or when the
/// model has a temperature term but the session no temperature.
FirmwareCorrection BestDiagonal(const estimation::Calibration& calibration,
                                const TemperatureRange& range);

/// Per-axis error of a correction against plumb's full one over the still segments.
struct AxisErrors {
  int segments = 0;           ///< still segments compared
  Vec3 rms = Vec3::Zero();    ///< RMS over the segments of (firmware - plumb), output unit
  Vec3 max_abs = Vec3::Zero();  ///< largest |firmware - plumb|, output unit
};

/// An effect of plumb's model that the target has no parameter for.
struct DroppedEffect {
  std::string effect;  ///< catalogue name, e.g. "gyro_g_sensitivity"
  std::vector<std::string> names;  ///< its parameters' full names
  std::vector<double> values;      ///< reported values, SI
  std::vector<std::string> units;
  bool seen_at_rest = true;  ///< false: it acts only in motion, the still-segment error omits it
};

/// What a target loses, in numbers, and what it was given.
struct ExportReport {
  std::string target;  ///< "ardupilot", "px4" or "kalibr"
  bool has_gyro = false;
  /// Firmware minus plumb on the session's still segments, per axis: each segment's mean
  /// output corrected both ways (plumb: model::Model::Correct at the segment's time,
  /// temperature and attitude; firmware: DiagonalCorrection::Apply). m/s^2 and rad/s.
  AxisErrors accel_still, gyro_still;
  /// Linear part lost, per unit input: diag(S_a) F - I (error in m/s^2 per m/s^2 of
  /// specific force along each column's axis) and diag(S_g) E - I (rad/s per rad/s).
  Mat3 accel_per_input = Mat3::Zero();
  Mat3 gyro_per_input = Mat3::Zero();
  std::vector<DroppedEffect> dropped;  ///< effects the target cannot carry
  std::vector<Notice> notes;  ///< what else the user must know (codes: export.h)

  /// The report for a terminal, one line each (numbers in SI and in mg, deg/h, ppm).
  std::vector<std::string> Lines() const;
};

/// The error left by `firmware` against plumb's full correction on the session (its still
/// segments as the fit saw them, `still`; temperatures from `series`), and the effects it
/// drops. `target` names it in the report; `keeps_temperature`: the target carries
/// temperature polynomials.
ExportReport Evaluate(const estimation::Calibration& calibration, const ImuSeries& series,
                      const std::vector<estimation::StillSegmentFit>& still,
                      const FirmwareCorrection& firmware, const std::string& target,
                      bool keeps_temperature);

}  // namespace plumb::exporter

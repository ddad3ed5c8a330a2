// plumb/io/ardupilot_params.h — ArduPilot's INS_* accelerometer/gyroscope correction, as the
// parameters of a log state it, and its inverse. Shared by every reader of ArduPilot data
// (DataFlash .bin in ardupilot_session.cc, MAVLink .tlog in mavlink_session.cc).
//
// ArduPilot (AP_InertialSensor) corrects each IMU instance n (0-based) before it logs or sends
// the samples: in the board frame, after the sensor's own rotation and the temperature
// correction,
//   acc_logged = R_ahrs ((acc_board - INS_ACC[n]OFFS) .* INS_ACC[n]SCAL),     m/s^2
//   gyr_logged = R_ahrs (gyr_board - INS_GYR[n]OFFS),                          rad/s
// with R_ahrs the AHRS_ORIENTATION rotation (identity for 0) and the instance suffix "" for
// n = 0, "2" for n = 1, "3" for n = 2 (INS_ACCOFFS_X, INS_ACC2SCAL_Y, INS_GYR3OFFS_Z, ...).
// With AHRS_ORIENTATION = 0 the sensor's own output is recovered as
//   acc_board = acc_logged ./ INS_ACC[n]SCAL + INS_ACC[n]OFFS,
//   gyr_board = gyr_logged + INS_GYR[n]OFFS.
// Not undone (said in the warnings): a non-zero AHRS_ORIENTATION, and the temperature
// calibration when INS_TCALk_ENABLE = 1.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/types.h"

namespace plumb::io {

/// "INS_ACC", "INS_ACC2", "INS_ACC3" for kind "ACC" and instance 0, 1, 2 ("INS_GYR..." for
/// kind "GYR"). instance >= 0.
std::string InsParamPrefix(const std::string& kind, int instance);

/// The INS_* correction of one IMU instance as the parameters state it.
struct InsCorrection {
  std::optional<Vec3> acc_offs_m_s2;  ///< INS_ACC[n]OFFS_X/Y/Z, m/s^2; nullopt if any is absent
  std::optional<Vec3> acc_scal;       ///< INS_ACC[n]SCAL_X/Y/Z, dimensionless (~1); nullopt if absent
  std::optional<Vec3> gyr_offs_rad_s; ///< INS_GYR[n]OFFS_X/Y/Z, rad/s; nullopt if any is absent
  double ahrs_orientation = 0.0;      ///< AHRS_ORIENTATION (ArduPilot rotation enum), 0 = none

  /// The accelerometer part can be undone: offsets and non-zero scales present, no rotation.
  bool AccUndoable() const;
  /// The gyroscope part can be undone: offsets present, no rotation.
  bool GyrUndoable() const;
};

/// Reads the correction of IMU `instance` (0-based, >= 0) from firmware parameters
/// (name -> value, e.g. DataFlash PARM or MAVLink PARAM_VALUE).
InsCorrection InsCorrectionFromParams(const std::map<std::string, double>& params, int instance);

/// What ArduPilot applied to instance `instance`, in ImuStreamInfo::applied's words:
/// "INS_ACCOFFS/INS_ACCSCAL, INS_GYROFFS" (instance 0), "INS_ACC2OFFS/INS_ACC2SCAL, INS_GYR2OFFS"...
std::string InsAppliedDescription(int instance);

/// Undoes the correction of `instance` on `series` in place (acc in m/s^2, gyr in rad/s, FRD),
/// with the equations of the file comment, when `undo` is true and AHRS_ORIENTATION is 0.
/// Returns one line per decision, each starting with `who` (e.g. "IMU instance 0: "), saying
/// which triad was reconstructed with which values and which was taken as logged, plus a line
/// per INS_TCALk_ENABLE = 1.
std::vector<std::string> UndoInsCorrection(const std::map<std::string, double>& params,
                                           int instance, bool undo, const std::string& who,
                                           ImuSeries* series);

}  // namespace plumb::io

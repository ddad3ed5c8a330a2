// plumb/io/ardupilot/ardupilot_correction.h — what ArduPilot applies to an IMU sample before
// logging it, read from the log's own parameters, and how to undo it.
//
// AP_InertialSensor_Backend::_rotate_and_correct_accel / _gyro (ArduPilot 4.x; 3.x the same
// without the temperature step), for instance k (0-based), in this order:
//   a_s  = R_sensor a_chip                              (driver's fixed chip -> board rotation)
//   a_t  = a_s - P_a(clamp(T) - 35) + P_a(clamp(T_cal,a) - 35)   (INS_TCAL{k+1}_ENABLE = 1)
//   a_c  = (a_t - INS_ACC{k}OFFS) .* INS_ACC{k}SCAL
//   a_log = R_board a_c                                  (R_board from AHRS_ORIENTATION)
//   g_log = R_board (g_s - P_g(clamp(T) - 35) + P_g(clamp(T_cal,g) - 35) - INS_GYR{k}OFFS)
// with P(d) = (c1 + (c2 + c3 d) d) d * 1e-6 per axis (c_i = INS_TCAL{k+1}_ACC{i}_X/Y/Z or
// _GYR{i}_X/Y/Z, stored scaled by 1e6), clamp to [INS_TCAL{k+1}_TMIN, _TMAX] degC, T the
// sensor temperature (the IMU message's T), T_cal = INS_ACC{k+1}_CALTEMP / INS_GYR{k+1}_CALTEMP
// (default -300, i.e. clamped to TMIN) (AP_InertialSensor_tempcal.cpp, TEMP_REFERENCE 35 degC,
// SCALE_FACTOR 1e6; ENABLE 0 disabled, 1 enabled, 2 learning = nothing applied).
// {k} is "" for k = 0, "2", "3" for k = 1, 2 (INS_ACCOFFS, INS_ACC2OFFS, ...).
//
// Undoing it gives a_s and g_s: the sensor's own output in the board frame (the driver's fixed
// rotation R_sensor stays: it is a property of the board layout, not a calibration).
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/core/types.h"

namespace plumb::io {

/// ArduPilot's Rotation enum (libraries/AP_Math/rotations.h) as a matrix R with
/// v_rotated = R v (Vector3::rotate): R = Rz(yaw) Ry(pitch) Rx(roll) of the entry's Euler
/// angles. Values 0..43 (ROTATION_NONE .. ROTATION_ROLL_315; 38 is roll 90, pitch 68.8,
/// yaw 293.3 and 41 is pitch 7, as ArduPilot defines them). nullopt for anything else,
/// including the custom rotations 100..102 (their matrix is in CUST_ROT* parameters).
std::optional<Mat3> ArdupilotRotation(int rotation);

/// ArduPilot's name of a rotation without the "ROTATION_" prefix ("ROLL_180"), "CUSTOM" for
/// 100..102, "unknown" otherwise.
std::string ArdupilotRotationName(int rotation);

/// INS_TCALn temperature calibration of one IMU instance.
struct ArdupilotTempCal {
  double t_min_degc = 0.0;   ///< INS_TCALn_TMIN, degC, temperatures are clamped to it
  double t_max_degc = 70.0;  ///< INS_TCALn_TMAX, degC
  /// Accelerometer coefficients c1, c2, c3 per axis (INS_TCALn_ACC1..3_X/Y/Z), as stored:
  /// P(d) = (c1 + (c2 + c3 d) d) d * 1e-6 m/s^2 for d in degC.
  std::array<Vec3, 3> acc_coeff{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  /// Gyroscope coefficients (INS_TCALn_GYR1..3_X/Y/Z), same form, rad/s.
  std::array<Vec3, 3> gyr_coeff{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  double acc_cal_temp_degc = -300.0;  ///< INS_ACCn_CALTEMP, degC (-300: never set)
  double gyr_cal_temp_degc = -300.0;  ///< INS_GYRn_CALTEMP, degC
};

/// The temperature polynomial P(d) = (c1 + (c2 + c3 d) d) d * 1e-6, d = temperature - 35 degC.
Vec3 ArdupilotTcalPolynomial(const std::array<Vec3, 3>& coeff, double d_degc);

/// What ArduPilot SUBTRACTED from the sensor output for temperature `temp_c` (degC):
/// P(clamp(temp_c) - 35) - P(clamp(cal_temp_c) - 35).
Vec3 ArdupilotTcalCorrection(const ArdupilotTempCal& tcal, const std::array<Vec3, 3>& coeff,
                             double temp_c, double cal_temp_c);

/// The correction ArduPilot applied to IMU instance `instance`, as the log's parameters say.
struct ArdupilotCorrection {
  int instance = 0;                 ///< 0-based
  std::optional<Vec3> acc_offset;   ///< INS_ACC{k}OFFS_X/Y/Z, m/s^2
  std::optional<Vec3> acc_scale;    ///< INS_ACC{k}SCAL_X/Y/Z, 1 (all non-zero when present)
  std::optional<Vec3> gyr_offset;   ///< INS_GYR{k}OFFS_X/Y/Z, rad/s
  int orientation = 0;              ///< AHRS_ORIENTATION (0 when absent)
  std::optional<Mat3> R_board;      ///< its rotation; nullopt when unknown or custom
  int tcal_enable = 0;              ///< INS_TCAL{k+1}_ENABLE (0 when absent)
  /// The calibration when tcal_enable == 1 and every INS_TCAL{k+1}_* parameter is present.
  std::optional<ArdupilotTempCal> tcal;

  /// Short description of what was applied, for ImuStreamInfo::applied, e.g.
  /// "INS_ACCOFFS/INS_ACCSCAL, INS_GYROFFS, AHRS_ORIENTATION=8 (ROLL_180), INS_TCAL1".
  std::string Describe(bool accel, bool gyro) const;
  /// True when every applied step can be undone for a stream with these contents.
  bool Undoable(bool accel, bool gyro, bool temperature) const;
};

/// Reads the correction of IMU `instance` (0-based) from a log's parameters.
ArdupilotCorrection ArdupilotCorrectionFor(const std::map<std::string, double>& params,
                                           int instance);

/// Undoes `c` on `series` in place when `undo` (acc m/s^2, gyr rad/s, FRD; temperature from
/// series->temp_c), in the order the inverse needs: board = R_board^T logged, then
/// acc ./ SCAL + OFFS and gyr + OFFS, then the temperature calibration added back. Returns one
/// line per decision, each starting with `who` (e.g. "IMU of IMU instance 0: "), naming the
/// parameters and values used and what was left as logged. `left`, when given, receives one
/// line per part of the correction that stays in the samples (not undone, or its parameters
/// missing or not finite); see Session::firmware_left. Shared by every reader of ArduPilot
/// data (DataFlash .bin/.log, MAVLink .tlog).
std::vector<Notice> UndoArdupilotCorrection(const ArdupilotCorrection& c, bool undo,
                                            const std::string& who, ImuSeries* series,
                                            std::vector<std::string>* left = nullptr);

}  // namespace plumb::io

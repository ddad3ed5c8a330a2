// plumb/export/formats.h — a FirmwareCorrection (firmware.h) as ArduPilot and PX4 parameters,
// and back; the parameter files both ground stations load.
//
// ArduPilot (libraries/AP_InertialSensor, AP_InertialSensor_Backend.cpp and
// AP_InertialSensor_tempcal.cpp): for IMU instance i (0-based; names use i + 1 or none),
//   acc = (acc_sensor - tcal(T) - INS_ACC{,2,3}OFFS) .* INS_ACC{,2,3}SCAL,
//   gyr =  gyr_sensor - tcal(T) - INS_GYR{,2,3}OFFS,
//   tcal(T) = p(clamp(T) - 35) - p(clamp(CALTEMP) - 35)   when INS_TCAL{i+1}_ENABLE = 1,
//   p(d) = (ACC1 + (ACC2 + ACC3 d) d) d * 1e-6        (TCal::polynomial_eval, SCALE_FACTOR 1e6,
//                                                      TEMP_REFERENCE 35 degC, no constant),
//   clamp to [INS_TCAL{i+1}_TMIN, _TMAX]; CALTEMP is INS_ACC{i+1}_CALTEMP / INS_GYR{i+1}_CALTEMP,
//   the temperature at which the offsets hold. plumb's h(T) is re-expanded about 35 degC
//   (Rebase), CALTEMP is plumb's reference temperature clamped to the range, and
//   OFFS = o + h(CALTEMP), so that OFFS + tcal(T) = o + h(clamp(T)) exactly.
// PX4 (src/lib/sensor_calibration Accelerometer/Gyroscope::Correct and
// src/modules/temperature_compensation TemperatureCompensation::calc_thermal_offsets_3D):
//   acc = (acc_sensor - thermal - CAL_ACC{i}_{X,Y,Z}OFF) .* CAL_ACC{i}_{X,Y,Z}SCALE,
//   gyr =  gyr_sensor - thermal - CAL_GYRO{i}_{X,Y,Z}OFF,
//   thermal = X0 + X1 d + X2 d^2 + X3 d^3, d = clamp(T, TMIN, TMAX) - TREF, per axis
//   (TC_A{i}_X{k}_{0,1,2}, TC_A{i}_TREF/TMIN/TMAX, enabled by TC_A_ENABLE; TC_G... likewise),
//   m/s^2 and rad/s. plumb's h maps directly: TREF = t0, X_k = c_k.
// Both firmwares match a calibration to a device by an ID parameter (INS_ACC_ID, CAL_ACC0_ID,
// TC_A0_ID) that plumb cannot know; the files leave them out: keep the vehicle's.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "plumb/export/firmware.h"

namespace plumb::exporter {

/// One firmware parameter.
struct Parameter {
  std::string name;     ///< e.g. "INS_ACCOFFS_X"
  double value = 0;     ///< in the firmware's unit (SI, or x1e6 for INS_TCAL coefficients)
  bool integer = false; ///< an integer parameter (enable flags); else float
};

/// The parameters of one target, in the order written.
struct ParameterSet {
  std::string target;  ///< "ardupilot" or "px4"
  int imu = 0;         ///< IMU instance, 0-based
  std::vector<Parameter> parameters;
  std::vector<Notice> notes;  ///< written as comments at the top of the file (codes: export.h)
  int system_id = 1;  ///< the vehicle's MAVLink system id (QGroundControl's first column)

  /// Name -> value.
  std::map<std::string, double> Values() const;
};

/// ArduPilot parameters for IMU instance `imu` (0..2). Throws plumb::Error for another
/// instance. Temperature polynomials are written (INS_TCALn_*, INS_ACCn/GYRn_CALTEMP) only when
/// `fw` has them; with one sensor's only, the other's coefficients are zero.
ParameterSet ArdupilotParameters(const FirmwareCorrection& fw, int imu);
/// The correction ArduPilot applies with these parameters (the inverse of the above, from the
/// values alone). Missing OFFS/SCAL/GYROFFS parameters throw plumb::Error naming them; missing
/// temperature parameters mean no temperature correction.
FirmwareCorrection ArdupilotCorrection(const std::map<std::string, double>& values, int imu);

/// PX4's calibration slots (0..3) of one IMU's sensors. The firmware finds a sensor's
/// calibration by its device id (PX4 src/lib/sensor_calibration/Utilities.cpp,
/// FindCurrentCalibrationIndex: the n whose CAL_ACCn_ID is the device's; the thermal
/// compensation likewise by TC_An_ID), so the accelerometer's slot, the gyroscope's and their
/// thermal ones need not be the IMU's instance, nor each other.
struct Px4Slots {
  int acc = 0;      ///< CAL_ACC{acc}_*
  int gyro = 0;     ///< CAL_GYRO{gyro}_*
  int tc_acc = 0;   ///< TC_A{tc_acc}_*
  int tc_gyro = 0;  ///< TC_G{tc_gyro}_*
  /// Every slot the instance's (what a log without device ids leaves).
  static Px4Slots Same(int instance) { return {instance, instance, instance, instance}; }
};

/// PX4 parameters in `slots` (each 0..3; CAL_ACC{acc}_*, CAL_GYRO{gyro}_*, TC_A{tc_acc}_*,
/// TC_G{tc_gyro}_*). Throws plumb::Error for a slot outside 0..3.
ParameterSet Px4Parameters(const FirmwareCorrection& fw, const Px4Slots& slots);
FirmwareCorrection Px4Correction(const std::map<std::string, double>& values,
                                 const Px4Slots& slots);

/// Mission Planner's .param text: `#` comment lines (the notes), then `NAME,VALUE` per line,
/// values with 9 significant digits (a float32 round-trips). MAVProxy (pymavlink mavparm.load)
/// reads the same file: it skips `#` lines and takes ',' as a separator.
std::string ArdupilotParamFile(const ParameterSet& set);
/// Reads `NAME,VALUE` or `NAME VALUE` lines (blank and `#` lines skipped). Throws
/// plumb::InputError(path, "line N", ...) for a malformed line or a non-finite value.
std::map<std::string, double> ReadArdupilotParamFile(const std::string& text,
                                                     const std::string& path);

/// QGroundControl's .params text: `#` comment lines, then per parameter
/// `SYSID<TAB>1<TAB>NAME<TAB>VALUE<TAB>TYPE` (the vehicle's system id, set.system_id, which
/// QGroundControl checks; component id; MAV_PARAM_TYPE: 9 for REAL32, 6 for INT32).
std::string Px4ParamsFile(const ParameterSet& set);
/// Reads QGroundControl's layout; throws plumb::InputError naming the line when malformed.
std::map<std::string, double> ReadPx4ParamsFile(const std::string& text, const std::string& path);

}  // namespace plumb::exporter

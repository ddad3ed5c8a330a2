// plumb/io/px4/px4_correction.h — what PX4 applies to an accelerometer or gyroscope sample
// before logging it, read from the log's parameters, and how to undo it. Pure functions of the
// parameters and the samples; px4_session.h finds, in the ULog topics, which sensor a stream
// comes from (its device id) and its temperature.
//
// PX4's correction (sensor_calibration, PX4 v1.12+; the 2016 sensors module did the same
// with the offset/scale in the driver and the board rotation after it), for a sensor m:
//   logged = R ((m - thermal(T) - CAL_ACCn_{X,Y,Z}OFF) .* CAL_ACCn_{X,Y,Z}SCALE)
// (gyro: CAL_GYROn_*, scale 1 when the log has no CAL_GYROn_*SCALE), with
//  * R the board rotation R_board = Euler(SENS_BOARD_X_OFF, SENS_BOARD_Y_OFF,
//    SENS_BOARD_Z_OFF degrees, roll-pitch-yaw, R = Rz Ry Rx) * Rot(SENS_BOARD_ROT) for an
//    internal sensor, or Rot(CAL_ACCn_ROT) when that parameter is >= 0 (external sensor).
//    Rot(k) is PX4's rotation enum (Px4RotationEuler: 0 none, 1..7 yaw k*45 deg, 8..15 roll
//    180 with yaw, 12 pitch 180, 16..23 roll 90/270 with yaw, 24/25 pitch 90/270);
//  * n the CAL_ACCn (n = 0..3) whose CAL_ACCn_ID equals the sensor's device id;
//  * thermal(T) (TemperatureCompensation, applied when TC_A_ENABLE / TC_G_ENABLE = 1) from
//    the TC_An / TC_Gn set whose TC_*n_ID equals the device id: with T the sensor temperature
//    (degC) clamped to [TC_An_TMIN, TC_An_TMAX] and dT = T - TC_An_TREF,
//    thermal_i = X0_i + X1_i dT + X2_i dT^2 + X3_i dT^3 (TC_An_Xk_i).
// Undone:  m = R^T logged ./ SCALE + OFF + thermal(T). Units: m/s^2 (accelerometer), rad/s
// (gyroscope), degC, s.
#pragma once

#include <array>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/core/types.h"

namespace plumb::io {

/// PX4's rotation enum as (roll, pitch, yaw) degrees, for the integers 0..25; nullopt
/// otherwise (other values, fractions, NaN).
std::optional<Vec3> Px4RotationEuler(double value);

/// R = Rz(yaw) Ry(pitch) Rx(roll), angles (roll, pitch, yaw) in degrees.
Mat3 Px4EulerRotation(const Vec3& rpy_deg);

/// What PX4 applied to one sensor (accelerometer or gyroscope) of a calibrated stream.
struct Px4Calibration {
  std::string prefix;          ///< e.g. "CAL_ACC0", "CAL_GYRO1"
  Vec3 offset = Vec3::Zero();  ///< CAL_*n_{X,Y,Z}OFF, sensor units (m/s^2 or rad/s)
  Vec3 scale = Vec3::Ones();   ///< CAL_*n_{X,Y,Z}SCALE (1 when absent), finite, non-zero
  Mat3 rotation = Mat3::Identity();  ///< R of the file comment
  std::string rotation_text;   ///< how R was obtained (parameters and values)
  double device_id = 0.0;      ///< the sensor's device id
  std::string id_source;       ///< where the device id came from
};

/// The calibration PX4 applied to the sensor of `kind` ("ACC" or "GYRO") with `device_id`
/// (found as `id_source` says), from the log's initial parameters; nullopt with `*why` set
/// when the device id is unknown, no CAL_{kind}n_ID (n = 0..3) equals it, an offset is
/// missing, a scale or offset is zero or not finite, or a rotation is not one PX4 defines.
std::optional<Px4Calibration> Px4CalibrationFor(const std::map<std::string, double>& params,
                                                const std::string& kind,
                                                std::optional<double> device_id,
                                                const std::string& id_source, std::string* why);

/// PX4's thermal offset of one sensor (TemperatureCompensation): with T clamped to
/// [t_min_c, t_max_c] and dT = T - t_ref_c, offset_i = x[0]_i + x[1]_i dT + x[2]_i dT^2 +
/// x[3]_i dT^3 (sensor units: m/s^2 or rad/s).
struct Px4Thermal {
  std::string prefix;        ///< e.g. "TC_A1"
  double t_ref_c = 0.0;      ///< TC_An_TREF, degC
  double t_min_c = 0.0;      ///< TC_An_TMIN, degC
  double t_max_c = 0.0;      ///< TC_An_TMAX, degC
  std::array<Vec3, 4> x;     ///< TC_An_X0_* .. TC_An_X3_*, per axis

  /// The offset at sensor temperature `temp_c`, degC.
  Vec3 Offset(double temp_c) const;
};

/// The TC_An / TC_Gn (kind "A" or "G", n = 0..3) coefficients whose TC_*n_ID equals
/// `device_id`; nullopt with `*why` set when there is none or one of its parameters is missing.
std::optional<Px4Thermal> Px4ThermalFor(const std::map<std::string, double>& params,
                                        const std::string& kind, double device_id,
                                        std::string* why);

/// A sensor temperature over time: temp_c (degC) at t_s (s), sorted by time.
struct Px4TemperatureTrack {
  std::vector<double> t_s;
  std::vector<double> temp_c;
  std::string source;  ///< topic(s) it came from, for the warnings

  /// The latest temperature at or before t (the first one before the track starts).
  /// Precondition: not empty.
  double At(double t) const;
};

/// m = R^T logged ./ scale + offset (+ the thermal offset at the temperature of each sample's
/// time t_s[k], when both `thermal` and `temp` are given), in place on `v` (one per t_s).
void UndoPx4Calibration(const Px4Calibration& c, const std::optional<Px4Thermal>& thermal,
                        const std::optional<Px4TemperatureTrack>& temp,
                        const std::vector<double>& t_s, std::vector<Vec3f>* v);

/// The sensors behind a calibrated stream, as the log identifies them.
struct Px4Sensors {
  std::optional<double> acc_id;  ///< accelerometer device id; nullopt when the log does not say
  std::string acc_id_source;     ///< where acc_id came from
  std::optional<double> gyr_id;  ///< gyroscope device id
  std::string gyr_id_source;
  /// The logged temperature of a sensor (accelerometer when the flag is true) with a device
  /// id; nullopt when the log holds none. Called only when thermal compensation is enabled.
  std::function<std::optional<Px4TemperatureTrack>(bool accel, double device_id)> temperature;
};

/// What PX4 applied to a calibrated stream, for ImuStreamInfo::applied, e.g.
/// "CAL_ACC0_*, CAL_GYRO0_*, board rotation, TC_A* thermal".
std::string Px4AppliedText(const std::map<std::string, double>& params,
                           const Px4Sensors& sensors);

/// True when the calibration of the accelerometer (and of the gyroscope, when `gyro`) is in
/// the parameters.
bool Px4Undoable(const std::map<std::string, double>& params, const Px4Sensors& sensors,
                 bool gyro);

/// Undoes PX4's correction on `series` in place (accelerometer, and gyroscope when the series
/// has one). Appends to `warnings` one line per sensor, starting with `who`, naming the
/// parameters and values used or why the samples were taken as logged, and to `left` one line
/// per correction left in the samples (see Session::firmware_left).
void UndoPx4Correction(const std::map<std::string, double>& params, const Px4Sensors& sensors,
                       const std::string& who, ImuSeries* series,
                       std::vector<Notice>* warnings, std::vector<std::string>* left);

}  // namespace plumb::io

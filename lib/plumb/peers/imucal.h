// plumb/peers/imucal.h — imucal's Ferraris calibration JSON in plumb's forward form.
//
// imucal (mad-lab-fau/imucal, MIT; imucal/ferraris_calibration_info.py, FerrarisCalibrationInfo
// ._calibrate_acc and ._calibrate_gyr) applies its calibration in the inverse direction:
//
//   acc_cal = R_a^-1 K_a^-1 (acc - b_a)
//   gyr_cal = R_g^-1 K_g^-1 (gyr - K_ga acc_cal - b_g)
//
// so its forward model is  acc = K_a R_a acc_cal + b_a,  gyr = K_g R_g gyr_cal + K_ga acc_cal +
// b_g. acc and gyr are in the file's `from_acc_unit` / `from_gyr_unit`, acc_cal and gyr_cal in
// its `acc_unit` (m/s^2) / `gyr_unit` (deg/s). imucal's FerrarisCalibration docstring: in the
// `x_p` pose "x-acc measures +1g", i.e. acc_cal is specific force, like plumb's f_b. Its frame
// is the one its six poses define; plumb's is the accelerometer-defined frame (F upper
// triangular), reached by the rotation R_peer_b of UpperTriangularFrame:
//
//   F = s_a K_a R_a R_peer_b,  b_a = S_a b_a,
//   E = s_g K_g R_g R_peer_b,  G = S_g / C_a K_ga R_peer_b,  b_g = S_g b_g,
//
// with S the SI value of one output unit (deg/s -> pi/180; plumb turns recognised units into
// SI when it reads the data), C the SI value of one calibrated unit, s = S / C. An output unit
// plumb does not know (imucal's "a.u.") is kept as it is (S = 1), with a note.
//
// The frame: against a plumb result whose F is full and determined (known faces define the
// frame, as the paper-benchmark method has them), the comparison is made in the frame of the
// poses, imucal's own: R_peer_b = I (ImucalFrame::kPoses). Rotating it into the accelerometer-
// defined frame there would set two answers in different frames side by side.
//
// The sign: imucal takes its turns as clockwise (expected_angle -360: "x-gyro shows negative
// values"), a right-handed rate, like plumb's omega_b; K_g is positive by construction, so a
// gyroscope whose output runs against the rate, or turns made the other way than
// expected_angle says, show as a negative diagonal of R_g. That is kept as imucal wrote it;
// peers::Compare declines to compare matrices whose diagonals differ in sign from plumb's and
// says why.
#pragma once

#include <string>

#include "plumb/core/types.h"
#include "plumb/peers/forward_calibration.h"

namespace plumb::peers {

/// The fields of imucal's FerrarisCalibrationInfo (also Turntable) JSON, as written.
struct ImucalFerraris {
  std::string cal_type;       ///< "Ferraris" or "Turntable"
  std::string acc_unit;       ///< unit of the calibrated accelerometer, e.g. "m/s^2"
  std::string gyr_unit;       ///< unit of the calibrated gyroscope, e.g. "deg/s"
  std::string from_acc_unit;  ///< unit of the raw accelerometer data, e.g. "m/s^2", "a.u."
  std::string from_gyr_unit;  ///< unit of the raw gyroscope data, e.g. "deg/s", "a.u."
  Mat3 K_a = Mat3::Identity();   ///< accelerometer scale (diagonal), from units per acc_unit
  Mat3 R_a = Mat3::Identity();   ///< accelerometer axes (rows near unit vectors)
  Vec3 b_a = Vec3::Zero();       ///< accelerometer bias, from_acc_unit
  Mat3 K_g = Mat3::Identity();   ///< gyroscope scale (diagonal), from units per gyr_unit
  Mat3 R_g = Mat3::Identity();   ///< gyroscope axes
  Mat3 K_ga = Mat3::Zero();      ///< gyroscope output per calibrated acceleration
  Vec3 b_g = Vec3::Zero();       ///< gyroscope bias, from_gyr_unit
};

/// Reads imucal's JSON. Throws plumb::InputError naming the file and the key when the JSON is
/// invalid (with its byte offset), a key is missing, or a matrix is not 3 rows of 3 finite
/// numbers (a vector not 3 finite numbers).
ImucalFerraris ReadImucalJson(const std::string& path);

/// SI value of one unit: "m/s^2" 1, "g" 9.80665 (units::kStandardGravity), "rad/s" 1,
/// "deg/s" pi/180; 0 when unknown.
double SiPerUnit(const std::string& unit);

/// The frame imucal's answer is expressed in (see the file comment).
enum class ImucalFrame {
  kAccelerometerDefined,  ///< plumb's usual frame: F upper triangular (R_peer_b from an RQ)
  kPoses,                 ///< imucal's own frame, that of its six poses (R_peer_b = I)
};

/// imucal's answer in plumb's forward form (see the file comment); `source` names the file.
/// Throws plumb::Error when K_a R_a is singular or a reflection.
ForwardCalibration ImucalToForward(const ImucalFerraris& cal, const std::string& source,
                                   ImucalFrame frame = ImucalFrame::kAccelerometerDefined);

}  // namespace plumb::peers

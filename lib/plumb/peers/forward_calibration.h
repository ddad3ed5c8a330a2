// plumb/peers/forward_calibration.h — another tool's calibration, converted into plumb's
// forward form (SPEC section 1) so that it can be set beside plumb's own answer.
//
//   y_a = F f_b + b_a
//   y_g = E omega_b + G f_b + b_g        (G only when the peer estimates it)
//
// y_a, y_g are the sensor outputs in the units of the data plumb was given: raw counts for
// imu_tk's demo data (plumb reads counts as they are), SI for data in m/s^2 and deg/s (plumb
// turns deg/s into rad/s). f_b is specific force in m/s^2, omega_b the angular rate in rad/s,
// both in the accelerometer-defined body frame in which F is upper triangular.
#pragma once

#include <string>
#include <vector>

#include "plumb/core/notice.h"
#include "plumb/core/types.h"

namespace plumb::peers {

struct ForwardCalibration {
  std::string peer;                  ///< the tool: "imu_tk" or "imucal"
  std::vector<std::string> sources;  ///< the files read
  /// F: accelerometer output units per m/s^2, upper triangular.
  Mat3 accel_matrix = Mat3::Identity();
  /// b_a: accelerometer output units.
  Vec3 accel_bias = Vec3::Zero();
  bool has_gyro = false;
  /// E: gyroscope output units per rad/s (full 3x3).
  Mat3 gyro_matrix = Mat3::Identity();
  /// b_g: gyroscope output units.
  Vec3 gyro_bias = Vec3::Zero();
  bool has_g_sensitivity = false;
  /// G: gyroscope output units per m/s^2 (rad/s per m/s^2 for SI data), row = gyro axis.
  Mat3 g_sensitivity = Mat3::Zero();
  /// Rotation from plumb's body frame into the frame the peer calibrated to (f_peer =
  /// R_peer_b f_b); identity when the peer already uses the accelerometer-defined frame.
  Mat3 R_peer_b = Mat3::Identity();
  /// Units of the outputs y_a, y_g after the conversion: "m/s^2" / "rad/s" when the peer's
  /// were converted to SI, the peer's own unit when kept ("a.u."), "" when the peer does not
  /// say (imu_tk: the data's as given).
  std::string acc_unit, gyr_unit;
  /// How the peer's numbers were converted, and anything a reader must know about them (codes:
  /// peer_form, the peer's equation and plumb's forward form of it; peer_frame, the frame
  /// compared in; peer_convention, what the peer assumes; unit_kept, an output unit plumb
  /// does not convert).
  std::vector<Notice> notes;
};

/// One named forward parameter, named as in plumb's JSON (`accel.matrix.xy`, `gyro.bias.z`,
/// `gyro_g_sensitivity.G.xy`).
struct NamedValue {
  std::string name;
  double value = 0.0;
};

/// Every forward parameter of `c` in plumb's order: accel.matrix (all 9 entries, row-major),
/// accel.bias, then, with a gyroscope, gyro.matrix (9), gyro.bias, and gyro_g_sensitivity.G
/// (9) when the peer has it.
std::vector<NamedValue> ForwardParameters(const ForwardCalibration& c);

/// Turns a full accelerometer matrix M (y = M f_peer + b, f_peer in the peer's frame) into
/// plumb's upper-triangular F = M R_peer_b with a proper rotation R_peer_b and a positive
/// diagonal (an RQ decomposition). Throws plumb::Error when M is singular or a reflection.
Mat3 UpperTriangularFrame(const Mat3& M, Mat3& R_peer_b);

}  // namespace plumb::peers

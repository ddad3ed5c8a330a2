// accel_size_effect — the three accelerometers sit at slightly different points (SPEC
// section 4). The body origin is the x accelerometer; r_y and r_z are the lever arms of the y
// and z accelerometers from it, in the body frame. Under rotation each senses the tangential
// and centripetal acceleration of its own point:
//
//   y_a,i += e_i^T (alpha_b x r_i + omega_b x (omega_b x r_i)),   i = y, z
//
// (alpha_b: SensorInput::alpha_b, omega_b: SensorInput::omega_b; the x accelerometer has no
// term.)
//
// Parameter block (6 values, zero = all three at one point), in m:
//   [0..2] r_y.x, r_y.y, r_y.z   lever arm of the y accelerometer
//   [3..5] r_z.x, r_z.y, r_z.z   lever arm of the z accelerometer
// Residual signature: accelerometer residual during rotation that follows omega^2 and the
// angular acceleration; nothing when still.
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace accel_size_effect {

/// The catalogue entry of accel_size_effect (parameters, units, typical sizes); throws
/// plumb::Error on an option it does not take.
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty()) throw Error("accel_size_effect takes no option (got '" + option + "')");
  EffectInfo info;
  info.name = "accel_size_effect";
  info.prefix = info.name;
  info.sensor = Sensor::kAccel;
  info.term = "y_a,i += e_i^T (alpha_b x r_i + omega_b x (omega_b x r_i)), i = y, z";
  // Proof masses of a single-package MEMS triad sit a few millimetres apart.
  info.parameters = AxisParameters("r_y", "m", 2e-3);
  auto r_z = AxisParameters("r_z", "m", 2e-3);
  info.parameters.insert(info.parameters.end(), r_z.begin(), r_z.end());
  info.excitation.rotation = true;
  info.excitation.angular_acceleration = true;
  return info;
}

}  // namespace accel_size_effect

class AccelSizeEffect : public EffectBase<AccelSizeEffect> {
 public:
  explicit AccelSizeEffect(const std::string& option) : EffectBase(accel_size_effect::Describe(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    Eigen::Map<const Vec3T<T>> r_y(theta);
    Eigen::Map<const Vec3T<T>> r_z(theta + 3);
    out.acc(1) += PointAcceleration(in, Vec3T<T>(r_y))(1);
    out.acc(2) += PointAcceleration(in, Vec3T<T>(r_z))(2);
  }

 private:
  /// Acceleration of a point at lever arm r relative to the body origin, body frame.
  template <typename T>
  static Vec3T<T> PointAcceleration(const SensorInput<T>& in, const Vec3T<T>& r) {
    return in.alpha_b.cross(r) + in.omega_b.cross(in.omega_b.cross(r));
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(accel_size_effect, ::plumb::model::AccelSizeEffect)

// gyro_scale_nonlinearity — a quadratic term in each gyroscope's own input (SPEC section 4):
//
//   y_g,i += k_i (E omega_b)_i^2,   i = x, y, z
//
// where E is the gyroscope matrix written by gyro_linear (SensorOutput::E).
//
// Parameter block (3 values, zero = linear): k.x, k.y, k.z in 1/(rad/s).
// Residual signature: the motion residual grows with the square of the rate (turns in
// opposite directions disagree in the same direction).
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace gyro_scale_nonlinearity {

/// The catalogue entry of gyro_scale_nonlinearity (parameters, units, typical sizes); throws
/// plumb::Error on an option it does not take.
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty()) {
    throw Error("gyro_scale_nonlinearity takes no option (got '" + option + "')");
  }
  EffectInfo info;
  info.name = "gyro_scale_nonlinearity";
  info.prefix = info.name;
  info.sensor = Sensor::kGyro;
  info.term = "y_g,i += k_i (E omega_b)_i^2";
  // ~0.1 % of reading at 1 rad/s.
  info.parameters = AxisParameters("k", "1/(rad/s)", 1e-3);
  info.excitation.rotation = true;
  return info;
}

}  // namespace gyro_scale_nonlinearity

class GyroScaleNonlinearity : public EffectBase<GyroScaleNonlinearity> {
 public:
  explicit GyroScaleNonlinearity(const std::string& option) : EffectBase(gyro_scale_nonlinearity::Describe(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    Eigen::Map<const Vec3T<T>> k(theta);
    const Vec3T<T> sensed = out.E * in.omega_b;
    out.gyr += k.cwiseProduct(sensed.cwiseProduct(sensed));
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(gyro_scale_nonlinearity, ::plumb::model::GyroScaleNonlinearity)

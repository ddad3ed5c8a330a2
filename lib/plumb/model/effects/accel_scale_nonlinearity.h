// accel_scale_nonlinearity — a quadratic term in each accelerometer's own input (SPEC
// section 4):
//
//   y_a,i += k_i (F f_b)_i^2,   i = x, y, z
//
// where F is the accelerometer matrix written by accel_linear (SensorOutput::F), so the term
// acts on what axis i senses through its own scale and misalignment.
//
// Parameter block (3 values, zero = linear): k.x, k.y, k.z in 1/(m/s^2).
// Residual signature: accelerometer residual that grows with the square of the same-axis input
// (the still poses with that axis up and down disagree in the same direction).
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace accel_scale_nonlinearity {

/// The catalogue entry of accel_scale_nonlinearity (parameters, units, typical sizes); throws
/// plumb::Error on an option it does not take.
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty()) {
    throw Error("accel_scale_nonlinearity takes no option (got '" + option + "')");
  }
  EffectInfo info;
  info.name = "accel_scale_nonlinearity";
  info.prefix = info.name;
  info.sensor = Sensor::kAccel;
  info.term = "y_a,i += k_i (F f_b)_i^2";
  // ~0.1 % of reading at 1 g: 1e-3 / 9.8 m/s^2.
  info.parameters = AxisParameters("k", "1/(m/s^2)", 1e-4);
  info.excitation.still_orientations = true;
  return info;
}

}  // namespace accel_scale_nonlinearity

class AccelScaleNonlinearity : public EffectBase<AccelScaleNonlinearity> {
 public:
  explicit AccelScaleNonlinearity(const std::string& option) : EffectBase(accel_scale_nonlinearity::Describe(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    Eigen::Map<const Vec3T<T>> k(theta);
    const Vec3T<T> sensed = out.F * in.f_b;
    out.acc += k.cwiseProduct(sensed.cwiseProduct(sensed));
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(accel_scale_nonlinearity, ::plumb::model::AccelScaleNonlinearity)

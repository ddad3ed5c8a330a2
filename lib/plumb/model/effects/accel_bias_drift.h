// accel_bias_drift — the accelerometer bias changes linearly with time (SPEC section 4).
//
//   y_a += d_a (t - t_ref)
//
// Parameter block (3 values, zero = no drift): d.x, d.y, d.z in m/s^3.
// Residual signature: accelerometer residual that trends with time.
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace accel_bias_drift {

/// The catalogue entry of accel_bias_drift (parameters, units, typical sizes); throws
/// plumb::Error on an option it does not take.
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty()) throw Error("accel_bias_drift takes no option (got '" + option + "')");
  EffectInfo info;
  info.name = "accel_bias_drift";
  info.prefix = info.name;
  info.sensor = Sensor::kAccel;
  info.term = "y_a += d_a (t - t_ref)";
  info.parameters = AxisParameters("d", "m/s^3", 1e-4);
  info.excitation.time = true;
  return info;
}

}  // namespace accel_bias_drift

class AccelBiasDrift : public EffectBase<AccelBiasDrift> {
 public:
  explicit AccelBiasDrift(const std::string& option) : EffectBase(accel_bias_drift::Describe(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    Eigen::Map<const Vec3T<T>> d_a(theta);
    out.acc += d_a * in.dt_s;
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(accel_bias_drift, ::plumb::model::AccelBiasDrift)

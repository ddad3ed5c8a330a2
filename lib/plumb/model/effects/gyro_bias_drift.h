// gyro_bias_drift — the gyroscope bias changes linearly with time (SPEC section 4).
//
//   y_g += d_g (t - t_ref)
//
// Parameter block (3 values, zero = no drift): d.x, d.y, d.z in rad/s^2.
// Residual signature: gyroscope residual that trends with time.
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace gyro_bias_drift {

/// The catalogue entry of gyro_bias_drift (parameters, units, typical sizes); throws
/// plumb::Error on an option it does not take.
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty()) throw Error("gyro_bias_drift takes no option (got '" + option + "')");
  EffectInfo info;
  info.name = "gyro_bias_drift";
  info.prefix = info.name;
  info.sensor = Sensor::kGyro;
  info.term = "y_g += d_g (t - t_ref)";
  // Warm-up drift of a small MEMS gyroscope: ~0.3 deg/s over ten minutes.
  info.parameters = AxisParameters("d", "rad/s^2", 1e-5);
  info.excitation.time = true;
  return info;
}

}  // namespace gyro_bias_drift

class GyroBiasDrift : public EffectBase<GyroBiasDrift> {
 public:
  explicit GyroBiasDrift(const std::string& option) : EffectBase(gyro_bias_drift::Describe(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    Eigen::Map<const Vec3T<T>> d_g(theta);
    out.gyr += d_g * in.dt_s;
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(gyro_bias_drift, ::plumb::model::GyroBiasDrift)

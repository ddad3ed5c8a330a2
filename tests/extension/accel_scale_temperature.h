// accel_scale_temperature — the accelerometer scale factors change with temperature (an
// effect that is not in the SPEC section 4 catalogue: the worked example of
// docs/extending.md). Each axis's sensitivity drifts linearly with the temperature offset
// dT = T - T_ref (Model::temp_ref_c):
//
//   y_a,i += s_i (T - T_ref) (F f_b)_i,   i = x, y, z
//
// where F is the accelerometer matrix written by accel_linear (SensorOutput::F), so the term
// scales what axis i senses through its own scale and misalignment.
//
// Parameter block (3 values, zero = scale independent of temperature):
//   [0..2] s.x, s.y, s.z in 1/degC (typical 1e-4, i.e. 100 ppm/degC, ICM-20602 class)
// The term uses SensorInput::dtemp_c.
// Residual signature: accelerometer residual that follows the temperature and flips sign
// with the same-axis input (an axis up and the same axis down disagree in opposite
// directions), where accel_temperature_bias moves the residual the same way in every pose.
//
// Two ways to add it (docs/extending.md): register it at run time in your own program
// (plumb::autodiff::RegisterEffect<plumb::model::AccelScaleTemperature>), or copy this file to
// lib/plumb/model/effects/ and add the line `accel_scale_temperature` to
// lib/plumb/model/effects/effects.cmake.
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace accel_scale_temperature {

/// The catalogue entry of accel_scale_temperature (parameters, units, typical sizes); throws
/// plumb::Error on an option (it takes none).
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty()) {
    throw Error("accel_scale_temperature takes no option (got '" + option + "')");
  }
  EffectInfo info;
  info.name = "accel_scale_temperature";
  info.prefix = info.name;
  info.sensor = Sensor::kAccel;
  info.term = "y_a,i += s_i (T - T_ref) (F f_b)_i";
  info.parameters = AxisParameters("s", "1/degC", 1e-4);
  // Seen only when the temperature varies while the axes sense different parts of gravity.
  info.excitation.temperature = true;
  info.excitation.still_orientations = true;
  return info;
}

}  // namespace accel_scale_temperature

class AccelScaleTemperature : public EffectBase<AccelScaleTemperature> {
 public:
  explicit AccelScaleTemperature(const std::string& option) : EffectBase(accel_scale_temperature::Describe(option)) {}

  // One template for double and Jet: every value that depends on theta or the input is a T.
  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    Eigen::Map<const Vec3T<T>> s(theta);  // 1/degC
    const Vec3T<T> sensed = out.F * in.f_b;
    out.acc += s.cwiseProduct(sensed) * in.dtemp_c;
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(accel_scale_temperature, ::plumb::model::AccelScaleTemperature)

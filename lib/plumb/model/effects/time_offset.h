// time_offset — the gyroscope samples are shifted by dt against the accelerometer samples
// (SPEC section 4): the gyroscope sample stamped t saw the rate at t + dt. To first order in dt,
//
//   y_g += E alpha_b dt
//
// where E is the gyroscope matrix written by gyro_linear (SensorOutput::E) and alpha_b the
// angular acceleration (SensorInput::alpha_b). A positive dt means the gyroscope leads.
//
// Parameter block (1 value, zero = synchronous): dt in s.
// Residual signature: motion residual that follows the angular acceleration.
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace time_offset {

/// The catalogue entry of time_offset (parameters, units, typical sizes); throws
/// plumb::Error on an option it does not take.
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty()) throw Error("time_offset takes no option (got '" + option + "')");
  EffectInfo info;
  info.name = "time_offset";
  info.prefix = info.name;
  info.sensor = Sensor::kGyro;
  info.term = "y_g += E alpha_b dt";
  // A sample period or so at the 400 Hz - 1 kHz rates of ArduPilot and PX4.
  info.parameters = {{"dt", "s", 1e-3, 0.0}};
  info.excitation.angular_acceleration = true;
  return info;
}

}  // namespace time_offset

class TimeOffset : public EffectBase<TimeOffset> {
 public:
  explicit TimeOffset(const std::string& option) : EffectBase(time_offset::Describe(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    const T& dt = theta[0];
    out.gyr += out.E * in.alpha_b * dt;
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(time_offset, ::plumb::model::TimeOffset)

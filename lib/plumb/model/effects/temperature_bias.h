// plumb/model/effects/temperature_bias.h — the polynomial temperature bias shared by
// accel_temperature_bias and gyro_temperature_bias (SPEC section 4):
//
//   y += c1 dT [+ c2 dT^2 [+ c3 dT^3]],   dT = T - T_ref (Model::temp_ref_c), degC
//
// Option: the polynomial order, "1" (default, also when empty), "2" or "3"; order 1 is
// normalised to "" so that "<name>:1" reads back as "<name>".
// Parameter block (3 values per order, lowest order first, zero = no temperature effect):
//   [0..2] c1.x c1.y c1.z, [3..5] c2.* (order >= 2), [6..8] c3.* (order 3), in the sensor's
//   output unit per degC^k. The term uses SensorInput::dtemp_c.
//
// The two effects (accel_temperature_bias.h, gyro_temperature_bias.h) differ only in their Spec.
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model::temperature {

/// What differs between the two sensors.
struct Spec {
  const char* name;         ///< catalogue name
  Sensor sensor;            ///< which output the term adds to
  const char* output;       ///< "y_a" or "y_g", for the term text
  const char* unit;         ///< output unit, e.g. "m/s^2"
  double typical[3];        ///< typical c1, c2, c3 of a MEMS IMU on a small UAV
};

/// The order an option asks for; throws plumb::Error on another option.
inline int ParseOrder(const Spec& spec, const std::string& option) {
  if (option.empty() || option == "1") return 1;
  if (option == "2") return 2;
  if (option == "3") return 3;
  throw Error(std::string(spec.name) +
              " takes the polynomial order 1, 2 or 3 as its option (got '" + option + "')");
}

/// The catalogue entry of the effect of `spec` with `option`.
inline EffectInfo Describe(const Spec& spec, const std::string& option) {
  const int order = ParseOrder(spec, option);
  EffectInfo info;
  info.name = spec.name;
  info.prefix = info.name;
  info.option = order == 1 ? "" : std::to_string(order);
  info.sensor = spec.sensor;
  info.term = std::string(spec.output) + " += c1 (T - T_ref)";
  if (order >= 2) info.term += " + c2 (T - T_ref)^2";
  if (order >= 3) info.term += " + c3 (T - T_ref)^3";
  for (int k = 0; k < order; ++k) {
    const std::string unit =
        std::string(spec.unit) + "/degC" + (k == 0 ? "" : "^" + std::to_string(k + 1));
    auto c = AxisParameters("c" + std::to_string(k + 1), unit, spec.typical[k]);
    info.parameters.insert(info.parameters.end(), c.begin(), c.end());
  }
  info.excitation.temperature = true;
  return info;
}

/// The effect; `kSpec` is the sensor's Spec.
template <const Spec& kSpec>
class TemperatureBias : public EffectBase<TemperatureBias<kSpec>> {
 public:
  explicit TemperatureBias(const std::string& option)
      : EffectBase<TemperatureBias<kSpec>>(Describe(kSpec, option)),
        order_(ParseOrder(kSpec, option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    Vec3T<T>& y = kSpec.sensor == Sensor::kAccel ? out.acc : out.gyr;
    T power = in.dtemp_c;  // dT^k, k = 1 .. order
    for (int k = 0; k < order_; ++k) {
      Eigen::Map<const Vec3T<T>> c_k(theta + 3 * k);
      y += c_k * power;
      power *= in.dtemp_c;
    }
  }

 private:
  int order_;
};

}  // namespace plumb::model::temperature

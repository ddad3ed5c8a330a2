// gyro_temperature_bias — the gyroscope bias depends on temperature
// (SPEC section 4), a polynomial in the temperature offset dT = T - T_ref (Model::temp_ref_c):
//
//   y_g += c1 dT [+ c2 dT^2 [+ c3 dT^3]]
//
// Option: the polynomial order, "1" (default, also when empty), "2" or "3"; the normalised
// option of order 1 is "" so that "gyro_temperature_bias:1" reads back as "gyro_temperature_bias".
//
// Parameter block (3 values per order, lowest order first, zero = no temperature effect):
//   [0..2] c1.x, c1.y, c1.z in rad/s/degC
//   [3..5] c2.x, c2.y, c2.z in rad/s/degC^2   (order >= 2)
//   [6..8] c3.x, c3.y, c3.z in rad/s/degC^3   (order 3)
// The term uses SensorInput::dtemp_c.
// Residual signature: gyroscope residual that follows the temperature.
#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace {

int ParseOrder(const std::string& option) {
  if (option.empty() || option == "1") return 1;
  if (option == "2") return 2;
  if (option == "3") return 3;
  throw Error("gyro_temperature_bias takes the polynomial order 1, 2 or 3 as its option (got '" +
              option + "')");
}

EffectInfo MakeInfo(const std::string& option) {
  const int order = ParseOrder(option);
  EffectInfo info;
  info.name = "gyro_temperature_bias";
  info.prefix = info.name;
  info.option = order == 1 ? "" : std::to_string(order);
  info.sensor = Sensor::kGyro;
  const char* terms[3] = {"y_g += c1 (T - T_ref)",
                          "y_g += c1 (T - T_ref) + c2 (T - T_ref)^2",
                          "y_g += c1 (T - T_ref) + c2 (T - T_ref)^2 + c3 (T - T_ref)^3"};
  info.term = terms[order - 1];
  // Typical sizes: ~0.02 deg/s/degC (ICM-20689 class), with a few per cent of curvature per degC.
  const double typical[3] = {4e-4, 1e-5, 2e-7};
  const char* units[3] = {"rad/s/degC", "rad/s/degC^2", "rad/s/degC^3"};
  for (int k = 0; k < order; ++k) {
    auto c = AxisParameters("c" + std::to_string(k + 1), units[k], typical[k]);
    info.parameters.insert(info.parameters.end(), c.begin(), c.end());
  }
  info.excitation.temperature = true;
  return info;
}

class GyroTemperatureBias : public EffectBase<GyroTemperatureBias> {
 public:
  explicit GyroTemperatureBias(const std::string& option)
      : EffectBase(MakeInfo(option)), order_(ParseOrder(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    T power = in.dtemp_c;  // dT^k, k = 1 .. order
    for (int k = 0; k < order_; ++k) {
      Eigen::Map<const Vec3T<T>> c_k(theta + 3 * k);
      out.gyr += c_k * power;
      power *= in.dtemp_c;
    }
  }

 private:
  int order_;
};

}  // namespace
}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(gyro_temperature_bias, ::plumb::model::GyroTemperatureBias)

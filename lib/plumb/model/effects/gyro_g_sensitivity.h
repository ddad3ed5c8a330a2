// gyro_g_sensitivity — the gyroscope responds to specific force (SPEC section 4).
//
//   y_g += G f_b
//
// Parameter block (9 values, zero = no g-sensitivity): G row-major, G.xx, G.xy, G.xz, G.yx,
// G.yy, G.yz, G.zx, G.zy, G.zz in rad/s per m/s^2 (row = gyroscope axis, column = axis of the
// specific force).
// Residual signature: the still gyroscope residual changes with the pose, i.e. with f_b.
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace gyro_g_sensitivity {

/// The catalogue entry of gyro_g_sensitivity (parameters, units, typical sizes); throws
/// plumb::Error on an option it does not take.
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty()) throw Error("gyro_g_sensitivity takes no option (got '" + option + "')");
  EffectInfo info;
  info.name = "gyro_g_sensitivity";
  info.prefix = info.name;
  info.sensor = Sensor::kGyro;
  info.term = "y_g += G f_b";
  // ~0.1 deg/s per g for a consumer MEMS gyroscope: 1.8e-4 rad/s per m/s^2.
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      info.parameters.push_back(
          {std::string("G.") + kAxisName[r] + kAxisName[c], "rad/s per m/s^2", 2e-4, 0.0});
    }
  }
  info.excitation.still_orientations = true;
  return info;
}

}  // namespace gyro_g_sensitivity

class GyroGSensitivity : public EffectBase<GyroGSensitivity> {
 public:
  explicit GyroGSensitivity(const std::string& option) : EffectBase(gyro_g_sensitivity::Describe(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    Eigen::Map<const Eigen::Matrix<T, 3, 3, Eigen::RowMajor>> G(theta);
    out.gyr += G * in.f_b;
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(gyro_g_sensitivity, ::plumb::model::GyroGSensitivity)

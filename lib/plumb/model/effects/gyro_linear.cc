// gyro_linear — the base gyroscope model (SPEC section 2, the paper's Equation (2)).
//
//   y_g = E omega_b + b_g,   E full 3x3 relative to the accelerometer-defined body frame
//                            (3 scales + 6 misalignments), b_g the bias.
//
// Option "triangular": the paper's upper-triangular E (matrix.yx, matrix.zx, matrix.zy held
// at zero).
//
// Parameter block: see gyro_linear.h, which owns its layout.
#include "plumb/core/error.h"
#include "plumb/model/effect.h"
#include "plumb/model/effects/gyro_linear.h"

namespace plumb::model {
namespace {

EffectInfo MakeInfo(const std::string& option) {
  if (!option.empty() && option != "triangular") {
    throw Error("gyro_linear's only option is 'triangular' (got '" + option + "')");
  }
  EffectInfo info;
  info.name = "gyro_linear";
  info.prefix = "gyro";
  info.option = option;
  info.sensor = Sensor::kGyro;
  info.linear_stage = true;
  info.term = option.empty() ? "y_g = E omega_b + b_g, E full"
                             : "y_g = E omega_b + b_g, E upper triangular";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      info.parameters.push_back({std::string("matrix.") + kAxisName[r] + kAxisName[c], "1",
                                 r == c ? 0.02 : 0.01, r == c ? 1.0 : 0.0});
    }
  }
  auto bias = AxisParameters("bias", "rad/s", 0.02);
  info.parameters.insert(info.parameters.end(), bias.begin(), bias.end());
  if (option == "triangular") {
    info.held = {gyro_linear::MatrixIndex(1, 0), gyro_linear::MatrixIndex(2, 0),
                 gyro_linear::MatrixIndex(2, 1)};
  }
  info.excitation.still_orientations = true;
  info.excitation.rotation = true;
  return info;
}

class GyroLinear : public EffectBase<GyroLinear> {
 public:
  explicit GyroLinear(const std::string& option) : EffectBase(MakeInfo(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    const Mat3T<T> E = gyro_linear::Matrix(theta);
    Eigen::Map<const Vec3T<T>> b_g(theta + gyro_linear::kBias);
    out.E = E;
    out.gyr = E * in.omega_b + b_g;
  }
};

}  // namespace
}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(gyro_linear, ::plumb::model::GyroLinear)

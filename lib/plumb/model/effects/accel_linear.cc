// accel_linear — the base accelerometer model (SPEC section 2, the paper's Equation (1)).
//
//   y_a = F f_b + b_a,   F upper triangular (sensor and body x axes coincide, body y lies in
//                        the sensor x-y plane), b_a the bias.
//
// Parameter block: see accel_linear.h, which owns its layout.
//
// Option "full": F full 3x3, for a frame that the data defines by known attitudes (the
// paper's benchmark platform, whose faces give the axes) rather than by the accelerometer
// itself. Three more values: matrix.yx, matrix.zx, matrix.zy (dimensionless). Without
// known attitudes, a full F is not determined (a rotation of the frame changes no prediction).
#include "plumb/core/error.h"
#include "plumb/model/effect.h"
#include "plumb/model/effects/accel_linear.h"

namespace plumb::model {
namespace {

EffectInfo MakeInfo(const std::string& option) {
  if (!option.empty() && option != "full") {
    throw Error("accel_linear's only option is 'full' (got '" + option + "')");
  }
  EffectInfo info;
  info.name = "accel_linear";
  info.prefix = "accel";
  info.option = option;
  info.sensor = Sensor::kAccel;
  info.linear_stage = true;
  info.term = option.empty() ? "y_a = F f_b + b_a, F upper triangular"
                             : "y_a = F f_b + b_a, F full";
  info.parameters = {{"matrix.xx", "1", 0.02, 1.0}, {"matrix.xy", "1", 0.01, 0.0},
                     {"matrix.xz", "1", 0.01, 0.0}, {"matrix.yy", "1", 0.02, 1.0},
                     {"matrix.yz", "1", 0.01, 0.0}, {"matrix.zz", "1", 0.02, 1.0}};
  auto bias = AxisParameters("bias", "m/s^2", 0.2);
  info.parameters.insert(info.parameters.end(), bias.begin(), bias.end());
  if (option == "full") {
    for (const char* name : {"matrix.yx", "matrix.zx", "matrix.zy"}) {
      info.parameters.push_back({name, "1", 0.01, 0.0});
    }
  }
  info.excitation.still_orientations = true;
  return info;
}

class AccelLinear : public EffectBase<AccelLinear> {
 public:
  explicit AccelLinear(const std::string& option)
      : EffectBase(MakeInfo(option)), full_(option == "full") {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    const Mat3T<T> F = accel_linear::Matrix(theta, full_);
    Eigen::Map<const Vec3T<T>> b_a(theta + accel_linear::kBias);
    out.F = F;
    out.acc = F * in.f_b + b_a;
  }

 private:
  bool full_;
};

}  // namespace
}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(accel_linear, ::plumb::model::AccelLinear)

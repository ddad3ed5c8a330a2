// plumb/model/effect.h — the extension point: one physical effect of the IMU error model.
//
// The forward model (SPEC sections 1-2) is a composition of effects:
//
//   y_a = F f_b + b_a + sum_k accel_term_k(theta_k, input)
//   y_g = E omega_b + b_g + sum_k gyro_term_k(theta_k, input)
//
// The base model is itself made of effects (`accel_linear` writes F and b_a, `gyro_linear`
// writes E and b_g); catalogue effects add terms. Every effect owns one parameter block whose
// all-zero value means "no effect" (for the linear effects: F = I, b = 0), so every effect is
// the identity at zero, as basalt's calib_bias.hpp is.
//
// An effect's term is a template on the scalar, as basalt's types are: the model evaluates it on
// doubles (the simulator, the correction, the reports), and the fit's residuals on Ceres Jets
// (plumb/autodiff/differentiable_effect.h instantiates the same Term for Jets). This module
// itself knows no Jet and no Ceres.
//
// Writing an effect (worked example, see docs/extending.md and tests/model/effects_test.cc):
//
//   // lib/plumb/model/effects/accel_bias_drift.h
//   class AccelBiasDrift : public EffectBase<AccelBiasDrift> {
//    public:
//     explicit AccelBiasDrift(const std::string& option)
//         : EffectBase(accel_bias_drift::Describe(option)) {}
//     template <typename T>
//     void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
//       Eigen::Map<const Vec3T<T>> d_a(theta);   // m/s^3
//       out.acc += d_a * in.dt_s;
//     }
//   };
//   PLUMB_DEFINE_EFFECT(accel_bias_drift, ::plumb::model::AccelBiasDrift)
//
// and one line `accel_bias_drift` in lib/plumb/model/effects/effects.cmake. The effect then
// appears in model specs ("base+accel_bias_drift"), in the simulator, in the fit and in
// diagnose.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "plumb/core/types.h"

namespace plumb::model {

enum class Sensor { kAccel, kGyro };

/// One scalar parameter of an effect.
struct ParameterInfo {
  std::string name;      ///< within the effect, e.g. "matrix.xy", "bias.z", "G.xy", "c1.x"
  std::string unit;      ///< SI unit of the reported value, e.g. "m/s^2", "rad/s per m/s^2"
  double typical = 1.0;  ///< typical magnitude for a MEMS IMU on a small UAV, same unit (> 0)
  double nominal = 0.0;  ///< reported value = nominal + block value (1 on matrix diagonals)
};

/// What data excites an effect (used to explain "not identifiable" and "too little data").
struct Excitation {
  bool still_orientations = false;  ///< still poses in several orientations
  bool rotation = false;            ///< motion between still poses (angular rate)
  bool angular_acceleration = false;
  bool temperature = false;         ///< temperature that varies
  bool time = false;                ///< a session long enough for drift
};

/// Static description of an effect: its name, its term and its parameters.
struct EffectInfo {
  std::string name;    ///< catalogue name (CLI and JSON contract), e.g. "gyro_g_sensitivity"
  std::string prefix;  ///< parameter-name prefix: "accel", "gyro" or the effect name
  std::string option;  ///< the option it was made with ("" or e.g. "2" for a polynomial order)
  Sensor sensor = Sensor::kAccel;
  bool linear_stage = false;  ///< true only for the base effects that write F/E and the bias
  /// Parameters are quantities of the true input (e.g. earth_rate's rad/s), reported in SI
  /// whatever the unit of the sensor output; otherwise additive terms are in output units.
  bool input_side = false;
  std::string term;           ///< its term in the forward model, as text
  std::vector<ParameterInfo> parameters;
  /// Parameters (indices into `parameters`) the option holds at their nominal value in every
  /// fit, e.g. gyro_linear:triangular's lower triangle of E.
  std::vector<int> held;
  Excitation excitation;

  int size() const { return static_cast<int>(parameters.size()); }
  /// True when parameter i is in the sensor's output units on unscaled output (counts): an
  /// additive term whose SI unit starts with the sensor's input unit ("rad/s per m/s^2" is
  /// then "counts per m/s^2"), so its value and typical size scale with the output's
  /// sensitivity. False for the linear stage and input-side parameters.
  bool ScalesWithOutput(int i) const {
    if (linear_stage || input_side) return false;
    const std::string in = sensor == Sensor::kAccel ? "m/s^2" : "rad/s";
    return parameters[static_cast<std::size_t>(i)].unit.rfind(in, 0) == 0;
  }
  /// Full name of parameter i: prefix + "." + parameters[i].name.
  std::string ParameterName(int i) const { return prefix + "." + parameters[i].name; }
};

/// What a sensor sees at one instant (or on average over a still segment).
template <typename T>
struct SensorInput {
  Vec3T<T> f_b = Vec3T<T>::Zero();      ///< true specific force, body frame, m/s^2
  Vec3T<T> omega_b = Vec3T<T>::Zero();  ///< true angular rate wrt inertial, body frame, rad/s
  Vec3T<T> alpha_b = Vec3T<T>::Zero();  ///< angular acceleration, body frame, rad/s^2
  T dt_s = T(0);     ///< time since the model's reference time t_ref, s
  T dtemp_c = T(0);  ///< temperature minus the model's reference temperature, degC
  /// Attitude, NED vectors into body (R_n_b^T), on still segments; zero where it is not known
  /// (samples of motion intervals). Used by earth_rate.
  Mat3T<T> R_b_n = Mat3T<T>::Zero();
};

/// What a sensor at rest sees (SPEC section 1): gravity's reaction and the Earth's rate (plus
/// a known turn omega_eb_b, e.g. a turntable's, rad/s) in the body frame of attitude R_b_n =
/// R_n_b^T; `g_n` and `omega_ie_n` in NED. The still residuals predict with it, and what
/// compares a fit with its still segments.
template <typename T>
SensorInput<T> AtRest(const Mat3T<T>& R_b_n, const Vec3& g_n, const Vec3& omega_ie_n,
                      const Vec3& omega_eb_b, T dt_s, T dtemp_c) {
  SensorInput<T> in;
  in.f_b = R_b_n * (-g_n.cast<T>());
  in.omega_b = R_b_n * omega_ie_n.cast<T>() + omega_eb_b.cast<T>();
  in.dt_s = dt_s;
  in.dtemp_c = dtemp_c;
  in.R_b_n = R_b_n;
  return in;
}

/// The predicted outputs, built up effect by effect.
template <typename T>
struct SensorOutput {
  Vec3T<T> acc = Vec3T<T>::Zero();  ///< predicted accelerometer output y_a
  Vec3T<T> gyr = Vec3T<T>::Zero();  ///< predicted gyroscope output y_g
  Mat3T<T> F = Mat3T<T>::Identity();  ///< accelerometer matrix written by accel_linear
  Mat3T<T> E = Mat3T<T>::Identity();  ///< gyroscope matrix written by gyro_linear
};

/// Interface of an effect. Implement it through EffectBase<Derived> (CRTP) with one templated
/// `Term<T>()`: the model calls it on doubles through Apply, and plumb::autodiff on Jets.
class Effect {
 public:
  explicit Effect(EffectInfo info) : info_(std::move(info)) {}
  virtual ~Effect() = default;
  const EffectInfo& info() const { return info_; }

  /// Adds this effect's term to `out`. `theta` points at this effect's parameter block
  /// (info().size() values). Linear-stage effects overwrite acc or gyr and F or E instead.
  /// A catalogue term may read the linear stage's F and E; one that reads acc or gyr as the
  /// terms before it left them makes the motion residual differentiate the whole model at
  /// every pass (residuals/motion_residual.h), so the built-in ones do not.
  virtual void Apply(const double* theta, const SensorInput<double>& in,
                     SensorOutput<double>& out) const = 0;

 private:
  EffectInfo info_;
};

/// The base of every effect: `Derived` has
///   template <typename T>
///   void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const;
/// written once for every scalar (docs/extending.md says what that asks of the code).
template <class Derived>
class EffectBase : public Effect {
 public:
  using Effect::Effect;
  void Apply(const double* theta, const SensorInput<double>& in,
             SensorOutput<double>& out) const final {
    static_cast<const Derived*>(this)->Term(theta, in, out);
  }
};

using EffectFactory = std::unique_ptr<Effect> (*)(const std::string& option);

/// The factory of effect class `E`: `option` is the text after ':' in a model spec (e.g. "2" in
/// accel_temperature_bias:2), empty when absent.
template <class E>
std::unique_ptr<Effect> MakeEffect(const std::string& option) {
  return std::make_unique<E>(option);
}

/// Names the class of a built-in effect for the registration lists generated from
/// effects/effects.cmake: plumb::model::effects::NAME is CLASS. The model's catalogue
/// (registry.cc) makes it by NAME, plumb::autodiff gives it its Jet form.
#define PLUMB_DEFINE_EFFECT(NAME, CLASS) \
  namespace plumb::model::effects {      \
  using NAME = CLASS;                    \
  }

/// Per-axis parameter helper: {"<stem>.x", "<stem>.y", "<stem>.z"}.
std::vector<ParameterInfo> AxisParameters(const std::string& stem, const std::string& unit,
                                          double typical, double nominal = 0.0);

}  // namespace plumb::model

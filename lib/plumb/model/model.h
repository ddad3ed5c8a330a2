// plumb/model/model.h — an IMU error model: an ordered composition of effects.
//
// A model is written as a spec (SPEC section 2): "base", "paper", or "base+EFFECT[:OPTION]...",
// e.g. "base+gyro_g_sensitivity+accel_temperature_bias:2". "base" is accel_linear +
// gyro_linear (F upper triangular, E full); "paper" is accel_linear + gyro_linear:triangular,
// the seed paper's upper-triangular E.
//
// Parameter layout: effect i owns parameter block i (effects()[i].info().size() values);
// the block's zero is "no effect". Parameters are addressed by their full names
// ("accel.matrix.xy", "gyro.bias.z", "gyro_g_sensitivity.G.xy"), and a parameter can be held
// fixed (the paper's constants, the triangular variant's zeros).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "plumb/model/effect.h"

namespace plumb::model {

/// One effect in a model with its fixed parameters.
struct ModelTerm {
  std::shared_ptr<const Effect> effect;
  std::vector<bool> fixed;  ///< per parameter: held at its value in the fit
  /// A candidate of the score test (Model::AddProbe): every parameter held at zero in the fit,
  /// not part of the spec; the fit reports the Jacobian columns of its parameters
  /// (estimation::CalibrationResult::probes).
  bool probe = false;
};

/// What a parameter is, answered from the layout its effect owns (effects/accel_linear.h,
/// effects/gyro_linear.h, the temperature polynomial's block): modules ask this instead of
/// reading the parameter's name.
enum class ParameterRole {
  kScale,            ///< a diagonal entry of F or E (the base effects)
  kCrossAxis,        ///< an off-diagonal entry of F or E
  kBias,             ///< b_a or b_g
  kTemperatureBias,  ///< a coefficient of accel_temperature_bias / gyro_temperature_bias
  kOther,            ///< any other catalogue effect's parameter
};

/// Where a parameter lives: model term `term` (Model::terms()), value `index` of its block.
struct ParameterPlace {
  int term = -1;
  int index = -1;
  bool operator==(const ParameterPlace& o) const { return term == o.term && index == o.index; }
  bool operator!=(const ParameterPlace& o) const { return !(*this == o); }
};

/// Parameter values of a model: one block per effect, in model order.
using ParameterBlocks = std::vector<std::vector<double>>;

class Model {
 public:
  /// Parses a spec; throws plumb::Error naming the unknown effect and the catalogue.
  static Model Parse(const std::string& spec);

  /// Reference time and temperature of the drift and temperature terms.
  double t_ref_s = 0.0;
  double temp_ref_c = 25.0;

  /// The spec this model was parsed from, normalised (e.g. "base+gyro_g_sensitivity").
  const std::string& spec() const { return spec_; }
  const std::vector<ModelTerm>& terms() const { return terms_; }
  int num_terms() const { return static_cast<int>(terms_.size()); }
  bool has_gyro() const;
  bool has_effect(const std::string& name) const;
  /// Index of the term with this effect name, or -1.
  int FindTerm(const std::string& name) const;
  /// Index of the base (linear-stage) term of `sensor` (accel_linear, gyro_linear), or -1.
  /// Whether a term is a base effect is asked of the effect (EffectInfo::linear_stage).
  int BaseTerm(Sensor sensor) const;

  /// Adds an effect (its block starts at zero); throws if already present.
  void Add(const std::string& name, const std::string& option = "");
  /// Adds an effect as a probe (see ModelTerm::probe): held at zero, left out of the spec.
  void AddProbe(const std::string& name, const std::string& option = "");
  /// True when some term is a probe.
  bool has_probes() const;
  /// Removes the gyroscope terms (accelerometer-only sessions).
  void DropGyro();

  /// Zero-valued parameter blocks (the identity model).
  ParameterBlocks ZeroParameters() const;
  /// Total number of scalar parameters, and of free ones.
  int num_parameters() const;
  /// Index of term `term`'s first parameter among all of them (ParameterNames() order).
  int FirstParameter(int term) const;
  int num_free_parameters() const;
  /// Full names of all parameters, in block order.
  std::vector<std::string> ParameterNames() const;
  /// (term, index) of a full parameter name, or nullopt.
  std::optional<std::pair<int, int>> FindParameter(const std::string& full_name) const;
  /// Holds a parameter fixed at its nominal value (the identity model: 1 on the diagonals of
  /// F and E, 0 elsewhere) in the fit (throws if the name is unknown).
  void Fix(const std::string& full_name, bool fixed = true);
  /// The same for the parameter at `place` (throws if the model has no such parameter).
  void Fix(ParameterPlace place, bool fixed = true);

  /// The sensor whose output the parameter at `place` models, and what it is there.
  Sensor SensorOf(ParameterPlace place) const;
  ParameterRole Role(ParameterPlace place) const;
  /// The place of entry (r, c) of F (kAccel) or E (kGyro) in the sensor's base term, or
  /// nullopt when the model has no such term or its block no such entry (F's lower triangle
  /// without accel_linear's option "full").
  std::optional<ParameterPlace> MatrixEntry(Sensor sensor, int r, int c) const;
  /// Index of the sensor's temperature bias polynomial term (accel_temperature_bias,
  /// gyro_temperature_bias), or -1.
  int TemperatureBiasTerm(Sensor sensor) const;

  /// True when every term but the linear stage's (EffectInfo::linear_stage) is at zero in
  /// `theta` (block i of term i): the model then acts as its linear stage, y = F f + b_a,
  /// y_g = E omega + b_g, and its inverse and derivatives have closed forms.
  bool AtLinearStage(const double* const* theta) const;

  /// Forward model: predicted outputs for the true inputs. `theta[i]` is block i. (On Jets:
  /// plumb::autodiff::DifferentiableModel.)
  SensorOutput<double> Predict(const double* const* theta, const SensorInput<double>& in) const;

  /// Inverse model: the true specific force and angular rate that produce measured y_a, y_g,
  /// by Newton iterations on the forward model started from the linear inverse. `in` supplies
  /// the other inputs (time, temperature, angular acceleration); its f_b and omega_b are
  /// ignored. Without gyroscope terms, omega_b is returned as zero.
  std::pair<Vec3, Vec3> Correct(const double* const* theta, const Vec3& y_a, const Vec3& y_g,
                                SensorInput<double> in, int iterations = 3) const;

  /// The same with the inverses of the linear part given (F^-1, E^-1, which do not depend on
  /// the inputs) and `steps` Newton steps, for callers that correct many samples.
  std::pair<Vec3, Vec3> Correct(const double* const* theta, const Vec3& y_a, const Vec3& y_g,
                                SensorInput<double> in, const Mat3& F_inv, const Mat3& E_inv,
                                int steps) const;

  /// The same on doubles, Newton steps until a step moves f_b and omega_b by at most
  /// `tolerance` times their size (or 1e-300), at most `max_steps`: the fixed point
  /// y = Predict(theta, x) to rounding, for implicit derivatives of the correction.
  std::pair<Vec3, Vec3> CorrectToFixedPoint(const double* const* theta, const Vec3& y_a,
                                            const Vec3& y_g, SensorInput<double> in,
                                            const Mat3& F_inv, const Mat3& E_inv, int max_steps,
                                            double tolerance) const;

  /// Convenience: the same on double blocks.
  SensorOutput<double> Predict(const ParameterBlocks& theta, const SensorInput<double>& in) const;
  std::pair<Vec3, Vec3> Correct(const ParameterBlocks& theta, const Vec3& y_a, const Vec3& y_g,
                                const SensorInput<double>& in) const;

 private:
  void RebuildSpec();

  std::string spec_;
  std::vector<ModelTerm> terms_;
};

/// Reported value of every parameter (nominal + block value), in ParameterNames() order.
std::vector<double> ReportedValues(const Model& model, const ParameterBlocks& theta);

}  // namespace plumb::model

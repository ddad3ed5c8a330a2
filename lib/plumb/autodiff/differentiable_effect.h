// plumb/autodiff/differentiable_effect.h — the error model's effects on Jets, for the fit.
//
// plumb::model evaluates an effect on doubles only (Effect::Apply) and knows no Ceres; every
// effect's term is a template on the scalar (EffectBase<Derived>::Term<T>). This module
// instantiates that same template for Jets and finds it again from the effect: a class's Jet
// form is registered once (the built-in effects' from the list generated from
// lib/plumb/model/effects/effects.cmake; a program's own effect with RegisterEffect<Class>) and
// looked up by the effect's dynamic type, never by its name.
//
//   // a program's own effect (docs/extending.md, way (a)):
//   plumb::autodiff::RegisterEffect<plumb::model::AccelScaleTemperature>("accel_scale_temperature");
//   // the residuals: each term applied on the scalar the cost function asks for
//   const autodiff::DifferentiableModel terms(model);
//   terms.term(i).Apply(theta_i, in, out);   // double or Jet
#pragma once

#include <string>
#include <typeinfo>
#include <vector>

#include "plumb/autodiff/jet.h"
#include "plumb/model/effect.h"
#include "plumb/model/model.h"
#include "plumb/model/registry.h"

namespace plumb::autodiff {

/// An effect's term on Jets: `effect`'s own Term<Jet> (`effect` is of the class it was made
/// for).
using JetTerm = void (*)(const model::Effect& effect, const Jet* theta,
                         const model::SensorInput<Jet>& in, model::SensorOutput<Jet>& out);

/// The Jet term of effect class `E`.
template <class E>
void ApplyOnJets(const model::Effect& effect, const Jet* theta, const model::SensorInput<Jet>& in,
                 model::SensorOutput<Jet>& out) {
  static_cast<const E&>(effect).Term(theta, in, out);
}

/// Gives the effects of class `effect_class` the Jet term `term`; registering a class again
/// replaces nothing (its term is the same template). Thread-safe.
void RegisterJetTerm(const std::type_info& effect_class, JetTerm term);

/// Gives effect class `E` its Jet form.
template <class E>
void RegisterJetForm() {
  RegisterJetTerm(typeid(E), &ApplyOnJets<E>);
}

/// Adds a program's own effect class `E` under `name`: to the model's catalogue
/// (model::Registry::Global(), which throws plumb::Error if the name is taken or malformed) and
/// with its Jet form, so that models, the simulator, the fit and diagnose all use it.
template <class E>
void RegisterEffect(const std::string& name) {
  model::Registry::Global().Register(name, &model::MakeEffect<E>);
  RegisterJetForm<E>();
}

/// One effect with its term on both scalars. Throws plumb::Error naming the effect when its
/// class has no Jet form (an effect added with model::Registry::Register alone).
class DifferentiableEffect {
 public:
  explicit DifferentiableEffect(const model::Effect& effect);

  const model::Effect& effect() const { return *effect_; }
  void Apply(const double* theta, const model::SensorInput<double>& in,
             model::SensorOutput<double>& out) const {
    effect_->Apply(theta, in, out);
  }
  void Apply(const Jet* theta, const model::SensorInput<Jet>& in,
             model::SensorOutput<Jet>& out) const {
    jet_term_(*effect_, theta, in, out);
  }

 private:
  const model::Effect* effect_;
  JetTerm jet_term_;
};

/// A model's terms on both scalars, in model order (the model must outlive it).
class DifferentiableModel {
 public:
  explicit DifferentiableModel(const model::Model& model);

  const DifferentiableEffect& term(int i) const { return terms_[static_cast<std::size_t>(i)]; }
  int num_terms() const { return static_cast<int>(terms_.size()); }

  /// Model::Predict on T = double or Jet: `theta[i]` is block i.
  template <typename T>
  model::SensorOutput<T> Predict(const T* const* theta, const model::SensorInput<T>& in) const {
    model::SensorOutput<T> out;
    for (std::size_t i = 0; i < terms_.size(); ++i) terms_[i].Apply(theta[i], in, out);
    return out;
  }

 private:
  std::vector<DifferentiableEffect> terms_;
};

}  // namespace plumb::autodiff

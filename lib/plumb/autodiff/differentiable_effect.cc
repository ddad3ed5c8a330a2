#include "plumb/autodiff/differentiable_effect.h"

#include <mutex>
#include <typeindex>
#include <unordered_map>

#include "plumb/core/error.h"

// The built-in effects' headers, generated from lib/plumb/model/effects/effects.cmake.
#include "plumb/model/effect_list.inc"

namespace plumb::autodiff {
namespace {

/// The Jet terms by effect class, the built-in ones from the start.
class JetTerms {
 public:
  static JetTerms& Global() {
    static JetTerms* terms = new JetTerms;
    return *terms;
  }

  void Register(const std::type_info& effect_class, JetTerm term) {
    std::lock_guard<std::mutex> lock(mutex_);
    terms_.emplace(std::type_index(effect_class), term);
  }

  /// The Jet term of the class of `effect`, or nullptr.
  JetTerm Find(const model::Effect& effect) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = terms_.find(std::type_index(typeid(effect)));
    return it == terms_.end() ? nullptr : it->second;
  }

 private:
  JetTerms() {
#define PLUMB_EFFECT(NAME) \
  terms_.emplace(std::type_index(typeid(model::effects::NAME)), &ApplyOnJets<model::effects::NAME>);
#include "plumb/model/effect_list.inc"
#undef PLUMB_EFFECT
  }

  mutable std::mutex mutex_;
  std::unordered_map<std::type_index, JetTerm> terms_;
};

}  // namespace

void RegisterJetTerm(const std::type_info& effect_class, JetTerm term) {
  JetTerms::Global().Register(effect_class, term);
}

DifferentiableEffect::DifferentiableEffect(const model::Effect& effect)
    : effect_(&effect), jet_term_(JetTerms::Global().Find(effect)) {
  if (jet_term_ == nullptr) {
    throw Error("effect '" + effect.info().name +
                "' has no Jet form, so a fit cannot differentiate it: add it with "
                "plumb::autodiff::RegisterEffect<Class>(name), not model::Registry::Register alone");
  }
}

DifferentiableModel::DifferentiableModel(const model::Model& model) {
  terms_.reserve(model.terms().size());
  for (const auto& term : model.terms()) terms_.emplace_back(*term.effect);
}

}  // namespace plumb::autodiff

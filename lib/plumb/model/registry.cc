#include "plumb/model/registry.h"

#include <algorithm>

#include "plumb/core/error.h"

// The built-in effects' headers, generated from effects/effects.cmake.
#include "plumb/model/effect_list.inc"

namespace plumb::model {

std::vector<ParameterInfo> AxisParameters(const std::string& stem, const std::string& unit,
                                          double typical, double nominal) {
  std::vector<ParameterInfo> p;
  for (const char* axis : kAxisName) p.push_back({stem + "." + axis, unit, typical, nominal});
  return p;
}

Registry& Registry::Global() {
  static Registry* registry = [] {
    auto* r = new Registry;
#define PLUMB_EFFECT(NAME) r->Register(#NAME, &MakeEffect<effects::NAME>);
#include "plumb/model/effect_list.inc"
#undef PLUMB_EFFECT
    return r;
  }();
  return *registry;
}

void Registry::Register(const std::string& name, EffectFactory factory) {
  const bool valid = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
  if (!valid) throw Error("effect name '" + name + "' must be lower-case letters, digits and _");
  if (Contains(name)) throw Error("effect '" + name + "' is registered twice");
  entries_.push_back({name, factory});
}

bool Registry::Contains(const std::string& name) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const Entry& e) { return e.name == name; });
}

std::unique_ptr<Effect> Registry::Make(const std::string& name, const std::string& option) const {
  for (const auto& e : entries_) {
    if (e.name == name) return e.factory(option);
  }
  std::string known;
  for (const auto& e : entries_) known += (known.empty() ? "" : ", ") + e.name;
  throw Error("unknown effect '" + name + "'; known effects: " + known);
}

std::vector<std::string> Registry::Names() const {
  std::vector<std::string> names;
  for (const auto& e : entries_) names.push_back(e.name);
  return names;
}

std::vector<std::string> Registry::CatalogueNames() const {
  std::vector<std::string> names;
  for (const auto& e : entries_) {
    if (!e.factory("")->info().linear_stage) names.push_back(e.name);
  }
  return names;
}

}  // namespace plumb::model

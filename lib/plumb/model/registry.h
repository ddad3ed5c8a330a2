// plumb/model/registry.h — the effect catalogue by name.
//
// Built-in effects are listed once in lib/plumb/model/effects/effects.cmake (one line each);
// CMake generates the registration list from that line and the effect's header
// effects/<name>.h. Programs linking plumb can add their own effects at run time: Register()
// makes them known to models; plumb::autodiff::RegisterEffect<Class>(name) does that and gives
// them the Jet form a fit needs.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "plumb/model/effect.h"

namespace plumb::model {

class Registry {
 public:
  /// The process-wide catalogue, holding the built-in effects.
  static Registry& Global();

  /// Adds an effect; throws plumb::Error if the name is taken or not [a-z0-9_]+.
  void Register(const std::string& name, EffectFactory factory);
  bool Contains(const std::string& name) const;
  /// Makes an effect; throws plumb::Error naming the known effects if `name` is unknown.
  std::unique_ptr<Effect> Make(const std::string& name, const std::string& option = "") const;
  /// Every registered name, in registration order.
  std::vector<std::string> Names() const;
  /// The catalogue effects: every name except the base ones (those whose EffectInfo says
  /// linear_stage: accel_linear, gyro_linear), each asked with its default option.
  std::vector<std::string> CatalogueNames() const;

 private:
  struct Entry {
    std::string name;
    EffectFactory factory;
  };
  std::vector<Entry> entries_;
};

}  // namespace plumb::model

// plumb/report/catalogue.h — the effect catalogue (SPEC section 4) as text and JSON, for
// `plumb effects`: each effect's name, sensor, term in the forward model, what data excites
// it, and its parameters with units and typical sizes.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "plumb/model/registry.h"

namespace plumb::report {

/// The catalogue as text. `only` restricts it to one effect (throws plumb::Error naming the
/// known effects if unknown); empty lists every registered effect, base ones first.
std::string CatalogueText(const model::Registry& registry, const std::string& only = "");

/// The same as JSON: [{name, base, sensor, term, excitation [], parameters [{name, unit,
/// typical}]}].
nlohmann::json CatalogueJson(const model::Registry& registry, const std::string& only = "");

}  // namespace plumb::report

#include "plumb/sim/truth.h"

#include <cmath>
#include <random>

#include "plumb/core/error.h"

namespace plumb::sim {

void SetParameter(const model::Model& model, model::ParameterBlocks& theta,
                  const std::string& full_name, double reported_value) {
  if (theta.empty()) theta = model.ZeroParameters();
  if (theta.size() != static_cast<std::size_t>(model.num_terms())) {
    throw Error("parameter blocks have " + std::to_string(theta.size()) + " blocks; model '" +
                model.spec() + "' has " + std::to_string(model.num_terms()));
  }
  const auto where = model.FindParameter(full_name);
  if (!where) throw Error("model '" + model.spec() + "' has no parameter '" + full_name + "'");
  if (!std::isfinite(reported_value)) {
    throw Error("value of '" + full_name + "' must be finite");
  }
  const auto k = static_cast<std::size_t>(where->first);
  const auto i = static_cast<std::size_t>(where->second);
  const auto& info = model.terms()[k].effect->info();
  if (theta[k].size() != static_cast<std::size_t>(info.size())) {
    throw Error("parameter block of '" + info.name + "' has " + std::to_string(theta[k].size()) +
                " values; expected " + std::to_string(info.size()));
  }
  theta[k][i] = reported_value - info.parameters[i].nominal;
}

model::ParameterBlocks RandomParameters(const model::Model& model, double scale,
                                        std::uint64_t seed) {
  if (!std::isfinite(scale) || scale < 0.0) {
    throw Error("random parameter scale " + Number(scale) + " must be finite and >= 0");
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  model::ParameterBlocks theta = model.ZeroParameters();
  for (std::size_t k = 0; k < theta.size(); ++k) {
    const auto& term = model.terms()[k];
    for (std::size_t i = 0; i < theta[k].size(); ++i) {
      const double draw = normal(rng);  // drawn even when fixed, to keep the sequence stable
      if (!term.fixed[i]) theta[k][i] = scale * term.effect->info().parameters[i].typical * draw;
    }
  }
  return theta;
}

}  // namespace plumb::sim

// plumb/sim/truth.h — filling the true parameter blocks of a simulation by name.
#pragma once

#include <cstdint>
#include <string>

#include "plumb/model/model.h"

namespace plumb::sim {

/// Sets the parameter `full_name` (e.g. "gyro.matrix.xx", "gyro_g_sensitivity.G.xy") so that
/// its reported value (nominal + block value; 1 on the matrix diagonals) is `reported_value`,
/// in the parameter's unit. `theta` is resized to the model's layout first if it is empty.
/// Throws plumb::Error if the name is unknown, the value is not finite or `theta` has the
/// wrong layout.
void SetParameter(const model::Model& model, model::ParameterBlocks& theta,
                  const std::string& full_name, double reported_value);

/// Random true parameters: every parameter that is not held fixed is drawn from
/// N(0, (scale * typical)^2) around its nominal value (typical from the effect's
/// ParameterInfo); fixed ones stay at nominal. Deterministic for a seed. scale >= 0, finite.
model::ParameterBlocks RandomParameters(const model::Model& model, double scale,
                                        std::uint64_t seed);

}  // namespace plumb::sim

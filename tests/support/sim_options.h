// The simulator's default MEMS sensor (sim::SimulationOptions::TypicalMems) at 100 Hz with
// random true parameters (scale 1), at a known site, all seeded by `seed`: the session most
// estimation tests start from.
#pragma once

#include <cstdint>

#include "plumb/geo/site.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb::testing {

inline sim::SimulationOptions TypicalMemsAt(const geo::Site& site, std::uint64_t seed) {
  sim::SimulationOptions opt = sim::SimulationOptions::TypicalMems();
  opt.rate_hz = 100.0;
  opt.truth = sim::RandomParameters(opt.model, 1.0, seed);
  opt.site = site;
  opt.seed = seed;
  return opt;
}

}  // namespace plumb::testing

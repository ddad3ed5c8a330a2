// plumb/core/datasheet_level.h — the bias wander levels (estimation/options.h: the random
// walk densities and the Gauss-Markov instability) as a datasheet states them, e.g. "4 deg/h"
// or "40ug", turned into SI numbers: one parser for the four levels as the command line and
// the Python module take them (Option::kAccelWalk ... kGyroInstability) and a study file's
// keys and factors of the same names (study/study.h). It needs only units.h and error.h, so it
// sits in core, below every module that reads a level.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace plumb {

/// Which level: the accelerometer's or gyroscope's bias random walk density, or its bias
/// instability (Gauss-Markov sigma).
enum class WanderLevel { kAccelWalk, kGyroWalk, kAccelInstability, kGyroInstability };

/// The units `level` may be given in, as (name, SI per unit), the SI unit first:
///   accelerometer walk m/s^3/sqrt(Hz), m/s^2/sqrt(s), ug/sqrt(s), ug/sqrt(h);
///   gyroscope walk rad/s^2/sqrt(Hz), rad/s/sqrt(s), deg/s/sqrt(s), deg/h/sqrt(h);
///   accelerometer instability m/s^2, ug, mg; gyroscope instability rad/s, deg/s, deg/h.
const std::vector<std::pair<std::string, double>>& DatasheetUnits(WanderLevel level);

/// `text`, a finite number >= 0 with an optional unit of DatasheetUnits(level) (blanks
/// ignored), in SI; without a unit the number is SI (sensor units for unscaled samples).
/// Throws plumb::Error whose message names no option ("must be a number >= 0 with an optional
/// unit (...), got '...'"), for the front end to prefix with its own name of the option.
double ParseDatasheetLevel(const std::string& text, WanderLevel level);

}  // namespace plumb

// plumb/estimation/options.cc — see options.h.
#include "plumb/estimation/options.h"

#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "plumb/core/error.h"

namespace plumb::estimation {
namespace {

/// Throws plumb::Error "calibration option NAME = VALUE must be RANGE" unless `ok`.
void Require(bool ok, const char* name, double value, const char* range) {
  if (!ok) {
    throw Error(std::string("calibration option ") + name + " = " + Number(value) + " must be " +
                range);
  }
}

bool FiniteAtLeastZero(const std::optional<double>& level) {
  return !level || (std::isfinite(*level) && *level >= 0.0);
}

}  // namespace

void CalibrationOptions::Validate() const {
  Require(std::isfinite(max_motion_s) && max_motion_s > 0.0, "max_motion_s", max_motion_s,
          "finite and > 0 s");
  if (first_heading_deg) {
    Require(std::isfinite(*first_heading_deg), "first_heading_deg", *first_heading_deg,
            "finite");
  }
  Require(rank_tolerance > 0.0 && rank_tolerance < 1.0, "rank_tolerance", rank_tolerance,
          "in (0, 1)");
  Require(min_segment_samples >= 1, "min_segment_samples", min_segment_samples, ">= 1");
  for (const auto& [name, level] : {std::pair{"accel_walk_density", accel_walk_density},
                                    std::pair{"gyro_walk_density", gyro_walk_density},
                                    std::pair{"accel_instability", accel_instability},
                                    std::pair{"gyro_instability", gyro_instability}}) {
    Require(FiniteAtLeastZero(level), name, level.value_or(0.0), "finite and >= 0");
  }
  Require(std::isfinite(instability_time_s) && instability_time_s > 0.0, "instability_time_s",
          instability_time_s, "finite and > 0 s");
  Require(walk_min_poses >= 2, "walk_min_poses", walk_min_poses, ">= 2");
  Require(min_sigma_acc > 0.0 && std::isfinite(min_sigma_acc), "min_sigma_acc", min_sigma_acc,
          "finite and > 0");
  Require(min_sigma_gyr > 0.0 && std::isfinite(min_sigma_gyr), "min_sigma_gyr", min_sigma_gyr,
          "finite and > 0");
  Require(max_iterations >= 1, "max_iterations", max_iterations, ">= 1");
  Require(function_tolerance > 0.0 && function_tolerance < 1.0, "function_tolerance",
          function_tolerance, "in (0, 1)");
  Require(parameter_tolerance > 0.0 && parameter_tolerance < 1.0, "parameter_tolerance",
          parameter_tolerance, "in (0, 1)");
}

}  // namespace plumb::estimation

// CalibrationOptions::Validate: the defaults pass; each field out of its documented range is
// an error that names it.
#include "plumb/estimation/options.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "plumb/core/error.h"

namespace plumb::estimation {
namespace {

TEST(CalibrationOptions, TheDefaultsAreInRange) { EXPECT_NO_THROW(CalibrationOptions().Validate()); }

TEST(CalibrationOptions, EachFieldOutOfRangeIsNamed) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<std::pair<std::string, std::function<void(CalibrationOptions&)>>> cases = {
      {"max_motion_s", [](CalibrationOptions& o) { o.max_motion_s = 0.0; }},
      {"first_heading_deg", [&](CalibrationOptions& o) { o.first_heading_deg = nan; }},
      {"rank_tolerance", [](CalibrationOptions& o) { o.rank_tolerance = 1.0; }},
      {"min_segment_samples", [](CalibrationOptions& o) { o.min_segment_samples = 0; }},
      {"accel_walk_density", [](CalibrationOptions& o) { o.accel_walk_density = -1e-4; }},
      {"gyro_walk_density", [](CalibrationOptions& o) { o.gyro_walk_density = INFINITY; }},
      {"accel_instability", [&](CalibrationOptions& o) { o.accel_instability = nan; }},
      {"gyro_instability", [](CalibrationOptions& o) { o.gyro_instability = -1.0; }},
      {"instability_time_s", [](CalibrationOptions& o) { o.instability_time_s = 0.0; }},
      {"walk_min_poses", [](CalibrationOptions& o) { o.walk_min_poses = 1; }},
      {"min_sigma_acc", [](CalibrationOptions& o) { o.min_sigma_acc = 0.0; }},
      {"min_sigma_gyr", [&](CalibrationOptions& o) { o.min_sigma_gyr = nan; }},
      {"max_iterations", [](CalibrationOptions& o) { o.max_iterations = 0; }},
      {"function_tolerance", [](CalibrationOptions& o) { o.function_tolerance = 0.0; }},
      {"parameter_tolerance", [](CalibrationOptions& o) { o.parameter_tolerance = 2.0; }},
  };
  for (const auto& [field, set] : cases) {
    SCOPED_TRACE(field);
    CalibrationOptions o;
    set(o);
    try {
      o.Validate();
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr("calibration option " + field + " = "));
    }
  }
}

TEST(CalibrationOptions, ZeroWanderLevelsAndAHeadingAreInRange) {
  CalibrationOptions o;
  o.accel_walk_density = 0.0;
  o.gyro_instability = 0.0;
  o.first_heading_deg = -90.0;
  EXPECT_NO_THROW(o.Validate());
}

}  // namespace
}  // namespace plumb::estimation

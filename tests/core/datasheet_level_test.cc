// core/datasheet_level.h: the bias wander levels as a datasheet states them, in SI; errors that
// name no option (each front end and the study reader put their own name before them).
#include "plumb/core/datasheet_level.h"

#include <gtest/gtest.h>

#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb {
namespace {

std::string LevelError(const std::string& text, WanderLevel level) {
  try {
    ParseDatasheetLevel(text, level);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(DatasheetLevel, UnitsBecomeSi) {
  EXPECT_DOUBLE_EQ(ParseDatasheetLevel("4 deg/h", WanderLevel::kGyroInstability),
                   4.0 / units::kDegPerHourPerRadPerS);
  EXPECT_DOUBLE_EQ(ParseDatasheetLevel("40ug", WanderLevel::kAccelInstability),
                   40.0 * units::kMicroG);
  EXPECT_DOUBLE_EQ(ParseDatasheetLevel("2 mg", WanderLevel::kAccelInstability),
                   2.0 * units::kMilliG);
  EXPECT_DOUBLE_EQ(ParseDatasheetLevel("10 ug/sqrt(h)", WanderLevel::kAccelWalk),
                   10.0 * units::kMicroG / units::kSqrtSecondsPerSqrtHour);
  EXPECT_DOUBLE_EQ(ParseDatasheetLevel("0.5 deg/s/sqrt(s)", WanderLevel::kGyroWalk),
                   0.5 * units::kRadPerDeg);
  EXPECT_DOUBLE_EQ(ParseDatasheetLevel("1e-4", WanderLevel::kAccelWalk), 1e-4);
  EXPECT_DOUBLE_EQ(ParseDatasheetLevel("0", WanderLevel::kGyroWalk), 0.0);
}

TEST(DatasheetLevel, ErrorsNameNoOption) {
  EXPECT_EQ(LevelError("4 deg/h", WanderLevel::kAccelInstability),
            "unit 'deg/h' not known here; use one of m/s^2, ug, mg (got '4 deg/h')");
  EXPECT_EQ(LevelError("-1", WanderLevel::kGyroInstability),
            "must be a finite number >= 0 (got '-1')");
  EXPECT_EQ(LevelError("nan", WanderLevel::kGyroInstability),
            "must be a finite number >= 0 (got 'nan')");
  EXPECT_EQ(LevelError("fast", WanderLevel::kGyroInstability),
            "must be a number >= 0 with an optional unit (rad/s, deg/s, deg/h), got 'fast'");
}

}  // namespace
}  // namespace plumb

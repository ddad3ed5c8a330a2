// A session from samples in memory (io/input/array_session.h): the checks a reader makes, the
// units turned into SI once, rows dropped on request, and errors named in the front end's words.
#include "plumb/io/input/array_session.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb::io {
namespace {

/// Four rows at 100 Hz, level, turning slowly about z, 25 degC.
struct Rows {
  std::vector<double> time{0.0, 0.01, 0.02, 0.03};
  std::vector<double> acc{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};  // g
  std::vector<double> gyr{0, 0, 10, 0, 0, 10, 0, 0, 10, 0, 0, 10};  // deg/s
  std::vector<double> temp{25, 25, 25, 25};

  ArraySamples Samples() const {
    ArraySamples a;
    a.n = time.size();
    a.time = time.data();
    a.acc = acc.data();
    a.gyr = gyr.data();
    a.temp = temp.data();
    a.acc_unit = AccUnit::kStandardGravity;
    a.gyr_unit = GyrUnit::kDegreesPerSecond;
    a.source = "arrays";
    return a;
  }
};

TEST(SessionFromArrays, ConvertsTheUnitsOnceAsATableDoes) {
  const Rows rows;
  const Session s = SessionFromArrays(rows.Samples(), ArrayNames{});
  ASSERT_EQ(s.series.size(), 4u);
  EXPECT_EQ(s.source, "arrays");
  EXPECT_EQ(s.series.acc[2].z(), static_cast<float>(units::kStandardGravity));
  EXPECT_EQ(s.series.gyr[3].z(), static_cast<float>(10 * units::kRadPerDeg));
  EXPECT_EQ(s.series.t_s[1], 0.01);
  ASSERT_EQ(s.series.temp_c.size(), 4u);
  EXPECT_EQ(s.series.temp_c[0], 25.0f);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(SessionFromArrays, WithoutGyroscopeOrTemperatureTheSeriesHasNone) {
  const Rows rows;
  ArraySamples a = rows.Samples();
  a.gyr = nullptr;
  a.temp = nullptr;
  const Session s = SessionFromArrays(a, ArrayNames{});
  EXPECT_TRUE(s.series.gyr.empty());
  EXPECT_TRUE(s.series.temp_c.empty());
  EXPECT_EQ(s.series.size(), 4u);
}

TEST(SessionFromArrays, ANonFiniteValueNamesTheArrayAndRowInTheFrontEndsWords) {
  Rows rows;
  rows.gyr[3 * 2 + 1] = std::numeric_limits<double>::quiet_NaN();
  ArrayNames names;
  names.gyr = "gyro";
  names.first_row = 1;  // a table's numbering
  try {
    SessionFromArrays(rows.Samples(), names);
    FAIL() << "a NaN was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "arrays");
    EXPECT_EQ(e.where(), "gyro row 3");
    ASSERT_EQ(e.options().size(), 1u);
    EXPECT_EQ(e.options()[0], Option::kDropNan);
  }
  ArraySamples a = rows.Samples();
  a.drop_nan_rows = true;
  const Session s = SessionFromArrays(a, names);
  EXPECT_EQ(s.series.size(), 3u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].code, "nan_rows_skipped");
  EXPECT_NE(s.warnings[0].message.find("gyro row 3"), std::string::npos) << s.warnings[0].message;
}

TEST(SessionFromArrays, TimesMustIncreaseAndTwoSamplesRemain) {
  Rows rows;
  rows.time[2] = rows.time[1];
  try {
    SessionFromArrays(rows.Samples(), ArrayNames{});
    FAIL() << "a repeated time was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "time row 2");
    EXPECT_NE(std::string(e.what()).find("repeats"), std::string::npos) << e.what();
  }
  Rows few;
  few.acc.assign(12, std::numeric_limits<double>::infinity());
  few.acc[0] = 0.0;  // row 0 still has infinities on y and z
  ArraySamples a = few.Samples();
  a.drop_nan_rows = true;
  EXPECT_THROW(SessionFromArrays(a, ArrayNames{}), InputError);
}

}  // namespace
}  // namespace plumb::io

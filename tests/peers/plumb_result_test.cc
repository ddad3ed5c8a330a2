// Reading back `plumb calibrate --json`: the keys a comparison needs, and errors that name the
// file and the key.
#include "plumb/peers/plumb_result.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "temp_files.h"

namespace plumb::peers {
namespace {

using nlohmann::json;
using testing::ErrorOf;
using testing::TempFolder;

/// A small document with the keys and layout of json_report.cc.
json SmallResult() {
  return json{
      {"method", "generalized"},
      {"model", "base"},
      {"accel", {{"matrix", {{2.0, 0.1, 0.0}, {0.0, 3.0, 0.2}, {0.0, 0.0, 4.0}}}, {"bias", {1.0, 2.0, 3.0}}}},
      {"gyro", {{"matrix", {{5.0, 0.0, 0.0}, {0.0, 6.0, 0.0}, {0.0, 0.0, 7.0}}}, {"bias", {-1.0, -2.0, -3.0}}}},
      {"parameters",
       {{{"name", "accel.matrix.xx"}, {"value", 2.0}, {"sigma", 0.01}, {"observable", true}, {"fixed", false}, {"unit", "1"}},
        {{"name", "accel.bias.z"}, {"value", 3.0}, {"sigma", nullptr}, {"observable", false}, {"fixed", false}, {"unit", "m/s^2"}}}},
      {"fit", {{"chi2", 50.0}, {"dof", 10}, {"chi2_dof", 5.0}}},
      {"site", {{"gravity", 9.81}, {"source", "none"}, {"lat_deg", nullptr}}},
      {"noise", {{"accel", {0.1, 0.2, 0.3}}, {"gyro", {0.01, 0.02, 0.03}}}},
      {"segments", {{{"label", "still #1"}, {"count", 400}, {"acc_mean", {1.0, 2.0, 40.0}}}}},
      {"inputs", {"a.csv"}}};
}

TEST(PlumbResult, ReadsTheKeysAComparisonNeeds) {
  const TempFolder dir;
  const PlumbResult r = ReadPlumbResult(dir.Write("r.json", SmallResult().dump(2)));
  EXPECT_EQ(r.method, "generalized");
  EXPECT_EQ(r.model_spec, "base");
  EXPECT_EQ(r.accel_matrix(0, 1), 0.1);
  EXPECT_EQ(r.accel_matrix(1, 2), 0.2);
  EXPECT_EQ(r.accel_bias, Vec3(1, 2, 3));
  ASSERT_TRUE(r.has_gyro);
  EXPECT_EQ(r.gyro_matrix(2, 2), 7.0);
  EXPECT_EQ(r.gyro_bias, Vec3(-1, -2, -3));
  ASSERT_EQ(r.parameters.size(), 2u);
  EXPECT_EQ(r.parameters[0].name, "accel.matrix.xx");
  EXPECT_EQ(r.parameters[0].sigma, 0.01);
  EXPECT_FALSE(r.parameters[1].sigma.has_value());
  EXPECT_FALSE(r.parameters[1].observable);
  EXPECT_EQ(r.parameters[1].unit, "m/s^2");
  ASSERT_EQ(r.segments.size(), 1u);
  EXPECT_EQ(r.segments[0].acc_mean, Vec3(1, 2, 40));
  EXPECT_EQ(r.segments[0].count, 400.0);
  EXPECT_EQ(r.gravity_m_s2, 9.81);
  EXPECT_EQ(r.chi2_dof, 5.0);
  EXPECT_EQ(r.dof, 10);
  EXPECT_EQ(r.noise_accel, Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(r.inputs, std::vector<std::string>{"a.csv"});
  EXPECT_EQ(FindParameter(r, "accel.bias.z"), &r.parameters[1]);
  EXPECT_EQ(FindParameter(r, "gyro.bias.z"), nullptr);
}

TEST(PlumbResult, WithoutGyroscopeOrSegments) {
  json doc = SmallResult();
  doc["gyro"] = nullptr;
  doc.erase("segments");
  const TempFolder dir;
  const PlumbResult r = ReadPlumbResult(dir.Write("r.json", doc.dump()));
  EXPECT_FALSE(r.has_gyro);
  EXPECT_TRUE(r.segments.empty());
}

TEST(PlumbResult, ErrorsNameTheFileAndTheKey) {
  const TempFolder dir;
  json doc = SmallResult();
  doc["accel"]["matrix"][2] = {0.0, 0.0};
  std::string path = dir.Write("rows.json", doc.dump());
  std::string message = ErrorOf([&] { ReadPlumbResult(path); });
  EXPECT_NE(message.find(path + ":key 'accel.matrix[2]'"), std::string::npos) << message;

  doc = SmallResult();
  doc["segments"][0].erase("acc_mean");
  path = dir.Write("seg.json", doc.dump());
  message = ErrorOf([&] { ReadPlumbResult(path); });
  EXPECT_NE(message.find(path + ":key 'segments[0].acc_mean'"), std::string::npos) << message;

  doc = SmallResult();
  doc.erase("parameters");
  path = dir.Write("params.json", doc.dump());
  message = ErrorOf([&] { ReadPlumbResult(path); });
  EXPECT_NE(message.find(path + ":key 'parameters'"), std::string::npos) << message;

  path = dir.Write("text.json", "not json");
  message = ErrorOf([&] { ReadPlumbResult(path); });
  EXPECT_NE(message.find(path + ":line 1, column 2: not valid JSON: syntax error while parsing "
                                "value - invalid literal; last read: 'no'"),
            std::string::npos)
      << message;
}

// Issue 35 item 5: what no calibration can be is refused, the key named (a negative sigma
// printed as "-1" and "error/sigma -0.00"; a repeated name shifted the mapping).
TEST(PlumbResult, WhatNoCalibrationCanBeIsRefused) {
  const TempFolder dir;
  json doc = SmallResult();
  doc["parameters"][0]["sigma"] = -1.0;
  std::string path = dir.Write("sigma.json", doc.dump());
  EXPECT_EQ(ErrorOf([&] { ReadPlumbResult(path); }),
            path + ":key 'parameters[0].sigma': expected a standard deviation >= 0, not -1.0");

  doc = SmallResult();
  doc["parameters"][1]["name"] = "accel.matrix.xx";
  path = dir.Write("twice.json", doc.dump());
  EXPECT_EQ(ErrorOf([&] { ReadPlumbResult(path); }),
            path + ":key 'parameters[1].name': 'accel.matrix.xx' given twice (first at "
                   "parameters[0])");

  doc = SmallResult();
  doc["gyro"]["matrix"] = {{5.0, 0.0, 0.0}, {5.0, 0.0, 0.0}, {0.0, 0.0, 7.0}};
  path = dir.Write("singular.json", doc.dump());
  EXPECT_EQ(ErrorOf([&] { ReadPlumbResult(path); }),
            path + ":key 'gyro.matrix': the matrix is singular (it maps some input to zero): "
                   "not a sensor's calibration");

  doc = SmallResult();
  doc["covariance"] = {{"parameters", {"accel.matrix.xx", "accel.matrix.xx"}},
                       {"matrix", {{1e-4, 0.0}, {0.0, 1e-4}}}};
  path = dir.Write("cov_twice.json", doc.dump());
  EXPECT_EQ(ErrorOf([&] { ReadPlumbResult(path); }),
            path + ":key 'covariance.parameters[1]': 'accel.matrix.xx' given twice (first at [0])");

  doc = SmallResult();
  doc["covariance"] = {{"parameters", {"accel.matrix.xx", "accel.bias.z"}},
                       {"matrix", {{-1e-4, 0.0}, {0.0, 1e-4}}}};
  path = dir.Write("cov_negative.json", doc.dump());
  EXPECT_EQ(ErrorOf([&] { ReadPlumbResult(path); }),
            path + ":key 'covariance.matrix': the covariance has a negative variance on row 0 "
                   "(-0.0001)");
}

}  // namespace
}  // namespace plumb::peers

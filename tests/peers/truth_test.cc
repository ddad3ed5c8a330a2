// A calibration against a simulated session's truth (plumb/peers/truth.h): errors in sigmas,
// the NEES over the full covariance, and what is said when it cannot be computed.
#include "plumb/peers/truth.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "temp_files.h"

namespace plumb::peers {
namespace {

using nlohmann::json;
using testing::ErrorOf;
using testing::TempFolder;

/// Two parameters, errors (1, 2) against the truth (0, 10), covariance [[4, 2], [2, 9]].
json Result(const json& covariance) {
  return json{{"method", "generalized"},
              {"accel", {{"matrix", {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, {"bias", {0, 0, 0}}}},
              {"parameters",
               {{{"name", "accel.bias.x"}, {"value", 1.0}, {"sigma", 2.0}, {"unit", "m/s^2"}},
                {{"name", "accel.bias.y"}, {"value", 12.0}, {"sigma", 3.0}, {"unit", "m/s^2"}},
                {{"name", "accel.bias.z"}, {"value", 7.0}, {"sigma", 0.5}, {"unit", "m/s^2"}}}},
              {"covariance", covariance}};
}

const json kTruth = {{"parameters",
                      {{{"name", "accel.bias.x"}, {"value", 0.0}, {"unit", "m/s^2"}},
                       {{"name", "accel.bias.y"}, {"value", 10.0}, {"unit", "m/s^2"}},
                       {{"name", "accel.bias.z"}, {"value", 5.0}, {"unit", "m/s^2"}}}}};

TEST(Truth, NeesUsesTheFullCovariance) {
  const TempFolder dir;
  const json cov = {{"parameters", {"accel.bias.x", "accel.bias.y"}},
                    {"matrix", {{4.0, 2.0}, {2.0, 9.0}}},
                    {"sigma_scaled_by_chi2", false}};
  const std::string truth = dir.Write("t.json", kTruth.dump());
  const TruthComparison c = CompareWithTruth(
      ReadPlumbResult(dir.Write("r.json", Result(cov).dump())), ReadSimulationTruth(truth), truth);
  // e = (1, 2): e^T C^-1 e = (9 - 8 + 16) / 32 = 17 / 32 (C^-1 = [[9, -2], [-2, 4]] / 32).
  ASSERT_TRUE(c.nees.has_value()) << c.nees_note;
  EXPECT_NEAR(*c.nees, 17.0 / 32.0, 1e-12);
  EXPECT_EQ(c.nees_dof, 2);
  EXPECT_NEAR(c.band_low, 0.0506356, 1e-6);  // chi^2(2) 2.5 % and 97.5 %
  EXPECT_NEAR(c.band_high, 7.3777589, 1e-6);
  ASSERT_EQ(c.rows.size(), 3U);
  EXPECT_EQ(c.beyond_3_sigma, 1);  // accel.bias.z: 2 / 0.5
  EXPECT_NE(TruthComparisonText(c).find("NEES 0.5 on 2 parameters (full covariance): chi^2(2) "
                                        "95% band 0.1 .. 7.4, inside"),
            std::string::npos)
      << TruthComparisonText(c);
  EXPECT_EQ(TruthComparisonJson(c)["nees"]["dof"], 2);
}

TEST(Truth, SaysWhyThereIsNoNees) {
  const TempFolder dir;
  const std::string truth = dir.Write("t.json", kTruth.dump());
  const auto nees_note = [&](const json& cov) {
    json r = Result(cov);
    if (cov.is_null()) r.erase("covariance");
    // The sigma column would disagree with these covariances (a file changed after it was
    // written is refused): without it, only the covariance speaks.
    for (json& p : r["parameters"]) p.erase("sigma");
    return CompareWithTruth(ReadPlumbResult(dir.Write("r.json", r.dump())),
                            ReadSimulationTruth(truth), truth)
        .nees_note;
  };
  EXPECT_NE(nees_note(nullptr).find("no covariance in"), std::string::npos);
  EXPECT_EQ(nees_note({{"parameters", {"accel.bias.x", "gyro.bias.x"}},
                       {"matrix", {{1.0, 0.0}, {0.0, 1.0}}}}),
            "the covariance's parameter gyro.bias.x has no truth: no NEES");
  EXPECT_EQ(nees_note({{"parameters", {"accel.bias.x", "accel.bias.y"}},
                       {"matrix", {{1.0, 1.0}, {1.0, 1.0}}}}),
            "the covariance is not positive definite: no NEES");
  // One that is no covariance at all (an eigenvalue -1) is refused as the file is read
  // (issue 35 item 5).
  EXPECT_NE(ErrorOf([&] {
              nees_note({{"parameters", {"accel.bias.x", "accel.bias.y"}},
                         {"matrix", {{1.0, 2.0}, {2.0, 1.0}}}});
            }).find(":key 'covariance.matrix': the covariance is not positive semidefinite"),
            std::string::npos);
}

TEST(Truth, BadFilesNameTheFileAndKey) {
  const TempFolder dir;
  const std::string bad = dir.Write("t.json", R"({"parameters": [{"name": "a", "value": "x"}]})");
  EXPECT_NE(ErrorOf([&] { ReadSimulationTruth(bad); }).find("parameters[0].value"),
            std::string::npos);
  const std::string ragged =
      dir.Write("r.json", Result({{"parameters", {"accel.bias.x"}}, {"matrix", {{1.0, 2.0}}}}).dump());
  EXPECT_NE(ErrorOf([&] { ReadPlumbResult(ragged); }).find("covariance.matrix[0]"),
            std::string::npos);
}

}  // namespace
}  // namespace plumb::peers

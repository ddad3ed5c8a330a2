// The calibrate --json document (SPEC section 6): keys, nulls for non-finite values, the
// correction matrices, the site, effects, segments, and the atomic write.
#include "plumb/report/json_report.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "plumb/core/error.h"
#include "report_test_util.h"

namespace plumb::report {
namespace {

using nlohmann::json;
using testing::MakeResult;

const json* FindParameter(const json& doc, const std::string& name) {
  for (const auto& p : doc.at("parameters")) {
    if (p.at("name") == name) return &p;
  }
  return nullptr;
}

Mat3 ReadMatrix(const json& rows) {
  Mat3 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = rows.at(r).at(c).get<double>();
  }
  return m;
}

/// True when no number anywhere in `j` is NaN or infinite.
bool AllNumbersFinite(const json& j) {
  if (j.is_number_float()) return std::isfinite(j.get<double>());
  if (j.is_structured()) {
    for (const auto& item : j) {
      if (!AllNumbersFinite(item)) return false;
    }
  }
  return true;
}

segmentation::SegmentationResult GivenSegmentation() {
  segmentation::SegmentationResult s;
  s.segments.resize(2);
  s.report.method = "given";
  return s;
}

TEST(JsonReport, HasEverySpecKey) {
  const json doc = ToJson(MakeResult());
  for (const char* key :
       {"plumb_version", "method", "model", "accel", "gyro", "effects", "parameters", "fit",
        "observability", "site", "noise", "segments", "motion", "warnings"}) {
    EXPECT_TRUE(doc.contains(key)) << key;
  }
  EXPECT_EQ(doc["method"], "generalized");
  EXPECT_EQ(doc["model"], "base+gyro_g_sensitivity");
  for (const char* sensor : {"accel", "gyro"}) {
    EXPECT_EQ(doc[sensor]["matrix"].size(), 3u);
    EXPECT_EQ(doc[sensor]["matrix"][0].size(), 3u);
    EXPECT_EQ(doc[sensor]["bias"].size(), 3u);
  }
  for (const char* key :
       {"chi2", "dof", "chi2_dof", "residual_rms", "segments", "converged", "iterations"}) {
    EXPECT_TRUE(doc["fit"].contains(key)) << key;
  }
  EXPECT_EQ(doc["fit"]["segments"]["still"], 2);
  EXPECT_EQ(doc["fit"]["segments"]["motion"], 1);
  for (const char* key : {"rank", "unknowns", "unobservable", "determined"}) {
    EXPECT_TRUE(doc["observability"].contains(key)) << key;
  }
  EXPECT_EQ(doc["observability"]["determined"][0]["combination"],
            "accel.bias.z - 9.81 accel.matrix.zz");
  EXPECT_EQ(doc["parameters"].size(), 30u);
}

TEST(JsonReport, ForwardQuantitiesAreWrittenAsGiven) {
  const auto r = MakeResult();
  const json doc = ToJson(r);
  EXPECT_TRUE(ReadMatrix(doc["accel"]["matrix"]).isApprox(r.calibration.AccelMatrix(), 1e-15));
  EXPECT_TRUE(ReadMatrix(doc["gyro"]["matrix"]).isApprox(r.calibration.GyroMatrix(), 1e-15));
  EXPECT_DOUBLE_EQ(doc["accel"]["bias"][2].get<double>(), 0.3);
  EXPECT_DOUBLE_EQ(doc["gyro"]["bias"][1].get<double>(), 0.02);
}

TEST(JsonReport, UnobservableAndFixedSigmasAndNaNBecomeNull) {
  const json doc = ToJson(MakeResult());
  const json* lost = FindParameter(doc, "accel.bias.z");
  ASSERT_NE(lost, nullptr);
  EXPECT_TRUE((*lost)["sigma"].is_null());
  EXPECT_EQ((*lost)["observable"], false);
  const json* fixed = FindParameter(doc, "gyro_g_sensitivity.G.zz");
  ASSERT_NE(fixed, nullptr);
  EXPECT_TRUE((*fixed)["sigma"].is_null());
  EXPECT_EQ((*fixed)["fixed"], true);
  EXPECT_DOUBLE_EQ((*FindParameter(doc, "accel.bias.x"))["sigma"].get<double>(), 1e-3);
  EXPECT_TRUE(doc["fit"]["chi2_dof"].is_null());  // dof = 0
  EXPECT_TRUE(AllNumbersFinite(doc));
}

TEST(JsonReport, TextNeverHoldsNaNAndParsesBack) {
  auto r = MakeResult();
  r.fit.rms_motion = Vec3::Constant(std::numeric_limits<double>::infinity());
  r.calibration.noise.acc.x() = std::numeric_limits<double>::quiet_NaN();
  const std::string text = ToJson(r).dump();
  EXPECT_EQ(text.find("NaN"), std::string::npos);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
  const json back = json::parse(text);
  EXPECT_TRUE(back["fit"]["residual_rms"]["motion"][0].is_null());
  EXPECT_TRUE(back["noise"]["accel"][0].is_null());
}

TEST(JsonReport, CorrectionInvertsTheForwardModel) {
  const auto r = MakeResult();
  const json doc = ToJson(r);
  for (const char* sensor : {"accel", "gyro"}) {
    const json& c = doc[sensor]["correction"];
    const Mat3 forward = ReadMatrix(doc[sensor]["matrix"]);
    EXPECT_TRUE((ReadMatrix(c["matrix"]) * forward).isApprox(Mat3::Identity(), 1e-12)) << sensor;
    EXPECT_EQ(c["offset"], doc[sensor]["bias"]) << sensor;
    EXPECT_TRUE(c.contains("formula")) << sensor;
  }
  // Only the gyroscope carries an extra effect: its correction says so.
  EXPECT_FALSE(doc["accel"]["correction"].contains("note"));
  EXPECT_NE(doc["gyro"]["correction"]["note"].get<std::string>().find("gyro_g_sensitivity"),
            std::string::npos);
}

TEST(JsonReport, SingularForwardMatrixGivesNullCorrection) {
  auto r = MakeResult();
  r.calibration.theta[0][5] = -1.0;  // F(2, 2) = 1 + block[5] = 0: F singular
  const json doc = ToJson(r);
  EXPECT_TRUE(doc["accel"]["correction"]["matrix"].is_null());
}

TEST(JsonReport, NoSiteHasNullCoordinatesAndSourceNone) {
  const json site = ToJson(MakeResult())["site"];
  EXPECT_TRUE(site["lat_deg"].is_null());
  EXPECT_TRUE(site["lon_deg"].is_null());
  EXPECT_TRUE(site["height_m"].is_null());
  EXPECT_EQ(site["source"], "none");
  EXPECT_DOUBLE_EQ(site["gravity"].get<double>(), 9.80665);
}

TEST(JsonReport, GivenSiteIsWrittenInDegrees) {
  auto r = MakeResult();
  r.calibration.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
  const json site = ToJson(r)["site"];
  EXPECT_DOUBLE_EQ(site["lat_deg"].get<double>(), 51.64);
  EXPECT_DOUBLE_EQ(site["lon_deg"].get<double>(), -1.2);
  EXPECT_DOUBLE_EQ(site["height_m"].get<double>(), 100.0);
  EXPECT_EQ(site["source"], "flags");
  EXPECT_NEAR(site["gravity"].get<double>(), 9.81, 0.01);
}

TEST(JsonReport, EffectsHoldOnlyNonBaseEffectsInBlockOrder) {
  const json effects = ToJson(MakeResult())["effects"];
  EXPECT_FALSE(effects.contains("accel_linear"));
  EXPECT_FALSE(effects.contains("gyro_linear"));
  ASSERT_TRUE(effects.contains("gyro_g_sensitivity"));
  const json& g = effects["gyro_g_sensitivity"];
  ASSERT_EQ(g["parameters"].size(), 9u);
  ASSERT_EQ(g["sigma"].size(), 9u);
  EXPECT_EQ(g["names"][1], "gyro_g_sensitivity.G.xy");
  // The hand-made result gives parameter i the value 0.01 i; G.xx is parameter 21.
  EXPECT_DOUBLE_EQ(g["parameters"][0].get<double>(), 0.21);
  EXPECT_TRUE(g["sigma"][8].is_null());  // G.zz is fixed
  EXPECT_EQ(g["unit"], "rad/s per m/s^2");
}

TEST(JsonReport, SegmentsCarryResidualsAndAttitude) {
  const auto r = MakeResult();
  const json segments = ToJson(r)["segments"];
  ASSERT_EQ(segments.size(), 2u);
  const json& s = segments[1];
  EXPECT_EQ(s["label"], "pose 2");
  EXPECT_EQ(s["begin"], 100);
  EXPECT_EQ(s["end"], 150);
  EXPECT_DOUBLE_EQ(s["t_mid_s"].get<double>(), 101.25);
  EXPECT_DOUBLE_EQ(s["acc_whitened"][2].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(s["gyr_residual"][2].get<double>(), -3e-5);
  const Quat& q = r.fit.still[1].R_n_b;
  EXPECT_DOUBLE_EQ(s["attitude_quaternion_wxyz"][0].get<double>(), q.w());
  EXPECT_DOUBLE_EQ(s["attitude_quaternion_wxyz"][3].get<double>(), q.z());
  EXPECT_EQ(s["attitude_known"], false);
  EXPECT_EQ(segments[0]["attitude_known"], true);
}

TEST(JsonReport, AccelerometerOnlyResultHasNullGyro) {
  auto r = MakeResult();
  r.calibration.has_gyro = false;
  const json doc = ToJson(r);
  EXPECT_TRUE(doc["gyro"].is_null());
  EXPECT_TRUE(doc["fit"]["residual_rms"]["gyro"].is_null());
  EXPECT_TRUE(doc["segments"][0]["gyr_residual"].is_null());
}

TEST(JsonReport, CalibrationJsonAddsSegmentationInputsAndReaderWarningsFirst) {
  const json doc =
      CalibrationJson(MakeResult(), GivenSegmentation(), {"a.csv"},
                      {Notice{"nan_rows_skipped", "a.csv: 3 rows dropped", {}}});
  EXPECT_EQ(doc["inputs"], json::array({"a.csv"}));
  EXPECT_EQ(doc["segmentation"]["method"], "given");
  EXPECT_EQ(doc["segmentation"]["segments"], 2);
  EXPECT_TRUE(doc["segmentation"]["noise"].is_null());
  ASSERT_EQ(doc["warnings"].size(), 2u);
  EXPECT_EQ(doc["warnings"][0], "a.csv: 3 rows dropped");
  EXPECT_EQ(doc["warnings"][1], "no site given");
}

TEST(JsonReport, DetectedSegmentationReportsNoiseAndThresholds) {
  segmentation::SegmentationResult s;
  s.report.method = "detected";
  s.report.window_s = 1.0;
  s.noise.periods.resize(1);
  s.noise.periods[0].begin = 10;
  s.noise.periods[0].end = 200;
  s.noise.acc_sigma = Vec3(0.01, 0.02, 0.03);
  s.detail.acc_threshold = 1.4;
  const json j = ToJson(s);
  EXPECT_DOUBLE_EQ(j["window_s"].get<double>(), 1.0);
  EXPECT_EQ(j["noise"]["periods"][0], json::array({10, 200}));
  EXPECT_DOUBLE_EQ(j["noise"]["acc_sigma"][2].get<double>(), 0.03);
  EXPECT_TRUE(j["noise"]["gyr_sigma"].is_null());  // has_gyro false
  EXPECT_DOUBLE_EQ(j["thresholds"]["acc_threshold"].get<double>(), 1.4);
}

TEST(JsonReport, WriteJsonWritesTheDocumentThatReadsBack) {
  testing::TempDir dir;
  const std::string path = dir.File("result.json");
  const json doc = ToJson(MakeResult());
  WriteJson(path, doc);
  std::ifstream in(path);
  EXPECT_EQ(json::parse(in), json::parse(doc.dump()));
}

TEST(JsonReport, WriteJsonToAMissingFolderThrowsNamingThePath) {
  testing::TempDir dir;
  const std::string path = dir.File("no/such/folder/result.json");
  try {
    WriteJson(path, json{{"a", 1}});
    ADD_FAILURE() << "expected plumb::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(JsonReport, WriteJsonReplacesInvalidUtf8InLabels) {
  testing::TempDir dir;
  auto r = MakeResult();
  r.fit.still[0].segment.label = "bad \xff label";
  const std::string path = dir.File("result.json");
  WriteJson(path, ToJson(r));
  std::ifstream in(path);
  const json back = json::parse(in);
  EXPECT_NE(back["segments"][0]["label"].get<std::string>().find("label"), std::string::npos);
}

}  // namespace
}  // namespace plumb::report

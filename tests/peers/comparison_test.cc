// plumb's answer beside a peer's: rows, differences in sigma units, what has no counterpart,
// and imu_tk's cost of both on the still-segment means.
#include "plumb/peers/comparison.h"

#include <gtest/gtest.h>

#include <cmath>

namespace plumb::peers {
namespace {

/// plumb's result: F = 400 I, b_a = 32000, E = 5000 I, b_g = 32700, sigma 0.1 for every
/// parameter, chi^2/dof 4, and three still means at |f| = 9.8 m/s^2.
PlumbResult SmallPlumbResult() {
  PlumbResult r;
  r.path = "result.json";
  r.method = "generalized";
  r.model_spec = "base+gyro_bias_drift";
  r.accel_matrix = 400.0 * Mat3::Identity();
  r.accel_bias = Vec3::Constant(32000.0);
  r.has_gyro = true;
  r.gyro_matrix = 5000.0 * Mat3::Identity();
  r.gyro_bias = Vec3::Constant(32700.0);
  const char* axes = "xyz";
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) {
      r.parameters.push_back({std::string("accel.matrix.") + axes[i] + axes[j],
                              i == j ? 400.0 : 0.0, 0.1, true, false, "1"});
    }
  }
  for (int i = 0; i < 3; ++i) {
    r.parameters.push_back({std::string("accel.bias.") + axes[i], 32000.0, 0.1, true, false, "m/s^2"});
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      r.parameters.push_back({std::string("gyro.matrix.") + axes[i] + axes[j],
                              i == j ? 5000.0 : 0.0, 0.1, true, false, "1"});
    }
  }
  for (int i = 0; i < 3; ++i) {
    r.parameters.push_back({std::string("gyro.bias.") + axes[i], 32700.0, 0.1, true, false, "rad/s"});
  }
  r.parameters.push_back({"gyro_bias_drift.d.x", 0.0, std::nullopt, false, false, "rad/s^2"});
  r.chi2_dof = 4.0;
  r.dof = 100;
  r.gravity_m_s2 = 9.8;
  r.noise_accel = Vec3::Constant(4.0);
  for (const Vec3& f : {Vec3(9.8, 0, 0), Vec3(0, -9.8, 0), Vec3(0, 0, 9.8)}) {
    r.segments.push_back({"still", 400.0 * f + r.accel_bias, 500.0});
  }
  return r;
}

/// The peer: plumb's answer with accel.matrix.xx 0.3 lower and gyro.bias.x 0.5 higher.
ForwardCalibration SmallPeer(const PlumbResult& r) {
  ForwardCalibration p;
  p.peer = "imu_tk";
  p.sources = {"acc.calib", "gyro.calib"};
  p.accel_matrix = r.accel_matrix;
  p.accel_matrix(0, 0) -= 0.3;
  p.accel_bias = r.accel_bias;
  p.has_gyro = true;
  p.gyro_matrix = r.gyro_matrix;
  p.gyro_bias = r.gyro_bias + Vec3(0.5, 0, 0);
  return p;
}

const ComparisonRow& Row(const Comparison& c, const std::string& name) {
  for (const auto& row : c.rows) {
    if (row.name == name) return row;
  }
  throw std::runtime_error("no row " + name);
}

TEST(Comparison, DifferencesInSigmaUnits) {
  const PlumbResult r = SmallPlumbResult();
  const Comparison c = Compare(r, SmallPeer(r));
  // 6 accel matrix entries (the zero lower triangle is left out), 3 + 9 + 3 others.
  EXPECT_EQ(c.rows.size(), 21u);
  const ComparisonRow& xx = Row(c, "accel.matrix.xx");
  EXPECT_NEAR(xx.difference, 0.3, 1e-9);
  ASSERT_TRUE(xx.z.has_value());
  EXPECT_NEAR(*xx.z, 3.0, 1e-7);
  EXPECT_NEAR(*xx.z_scaled, 1.5, 1e-7);  // sqrt(chi^2/dof) = 2
  const ComparisonRow& bx = Row(c, "gyro.bias.x");
  EXPECT_NEAR(*bx.z, -5.0, 1e-7);
  EXPECT_EQ(Row(c, "gyro.bias.y").difference, 0.0);
  EXPECT_EQ(c.plumb_only, std::vector<std::string>{"gyro_bias_drift.d.x"});
  EXPECT_TRUE(c.notes.empty());
}

TEST(Comparison, PeerTermsOutsidePlumbsModelAreShownAgainstZero) {
  const PlumbResult r = SmallPlumbResult();
  ForwardCalibration p = SmallPeer(r);
  p.has_g_sensitivity = true;
  p.g_sensitivity(0, 1) = 2e-4;
  const Comparison c = Compare(r, p);
  const ComparisonRow& g = Row(c, "gyro_g_sensitivity.G.xy");
  EXPECT_FALSE(g.in_plumb_model);
  EXPECT_EQ(g.plumb_value, 0.0);
  EXPECT_NEAR(g.difference, -2e-4, 1e-18);
  EXPECT_FALSE(g.z.has_value());
}

TEST(Comparison, CostsAreImuTksOnTheSegmentMeans) {
  const PlumbResult r = SmallPlumbResult();
  const ForwardCalibration p = SmallPeer(r);
  const Comparison c = Compare(r, p);
  ASSERT_TRUE(c.cost.available) << c.cost.unavailable_reason;
  EXPECT_EQ(c.cost.segments, 3);
  EXPECT_EQ(c.cost.gravity_source, "the result's site.gravity");
  EXPECT_NEAR(c.cost.plumb_means.cost, 0.0, 1e-20);  // plumb's means sit exactly on |f| = g
  // The peer reads the x pose as 400 * 9.8 / 399.7: r = 9.8 (1 - 400 / 399.7).
  const double r_x = 9.8 * (1.0 - 400.0 / 399.7);
  EXPECT_NEAR(c.cost.peer_means.cost, 0.5 * r_x * r_x, 1e-15);
  ASSERT_TRUE(c.cost.has_sample_estimate);
  // Noise 4 output units per sample = 0.01 m/s^2 in every direction: 300 residuals.
  EXPECT_NEAR(c.cost.plumb_samples.cost, 0.5 * 300 * 1e-4, 1e-12);
  CompareOptions options;
  options.gravity_m_s2 = 9.9;
  const Comparison other_g = Compare(r, p, options);
  EXPECT_EQ(other_g.cost.gravity_source, "FitRequest/CompareOptions::gravity_m_s2");
  EXPECT_NEAR(other_g.cost.plumb_means.rms_m_s2, 0.1, 1e-12);
}

TEST(Comparison, NoSegmentsNoCost) {
  PlumbResult r = SmallPlumbResult();
  r.segments.clear();
  const Comparison c = Compare(r, SmallPeer(r));
  EXPECT_FALSE(c.cost.available);
  EXPECT_NE(c.cost.unavailable_reason.find("result.json has no still-segment means"),
            std::string::npos);
  EXPECT_NE(ComparisonText(c).find("not computed"), std::string::npos);
}

TEST(Comparison, ScalesOfDifferentUnitsAreFlagged) {
  const PlumbResult r = SmallPlumbResult();
  ForwardCalibration p = SmallPeer(r);
  p.accel_matrix = Mat3::Identity();  // a peer given m/s^2 against plumb's counts
  const Comparison c = Compare(r, p);
  ASSERT_EQ(c.notes.size(), 1u);
  EXPECT_EQ(c.notes[0].code, "scales_differ");
  EXPECT_NE(c.notes[0].message.find("accelerometer scales"), std::string::npos) << c.notes[0].message;
  EXPECT_EQ(c.notes[0].options, (std::vector<Option>{Option::kAccScale, Option::kGyrScale,
                                                     Option::kAccOffset, Option::kGyrOffset}));
}

TEST(Comparison, TextAndJsonCarryTheRows) {
  const PlumbResult r = SmallPlumbResult();
  const Comparison c = Compare(r, SmallPeer(r));
  const std::string text = ComparisonText(c);
  EXPECT_NE(text.find("accel.matrix.xx"), std::string::npos) << text;
  EXPECT_NE(text.find("largest |d/sigma|: accel 3 (accel.matrix.xx), gyro 5 (gyro.bias.x)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("its OWN still intervals"), std::string::npos) << text;
  const nlohmann::json j = ComparisonJson(c);
  EXPECT_EQ(j["rows"].size(), 21u);
  EXPECT_EQ(j["rows"][0]["name"], "accel.matrix.xx");
  EXPECT_NEAR(j["rows"][0]["z"].get<double>(), 3.0, 1e-7);
  EXPECT_EQ(j["peer"]["name"], "imu_tk");
  EXPECT_TRUE(j["gravity_norm_cost"]["available"].get<bool>());
  EXPECT_TRUE(j["gravity_norm_cost"]["means"]["peer"]["cost"].is_number());
}

}  // namespace
}  // namespace plumb::peers

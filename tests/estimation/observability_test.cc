// Rank, null space and determined combinations on small problems with known structure.
#include "plumb/estimation/observability.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace plumb::estimation {
namespace {

/// One level pose, accelerometer z only: y_z = -g F_zz + b_z, measured with sigma 0.01.
ObservabilityInput OneLevelPoseZ() {
  ObservabilityInput in;
  const double g = 9.78, w = 1.0 / 0.01;
  in.J.resize(1, 2);
  in.J << -g * w, 1.0 * w;  // d r / d(F_zz, b_z), up to the residual's sign
  in.names = {"accel.matrix.zz", "accel.bias.z"};
  in.values = {1.002, 0.05};
  in.is_model = {true, true};
  return in;
}

TEST(Observability, OneLevelPoseHasOneNullDirection) {
  const auto a = AnalyseObservability(OneLevelPoseZ());
  EXPECT_EQ(a.summary.rank, 1);
  ASSERT_EQ(a.summary.unobservable.size(), 1u);
  EXPECT_EQ(a.summary.unobservable[0], "9.78 accel.bias.z + 1 accel.matrix.zz");
  EXPECT_FALSE(a.observable[0]);
  EXPECT_FALSE(a.observable[1]);
}

TEST(Observability, OneLevelPoseDeterminesTheMeasuredCombination) {
  const auto a = AnalyseObservability(OneLevelPoseZ());
  ASSERT_EQ(a.summary.determined.size(), 1u);
  const auto& c = a.summary.determined[0];
  EXPECT_EQ(c.text, "accel.bias.z - 9.78 accel.matrix.zz");
  EXPECT_NEAR(c.value, 0.05 - 9.78 * 1.002, 1e-12);
  EXPECT_NEAR(c.sigma, 0.01, 1e-12);  // the one measurement's sigma
}

/// Two biases seen through one unknown attitude: y1 = a + theta, y2 = b + theta (sigma 1). The
/// null direction moves a, b and theta together; a - b = y1 - y2 is determined.
ObservabilityInput TwoBiasesThroughOneAttitude() {
  ObservabilityInput in;
  in.J.resize(2, 3);
  in.J << 1, 0, 1,
          0, 1, 1;
  in.names = {"a", "b", "theta"};
  in.values = {0.3, 0.1, std::nan("")};
  in.is_model = {true, true, false};
  return in;
}

TEST(Observability, ADirectionThroughAnAttitudeStillDeterminesWhatItLeaves) {
  const auto a = AnalyseObservability(TwoBiasesThroughOneAttitude());
  EXPECT_EQ(a.summary.rank, 2);
  ASSERT_EQ(a.summary.unobservable.size(), 1u);
  EXPECT_EQ(a.summary.unobservable[0], "1 a - 1 theta + 1 b");
  ASSERT_EQ(a.summary.determined.size(), 1u);
  const auto& c = a.summary.determined[0];
  EXPECT_EQ(c.text, "-a + b");
  EXPECT_NEAR(c.value, 0.1 - 0.3, 1e-12);
  EXPECT_NEAR(c.sigma, std::sqrt(2.0), 1e-12);  // y2 - y1
  // The determined combination is orthogonal to the null direction's model part.
  EXPECT_NEAR(c.coefficients[0] + c.coefficients[1], 0.0, 1e-12);
  // The direction as numbers, over every unknown: the data does not see it.
  ASSERT_EQ(a.summary.null_space.rows(), 1);
  ASSERT_EQ(a.summary.null_space.cols(), 3);
  EXPECT_EQ(a.summary.null_space_names, (std::vector<std::string>{"a", "b", "theta"}));
  EXPECT_LT((TwoBiasesThroughOneAttitude().J * a.summary.null_space.row(0).transpose()).norm(),
            1e-12);
}

TEST(Observability, FullRankCovarianceIsTheInverseNormalMatrix) {
  ObservabilityInput in;
  in.J.resize(4, 2);
  in.J << 1, 2, 3, -1, 0.5, 4, -2, 1;
  in.names = {"a", "b"};
  in.values = {0, 0};
  in.is_model = {true, true};
  const auto a = AnalyseObservability(in);
  EXPECT_EQ(a.summary.rank, 2);
  EXPECT_TRUE(a.summary.unobservable.empty());
  const Eigen::MatrixXd expected = (in.J.transpose() * in.J).inverse();
  EXPECT_LT((a.covariance - expected).norm(), 1e-12);
}

TEST(Observability, RankDecisionIgnoresUnits) {
  // The same full-rank problem with one unknown in units a million times smaller.
  ObservabilityInput in;
  in.J.resize(3, 2);
  in.J << 1e6, 1, 2e6, -1, 0.5e6, 3;
  in.names = {"raw", "si"};
  in.values = {0, 0};
  in.is_model = {true, true};
  EXPECT_EQ(AnalyseObservability(in).summary.rank, 2);
}

// Two parameters of typical size 1 whose sum the data determine to 0.1 and (with weight 0.02)
// whose difference only to 50, over three times its typical size: the difference is weakly
// determined (kWeakSpread), the sum is what the data determine, and neither parameter alone is
// (each sigma is 25).
ObservabilityInput SumAndDifference(double difference_weight) {
  ObservabilityInput in;
  in.J.resize(2, 2);
  in.J << 10, 10, difference_weight, -difference_weight;
  in.names = {"a", "b"};
  in.values = {0.5, 0.25};
  in.is_model = {true, true};
  in.typical = {1.0, 1.0};
  return in;
}

TEST(Observability, ACombinationKnownWorseThanItsTypicalSpreadIsWeak) {
  const auto a = AnalyseObservability(SumAndDifference(0.02));
  EXPECT_TRUE(a.summary.unobservable.empty());
  ASSERT_EQ(a.summary.weakly_determined.size(), 1u);
  const Combination& w = a.summary.weakly_determined[0];
  EXPECT_EQ(w.text, "a - b");
  EXPECT_DOUBLE_EQ(w.value, 0.25);
  // var(a - b) = 2 / (2 0.02^2) = 2500; its typical spread sqrt(1 + 1).
  EXPECT_NEAR(w.sigma, 50.0, 1e-9);
  EXPECT_NEAR(w.typical, std::sqrt(2.0), 1e-12);
  ASSERT_EQ(a.weak.size(), 1u);
  EXPECT_NEAR(std::abs(a.weak[0][0] + a.weak[0][1]), 0.0, 1e-12);  // along a - b
  EXPECT_EQ(a.summary.rank, 1);
  EXPECT_FALSE(a.observable[0]);
  EXPECT_FALSE(a.observable[1]);
  ASSERT_EQ(a.summary.determined.size(), 1u);
  EXPECT_EQ(a.summary.determined[0].text, "a + b");
  EXPECT_NEAR(a.summary.determined[0].sigma, 0.1, 1e-12);  // sqrt(2 / 200)
}

TEST(Observability, ACombinationKnownWithinItsTypicalSpreadIsDetermined) {
  // sigma(a - b) = 1 / 0.4 = 2.5 < 3 sqrt(2): determined, like every parameter.
  const auto a = AnalyseObservability(SumAndDifference(0.4));
  EXPECT_TRUE(a.summary.weakly_determined.empty());
  EXPECT_TRUE(a.observable[0] && a.observable[1]);
  EXPECT_EQ(a.summary.rank, 2);
  // Without typical sizes no weak combination is sought.
  ObservabilityInput untyped = SumAndDifference(0.02);
  untyped.typical.clear();
  EXPECT_TRUE(AnalyseObservability(untyped).summary.weakly_determined.empty());
}

TEST(Observability, FormatCombinationDropsNegligibleTerms) {
  Eigen::VectorXd c(3);
  c << 1.0, -2.5, 1e-15;
  EXPECT_EQ(FormatCombination(c, {"a", "b", "c"}, false), "a - 2.5 b");
}

}  // namespace
}  // namespace plumb::estimation

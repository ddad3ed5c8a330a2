// The score test (diagnostics/score_test.h) on linear problems, where its prediction is exact.
#include "plumb/diagnostics/score_test.h"

#include <gtest/gtest.h>

#include <Eigen/QR>
#include <random>

#include "plumb/core/error.h"

namespace plumb::diagnostics {
namespace {

Eigen::MatrixXd Gaussian(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = n(rng);
  return m;
}

/// Residual of the least-squares fit of y by the columns of A.
Eigen::VectorXd FitResidual(const Eigen::MatrixXd& A, const Eigen::VectorXd& y) {
  return y - A * A.colPivHouseholderQr().solve(y);
}

std::vector<std::string> Names(const std::string& prefix, Eigen::Index n) {
  std::vector<std::string> out;
  for (Eigen::Index i = 0; i < n; ++i) out.push_back(prefix + std::to_string(i));
  return out;
}

TEST(ScoreTest, LinearProblemLmIsTheExactFallOfChi2) {
  std::mt19937_64 rng(12345);
  const Eigen::MatrixXd J = Gaussian(200, 6, rng);
  const Eigen::MatrixXd Z = Gaussian(200, 3, rng);
  const Eigen::VectorXd y = Gaussian(200, 1, rng) + Z * Eigen::Vector3d(0.1, -0.2, 0.05);
  const Eigen::VectorXd r = FitResidual(J, y);  // the fit without the candidate
  Eigen::MatrixXd JZ(200, 9);
  JZ << J, Z;
  const double drop = r.squaredNorm() - FitResidual(JZ, y).squaredNorm();
  const ScoreTestResult s = ScoreTest(r, J, Z, Names("j", 6), Names("z", 3), {1, 1, 1});
  EXPECT_NEAR(s.lm, drop, 1e-9 * drop);
  EXPECT_EQ(s.dof, 3);
  EXPECT_TRUE(s.identifiable);
}

TEST(ScoreTest, UnderTheNullLmIsChiSquareWithQDegreesOfFreedom) {
  // Mean of LM over many pure-noise problems ~ q (chi^2 mean), within 4 standard errors.
  std::mt19937_64 rng(777);
  const int runs = 400;
  double sum = 0.0;
  for (int k = 0; k < runs; ++k) {
    const Eigen::MatrixXd J = Gaussian(60, 5, rng);
    const Eigen::MatrixXd Z = Gaussian(60, 2, rng);
    const Eigen::VectorXd r = FitResidual(J, Gaussian(60, 1, rng));
    sum += ScoreTest(r, J, Z, Names("j", 5), Names("z", 2), {1, 1}).lm;
  }
  const double mean = sum / runs;
  EXPECT_NEAR(mean, 2.0, 4.0 * std::sqrt(2.0 * 2.0 / runs));
}

TEST(ScoreTest, ConfoundedAndUnexcitedColumnsAreNamed) {
  std::mt19937_64 rng(99);
  const Eigen::MatrixXd J = Gaussian(50, 3, rng);
  Eigen::MatrixXd Z(50, 3);
  Z.col(0) = 2.0 * J.col(1);                  // the fit's j1 absorbs it entirely
  Z.col(1).setZero();                         // the data does not excite it
  Z.col(2) = Gaussian(50, 1, rng);            // a genuine new direction
  const Eigen::VectorXd r = FitResidual(J, Gaussian(50, 1, rng));
  const ScoreTestResult s = ScoreTest(r, J, Z, {"j0", "j1", "j2"}, {"za", "zb", "zc"}, {1, 1, 1});
  EXPECT_FALSE(s.identifiable);
  ASSERT_EQ(s.not_identifiable.size(), 2u);
  EXPECT_EQ(s.not_identifiable[0].parameter, "za");
  EXPECT_TRUE(s.not_identifiable[0].excited);
  ASSERT_FALSE(s.not_identifiable[0].confounders.empty());
  EXPECT_EQ(s.not_identifiable[0].confounders[0], "j1");
  EXPECT_NEAR(s.not_identifiable[0].shares[0], 1.0, 1e-9);
  EXPECT_EQ(s.not_identifiable[1].parameter, "zb");
  EXPECT_FALSE(s.not_identifiable[1].excited);
  EXPECT_EQ(s.dof, 1);  // the identifiable column still counts
}

TEST(ScoreTest, SizeMismatchesAreErrors) {
  const Eigen::MatrixXd J = Eigen::MatrixXd::Identity(4, 2);
  const Eigen::MatrixXd Z = Eigen::MatrixXd::Ones(4, 1);
  EXPECT_THROW(ScoreTest(Eigen::VectorXd::Zero(3), J, Z, {"a", "b"}, {"z"}, {1}), Error);
  EXPECT_THROW(ScoreTest(Eigen::VectorXd::Zero(4), J, Z, {"a"}, {"z"}, {1}), Error);
}

}  // namespace
}  // namespace plumb::diagnostics

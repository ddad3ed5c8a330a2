// The motion residual: zero on exactly integrated data, Jacobian against numeric differences.
#include "plumb/residuals/motion_residual.h"
#include "plumb/residuals/mounted_motion_residual.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>

#include "plumb/model/registry.h"
#include "plumb/residuals/manifolds.h"
#include "support/jacobian_check.h"

namespace plumb::residuals {
namespace {

/// A 90-degree turn about body z over 2 s at 100 Hz with a raised-cosine rate profile,
/// measured by the identity sensor; returns the samples and the final body rotation.
MotionSamples Turn(Quat* dR) {
  MotionSamples s;
  const double T = 2.0, A = M_PI / 2;
  const int n = 201;
  for (int i = 0; i < n; ++i) {
    const double t = T * i / (n - 1);
    const double rate = A / T * (1 - std::cos(2 * M_PI * t / T));
    s.dt_s.push_back(t);
    s.gyr.push_back(Vec3(0, 0, rate));
    s.acc.push_back(Vec3(0, 0, -9.81));
    s.alpha_b.push_back(Vec3(0, 0, A / T * 2 * M_PI / T * std::sin(2 * M_PI * t / T)));
    s.dtemp_c.push_back(1.5 + 0.8 * t);  // warming: the temperature terms move
  }
  s.sqrt_info = Vec3::Constant(1000.0);
  *dR = Quat(Eigen::AngleAxisd(A, Vec3::UnitZ()));
  return s;
}

TEST(MotionResidual, IntegratesAKnownTurn) {
  Quat dR_true;
  const MotionSamples s = Turn(&dR_true);
  const model::Model m = model::Model::Parse("base");
  const MotionResidual r(m, s, Vec3::Zero());
  const double q0[4] = {0, 0, 0, 1};
  const Quat dR = r.Integrate(q0, m.ZeroParameters());
  EXPECT_LT(dR.angularDistance(dR_true), 1e-8);
}

/// Jacobian error of the motion residual for `spec` with small non-zero parameters, the
/// attitudes off the turn by 0.01 rad and Earth rate present (or not: without it the
/// sensitivities are carried in the interval's start frame, another code path); `mounted`:
/// the residual of an IMU mounted at a rotation R_b_i of 2 degrees (mounted_motion_residual.h).
double MotionJacobianError(const std::string& spec, int processes = 0, bool earth = true,
                           bool mounted = false) {
  Quat dR_true;
  const MotionSamples s = Turn(&dR_true);
  const model::Model m = model::Model::Parse(spec);
  auto theta = m.ZeroParameters();
  theta[0][6] = 0.1;
  theta[1][0] = 0.01;
  theta[1][1] = -0.004;
  theta[1][5] = 0.003;
  theta[1][9] = 0.002;
  for (std::size_t t = 2; t < theta.size(); ++t) {
    for (std::size_t i = 0; i < theta[t].size(); ++i) theta[t][i] = 1e-4 * (1.0 + static_cast<double>(i));
  }
  const Vec3 omega_ie_n = earth ? Vec3(4e-5, 0, -5e-5) : Vec3::Zero();
  std::unique_ptr<ceres::CostFunction> cost(
      mounted ? static_cast<ceres::CostFunction*>(new MountedMotionResidual(
                    m, std::make_shared<const MotionSamples>(s), omega_ie_n, processes))
              : MotionResidual::Create(m, s, omega_ie_n, processes));
  const Quat qa = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 0, 1).normalized()));
  const Quat qb = qa * dR_true * Quat(Eigen::AngleAxisd(0.01, Vec3::UnitX()));
  const Vec3 rho = 0.035 * Vec3(-1, 2, 0.5).normalized();  // with a lever arm and time offset
  const double a[4] = {qa.x(), qa.y(), qa.z(), qa.w()};
  const double b[4] = {qb.x(), qb.y(), qb.z(), qb.w()};
  const double mount[7] = {rho.x(), rho.y(), rho.z(), 0.02, -0.01, 0.03, 1e-3};
  std::vector<const double*> params = {a, b};
  if (mounted) params.push_back(mount);
  for (const auto& block : theta) params.push_back(block.data());
  // Wander states: from and to of each process.
  const double states[2][2][3] = {{{2e-3, -1e-3, 4e-4}, {-5e-4, 3e-3, 1e-3}},
                                  {{-4e-4, 6e-4, 1e-4}, {3e-4, -2e-4, 5e-4}}};
  for (int p = 0; p < processes; ++p) params.insert(params.end(), {states[p][0], states[p][1]});
  const auto manifold = AttitudeManifold();
  std::vector<const ceres::Manifold*> manifolds(params.size(), nullptr);
  manifolds[0] = manifolds[1] = manifold.get();
  return testing::JacobianError(*cost, params, manifolds);
}

TEST(MotionResidual, JacobianMatchesNumericBase) {
  EXPECT_LT(MotionJacobianError("base"), 1e-7);
}

TEST(MotionResidual, JacobianMatchesNumericWithGyroEffects) {
  EXPECT_LT(MotionJacobianError("base+gyro_g_sensitivity"), 1e-7);
  EXPECT_LT(MotionJacobianError("base+gyro_scale_nonlinearity"), 1e-7);
  EXPECT_LT(MotionJacobianError("base+gyro_scale_nonlinearity+gyro_g_sensitivity"), 1e-7);
}

// Every effect of the catalogue, alone and with one that reads the linear stage's E
// (gyro_scale_nonlinearity) and one that couples the sensors (gyro_g_sensitivity): the linear
// stage's share of d w / d theta is closed-form, the effects' from Jets through their term
// alone, and through Jets of the linear stage where a term reads F or E.
TEST(MotionResidual, JacobianMatchesNumericWithEveryEffect) {
  for (const std::string& name : model::Registry::Global().CatalogueNames()) {
    SCOPED_TRACE(name);
    EXPECT_LT(MotionJacobianError("base+" + name), 1e-7);
    if (name != "gyro_scale_nonlinearity" && name != "gyro_g_sensitivity") {
      // Central differences (step 1e-6) reach 1.5e-7 on these larger models (the same figure
      // with every parameter differentiated through Jets of the whole model).
      EXPECT_LT(MotionJacobianError("base+gyro_scale_nonlinearity+gyro_g_sensitivity+" + name), 3e-7);
    }
  }
}

TEST(MotionResidual, JacobianMatchesNumericWithAccelEffect) {
  EXPECT_LT(MotionJacobianError("base+accel_bias_drift"), 1e-7);
}

TEST(MotionResidual, JacobianMatchesNumericWithABiasWalk) {
  EXPECT_LT(MotionJacobianError("base", 1), 1e-7);
  EXPECT_LT(MotionJacobianError("base+gyro_g_sensitivity+gyro_scale_nonlinearity", 1), 1e-7);
}

TEST(MotionResidual, JacobianMatchesNumericWithAWalkAndAnInstability) {
  EXPECT_LT(MotionJacobianError("base", 2), 1e-7);
  EXPECT_LT(MotionJacobianError("base+gyro_g_sensitivity+gyro_scale_nonlinearity", 2), 1e-7);
}

// Without a site (no Earth rate) the sensitivities are carried in the start frame and, for
// the base model, summed per sample before the product with E^-1.
TEST(MotionResidual, JacobianMatchesNumericWithoutEarthRate) {
  for (int processes : {0, 1, 2}) {
    SCOPED_TRACE(processes);
    EXPECT_LT(MotionJacobianError("base", processes, false), 1e-7);
    // The values alone are integrated on quaternions here (IntegratedRotation), the Jacobians
    // on matrices: central differences of the larger model reach 1.2e-7 (4e-8 to 1.2e-7 over
    // the processes; the base model's 1e-9 shows the two agree).
    EXPECT_LT(MotionJacobianError("base+gyro_g_sensitivity+gyro_scale_nonlinearity", processes, false),
              3e-7);
  }
  for (const std::string& name : model::Registry::Global().CatalogueNames()) {
    SCOPED_TRACE(name);
    EXPECT_LT(MotionJacobianError("base+" + name, 0, false), 1e-7);
  }
}

TEST(MountedMotionResidual, JacobianMatchesNumeric) {
  for (int processes : {0, 2}) {
    for (bool earth : {true, false}) {
      SCOPED_TRACE(std::to_string(processes) + (earth ? " with Earth rate" : " without"));
      EXPECT_LT(MotionJacobianError("base", processes, earth, true), 1e-7);
      EXPECT_LT(MotionJacobianError("base+gyro_g_sensitivity+gyro_scale_nonlinearity", processes,
                                    earth, true),
                3e-7);
    }
  }
}

/// The residual of the turn between attitudes `from` and `to`, plain or of an IMU mounted at
/// `R_b_i`, for a base model with a few parameters set.
Vec3 TurnResidual(const Quat& from, const Quat& to, const Quat* R_b_i) {
  Quat dR_true;
  const MotionSamples s = Turn(&dR_true);
  const model::Model m = model::Model::Parse("base");
  auto theta = m.ZeroParameters();
  theta[1][0] = 0.01;
  theta[1][9] = 0.002;
  const Vec3 omega_ie_n(4e-5, 0, -5e-5);
  std::unique_ptr<ceres::CostFunction> cost(
      R_b_i ? static_cast<ceres::CostFunction*>(new MountedMotionResidual(
                  m, std::make_shared<const MotionSamples>(s), omega_ie_n))
            : MotionResidual::Create(m, s, omega_ie_n));
  const double a[4] = {from.x(), from.y(), from.z(), from.w()};
  const double b[4] = {to.x(), to.y(), to.z(), to.w()};
  std::vector<const double*> params = {a, b};
  double mount[7] = {};  // no lever arm or time offset: they do not enter
  if (R_b_i) {
    const Eigen::AngleAxisd aa(*R_b_i);
    const Vec3 rho = aa.angle() * aa.axis();
    std::copy_n(rho.data(), 3, mount);
    params.push_back(mount);
  }
  for (const auto& block : theta) params.push_back(block.data());
  Vec3 r;
  cost->Evaluate(params.data(), r.data(), nullptr);
  return r;
}

// A mounted IMU is an IMU at R_n_i = R_n_b R_b_i: its residual at (R_k, R_k+1, R_b_i) is the
// plain one at (R_k R_b_i, R_k+1 R_b_i), and a mount at the identity changes
// nothing; and the residual does not depend on which of two mounts the same pair of IMU
// attitudes is reached through.
TEST(MountedMotionResidual, AnImuMountedIsAnImuAtItsOwnAttitude) {
  Quat dR_true;
  Turn(&dR_true);
  const Quat from = Quat(Eigen::AngleAxisd(0.4, Vec3(0.2, 1, -0.3).normalized()));
  const Quat to = from * dR_true * Quat(Eigen::AngleAxisd(0.02, Vec3(1, -1, 0).normalized()));
  const Quat mount(Eigen::AngleAxisd(0.03, Vec3(0.5, -1, 2).normalized()));
  const Quat identity = Quat::Identity();
  const Vec3 plain = TurnResidual(from, to, nullptr);
  EXPECT_LT((TurnResidual(from, to, &identity) - plain).norm(), 1e-13 * plain.norm());
  const Vec3 mounted = TurnResidual(from, to, &mount);
  EXPECT_LT((mounted - TurnResidual(from * mount, to * mount, nullptr)).norm(), 1e-12 * mounted.norm());
  EXPECT_GT((mounted - plain).norm(), 1e-3 * plain.norm());  // the mount matters
  const Quat other(Eigen::AngleAxisd(0.05, Vec3(1, 0.3, 0).normalized()));
  const Quat shift = mount * other.inverse();  // (R_k shift) other = R_k mount
  EXPECT_LT((TurnResidual(from * shift, to * shift, &other) - mounted).norm(), 1e-9 * mounted.norm());
}

// A precomputed evaluation (cached_cost_function.h) is handed out only at the same values
// with the same Jacobian blocks asked for, and then holds the direct evaluation's bits; at
// other values, or with other blocks asked for, the residual is evaluated directly.
TEST(MotionResidual, APrecomputedEvaluationIsTheDirectOneOrNone) {
  Quat dR_true;
  const MotionSamples s = Turn(&dR_true);
  const model::Model m = model::Model::Parse("base");
  auto theta = m.ZeroParameters();
  theta[1][0] = 0.01;
  const MotionResidual r(m, s, Vec3::Zero(), 1);
  const Quat qb = dR_true * Quat(Eigen::AngleAxisd(0.01, Vec3::UnitX()));
  double a[4] = {0, 0, 0, 1}, b[4] = {qb.x(), qb.y(), qb.z(), qb.w()};
  const double from[3] = {1e-3, 0, 0}, to[3] = {0, 2e-3, 0};
  std::vector<const double*> p = {a, b, theta[0].data(), theta[1].data(), from, to};
  // Direct evaluation first (nothing kept yet), then the same after Precompute.
  std::vector<std::vector<double>> direct_j, kept_j;
  std::vector<double*> direct_ptr, kept_ptr;
  for (int size : r.parameter_block_sizes()) {
    direct_j.emplace_back(static_cast<std::size_t>(3 * size), 0.0);
    kept_j.emplace_back(static_cast<std::size_t>(3 * size), -1.0);
    direct_ptr.push_back(direct_j.back().data());
    kept_ptr.push_back(kept_j.back().data());
  }
  kept_ptr[2] = direct_ptr[2] = nullptr;  // the accelerometer block: no Jacobian asked
  double direct[3], kept[3];
  ASSERT_TRUE(r.Evaluate(p.data(), direct, direct_ptr.data()));
  EXPECT_EQ(r.misses(), 1);
  std::vector<bool> wanted(p.size(), true);
  wanted[2] = false;
  r.Precompute(p.data(), wanted);
  ASSERT_TRUE(r.Evaluate(p.data(), kept, kept_ptr.data()));
  EXPECT_EQ(r.hits(), 1);
  EXPECT_EQ(std::memcmp(direct, kept, sizeof direct), 0);
  for (std::size_t j = 0; j < p.size(); ++j) {
    if (j == 2) continue;
    EXPECT_EQ(direct_j[j], kept_j[j]) << "block " << j;
  }
  // Other blocks asked for, or other values: evaluated directly.
  double value_only[3];
  ASSERT_TRUE(r.Evaluate(p.data(), value_only, nullptr));
  EXPECT_EQ(r.misses(), 2);
  a[0] = 1e-3;
  a[3] = std::sqrt(1.0 - 1e-6);
  double moved[3];
  ASSERT_TRUE(r.Evaluate(p.data(), moved, kept_ptr.data()));
  EXPECT_EQ(r.misses(), 3);
  EXPECT_NE(std::memcmp(direct, moved, sizeof direct), 0);
}

TEST(MotionResidual, AWalkAtZeroChangesNothing) {
  // The walk's blocks at zero give the residual without a walk, to the last bit.
  Quat dR_true;
  const MotionSamples s = Turn(&dR_true);
  const model::Model m = model::Model::Parse("base");
  const auto theta = m.ZeroParameters();
  const Quat qa = Quat::Identity(), qb = dR_true;
  const double a[4] = {qa.x(), qa.y(), qa.z(), qa.w()}, b[4] = {qb.x(), qb.y(), qb.z(), qb.w()};
  const double zero[3] = {0, 0, 0};
  std::vector<const double*> p = {a, b, theta[0].data(), theta[1].data()};
  std::unique_ptr<ceres::CostFunction> plain(MotionResidual::Create(m, s, Vec3(4e-5, 0, -5e-5)));
  double r0[3], r1[3];
  plain->Evaluate(p.data(), r0, nullptr);
  p.insert(p.end(), {zero, zero});
  std::unique_ptr<ceres::CostFunction> walked(
      MotionResidual::Create(m, s, Vec3(4e-5, 0, -5e-5), 1));
  walked->Evaluate(p.data(), r1, nullptr);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(r0[i], r1[i]);
}

}  // namespace
}  // namespace plumb::residuals

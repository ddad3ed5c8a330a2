#include "plumb/residuals/mounted_motion_residual.h"

#include <array>
#include <vector>

#include "plumb/model/board_mount.h"

namespace plumb::residuals {
namespace {

Quat QuatOf(const double* q) { return Quat(q[3], q[0], q[1], q[2]); }

using Ambient = Eigen::Matrix<double, 3, 4, Eigen::RowMajor>;

}  // namespace

MountedMotionResidual::MountedMotionResidual(const model::Model& model,
                                             SharedMotionSamples samples, const Vec3& omega_ie_n,
                                             int wander_processes)
    : inner_(model, std::move(samples), omega_ie_n, wander_processes) {
  set_num_residuals(3);
  std::vector<int32_t>& sizes = *mutable_parameter_block_sizes();
  sizes = inner_.parameter_block_sizes();
  sizes.insert(sizes.begin() + 2, model::board_mount::kSize);  // after the two attitudes
}

bool MountedMotionResidual::EvaluateUncached(double const* const* parameters, double* residuals,
                                             double** jacobians) const {
  const Quat R_b_i = model::board_mount::Rotation(parameters[2]);
  const std::array<Quat, 2> R_n_b = {QuatOf(parameters[0]).normalized(),
                                     QuatOf(parameters[1]).normalized()};
  // The IMU's own attitudes R_n_i = R_n_b R_b_i at both poses.
  std::array<std::array<double, 4>, 2> q_n_i;
  for (std::size_t j = 0; j < 2; ++j) {
    const Quat R_n_i = (R_n_b[j] * R_b_i).normalized();
    q_n_i[j] = {R_n_i.x(), R_n_i.y(), R_n_i.z(), R_n_i.w()};
  }
  const std::size_t blocks = parameter_block_sizes().size();
  std::vector<const double*> inner_parameters = {q_n_i[0].data(), q_n_i[1].data()};
  inner_parameters.insert(inner_parameters.end(), parameters + 3, parameters + blocks);
  if (jacobians == nullptr) return inner_.Evaluate(inner_parameters.data(), residuals, nullptr);

  const bool attitudes_wanted = jacobians[0] || jacobians[1] || jacobians[2];
  std::array<Ambient, 2> r_H_q_n_i;
  std::vector<double*> inner_jacobians = {attitudes_wanted ? r_H_q_n_i[0].data() : nullptr,
                                          attitudes_wanted ? r_H_q_n_i[1].data() : nullptr};
  inner_jacobians.insert(inner_jacobians.end(), jacobians + 3, jacobians + blocks);
  if (!inner_.Evaluate(inner_parameters.data(), residuals, inner_jacobians.data())) return false;
  if (!attitudes_wanted) return true;

  Mat3 r_H_d_b = Mat3::Zero();
  for (std::size_t j = 0; j < 2; ++j) {
    const Mat3 r_H_d_n_i = r_H_q_n_i[j] * LeftPlusJacobian(QuatOf(q_n_i[j].data()));
    if (jacobians[j]) {
      Eigen::Map<Ambient> r_H_q(jacobians[j]);
      r_H_q = r_H_d_n_i * 4.0 * LeftPlusJacobian(QuatOf(parameters[j])).transpose();
    }
    r_H_d_b += r_H_d_n_i * R_n_b[j].toRotationMatrix();
  }
  if (jacobians[2]) {
    using MountJacobian = Eigen::Matrix<double, 3, model::board_mount::kSize, Eigen::RowMajor>;
    Eigen::Map<MountJacobian> r_H_mount(jacobians[2]);
    r_H_mount.setZero();  // the lever arm and the time offset do not enter
    r_H_mount.middleCols<3>(model::board_mount::kRotation) =
        r_H_d_b * model::board_mount::LeftPerturbation_H_rotation(parameters[2]);
  }
  return true;
}

}  // namespace plumb::residuals

#include "plumb/residuals/still_residuals.h"

#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <algorithm>

#include "plumb/core/so3.h"
#include "plumb/model/board_mount.h"

namespace plumb::residuals {

StillResidual::StillResidual(const model::Model& model, model::Sensor sensor,
                             std::vector<int> terms, StillMeasurement measurement,
                             const Vec3& g_n, const Vec3& omega_ie_n, const Vec3& omega_eb_b,
                             std::vector<double> wander_weights, bool mounted)
    : model_(&model), sensor_(sensor), terms_(std::move(terms)), m_(measurement), g_n_(g_n),
      omega_ie_n_(omega_ie_n), omega_eb_b_(omega_eb_b), wander_weights_(std::move(wander_weights)),
      first_term_block_(mounted ? 2 : 1) {
  for (int t : terms_) effects_.emplace_back(*model.terms()[static_cast<std::size_t>(t)].effect);
}

std::vector<int> StillResidual::TermsOf(const model::Model& model, model::Sensor sensor) {
  std::vector<int> terms;
  for (int i = 0; i < model.num_terms(); ++i) {
    if (model.terms()[static_cast<std::size_t>(i)].effect->info().sensor == sensor) {
      terms.push_back(i);
    }
  }
  return terms;
}

template <typename T>
Vec3T<T> StillResidual::PredictT(T const* const* parameters) const {
  const Eigen::Map<const Eigen::Quaternion<T>> q_n_b(parameters[0]);
  Mat3T<T> R_n_i = q_n_b.toRotationMatrix();  // the sensing IMU's frame into NED
  if (first_term_block_ == 2) {
    Mat3T<T> R_b_i;  // column-major, as ceres::AngleAxisToRotationMatrix writes it
    ceres::AngleAxisToRotationMatrix(parameters[1] + model::board_mount::kRotation, R_b_i.data());
    R_n_i = R_n_i * R_b_i;
  }
  const model::SensorInput<T> in = model::AtRest<T>(R_n_i.transpose(), g_n_, omega_ie_n_,
                                                    omega_eb_b_, T(m_.dt_s), T(m_.dtemp_c));
  model::SensorOutput<T> out;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    effects_[i].Apply(parameters[i + static_cast<std::size_t>(first_term_block_)], in, out);
  }
  return sensor_ == model::Sensor::kAccel ? out.acc : out.gyr;
}

template <typename T>
bool StillResidual::operator()(T const* const* parameters, T* residuals) const {
  Vec3T<T> predicted = PredictT(parameters);
  for (std::size_t p = 0; p < wander_weights_.size(); ++p) {
    const std::size_t w = terms_.size() + static_cast<std::size_t>(first_term_block_) + 2 * p;
    const Eigen::Map<const Vec3T<T>> s_k(parameters[w]), e_k(parameters[w + 1]);
    predicted += T(wander_weights_[p]) * (s_k + e_k);
  }
  Eigen::Map<Vec3T<T>> r(residuals);
  r = (m_.mean.cast<T>() - predicted).cwiseProduct(m_.sqrt_info.cast<T>());
  return true;
}

Vec3 StillResidual::Predict(const double* q_k, const model::ParameterBlocks& theta,
                            const Quat& R_b_i) const {
  double mount[model::board_mount::kSize] = {};
  const Vec3 rho = so3::Log(R_b_i.toRotationMatrix());
  std::copy_n(rho.data(), 3, mount + model::board_mount::kRotation);
  std::vector<const double*> p = {q_k};
  if (first_term_block_ == 2) p.push_back(mount);
  for (int t : terms_) p.push_back(theta[static_cast<std::size_t>(t)].data());
  return PredictT<double>(p.data());
}

namespace {

/// The cost function of a still residual (`mounted`: with IMU i's board_mount block after q_k).
ceres::CostFunction* Cost(const model::Model& model, model::Sensor sensor,
                          StillMeasurement measurement, const Vec3& g_n, const Vec3& omega_ie_n,
                          const Vec3& omega_eb_b, std::vector<double> wander_weights,
                          bool mounted) {
  const std::vector<int> terms = StillResidual::TermsOf(model, sensor);
  const std::size_t processes = wander_weights.size();
  auto* functor = new StillResidual(model, sensor, terms, measurement, g_n, omega_ie_n, omega_eb_b,
                                    std::move(wander_weights), mounted);
  auto* cost = new ceres::DynamicAutoDiffCostFunction<StillResidual, autodiff::kJetStride>(functor);
  cost->AddParameterBlock(4);
  if (mounted) cost->AddParameterBlock(model::board_mount::kSize);
  for (int t : terms) cost->AddParameterBlock(model.terms()[static_cast<std::size_t>(t)].effect->info().size());
  for (std::size_t p = 0; p < 2 * processes; ++p) cost->AddParameterBlock(3);
  cost->SetNumResiduals(3);
  return cost;
}

}  // namespace

ceres::CostFunction* StillResidual::Create(const model::Model& model, model::Sensor sensor,
                                           StillMeasurement measurement, const Vec3& g_n,
                                           const Vec3& omega_ie_n, const Vec3& omega_eb_b,
                                           std::vector<double> wander_weights) {
  return Cost(model, sensor, measurement, g_n, omega_ie_n, omega_eb_b, std::move(wander_weights),
              false);
}

ceres::CostFunction* StillResidual::CreateMounted(const model::Model& model, model::Sensor sensor,
                                                  StillMeasurement measurement, const Vec3& g_n,
                                                  const Vec3& omega_ie_n, const Vec3& omega_eb_b,
                                                  std::vector<double> wander_weights) {
  return Cost(model, sensor, measurement, g_n, omega_ie_n, omega_eb_b, std::move(wander_weights),
              true);
}

template bool StillResidual::operator()<double>(double const* const*, double*) const;
template bool StillResidual::operator()<autodiff::Jet>(autodiff::Jet const* const*, autodiff::Jet*) const;

}  // namespace plumb::residuals

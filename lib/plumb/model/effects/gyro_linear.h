// plumb/model/effects/gyro_linear.h — the base gyroscope effect (SPEC section 2, the paper's
// Equation (2)) and its parameter block, owned here: nothing outside this file indexes it by
// hand.
//
//   y_g = E omega_b + b_g,   E full 3x3 relative to the accelerometer-defined body frame
//                            (3 scales + 6 misalignments), b_g the bias.
//
// Block layout (12 values; all zero = E = I, no bias):
//   [0..8]   E - I row-major: matrix.xx, matrix.xy, ..., matrix.zz (dimensionless; the
//            diagonals are reported as 1 + value)
//   [9..11]  b_g: bias.x, bias.y, bias.z (sensor output units; rad/s for SI input)
// Option "triangular" (the paper's E) holds matrix.yx, matrix.zx, matrix.zy at zero.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/core/types.h"
#include "plumb/model/effect.h"

namespace plumb::model::gyro_linear {

inline constexpr int kSize = 12;  ///< values in the block
inline constexpr int kBias = 9;   ///< offset of b_g

/// Offset of E(r, c) - [r == c] in the block.
inline constexpr int MatrixIndex(int r, int c) { return 3 * r + c; }

/// True when block value j is a bias (b_g), and when it is a diagonal entry of E (a scale).
inline constexpr bool IsBias(int j) { return j >= kBias && j < kSize; }
inline constexpr bool IsDiagonal(int j) { return j < kBias && j / 3 == j % 3; }

/// E from a block.
template <typename T>
Mat3T<T> Matrix(const T* block) {
  Mat3T<T> E = Mat3T<T>::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) E(r, c) += block[MatrixIndex(r, c)];
  }
  return E;
}

/// b_g of a block, sensor output units.
inline Vec3 Bias(const std::vector<double>& block) {
  return Vec3(block[kBias + 0], block[kBias + 1], block[kBias + 2]);
}

/// Sets the block to E = (1 / rad_per_unit) I and b_g = bias: the starting values of the fit
/// (`rad_per_unit`: the scalar gyroscope scale found by estimation/initialization.h, rad/s per
/// sensor unit).
inline void SetIsotropic(std::vector<double>& block, double rad_per_unit, const Vec3& bias) {
  block[0] = block[4] = block[8] = 1.0 / rad_per_unit - 1.0;
  for (int i = 0; i < 3; ++i) block[static_cast<std::size_t>(kBias + i)] = bias[i];
}

/// The corrected rate of the base model is omega = E^-1 (y_g - b_g), so
///   d omega / d E_rc = -E^-1 e_r omega_c,   d omega / d b_g = -E^-1.
/// Subtracts K d omega / d block from the block's 12 columns `cols` (3 x 12, e.g. a
/// middleCols of a wider Jacobian), given KE_inv = K E^-1 and omega. With K = I and zero
/// columns this writes d omega / d block itself.
template <class Columns>
void SubtractRateJacobian(const Mat3& KE_inv, const Vec3& omega, Columns&& cols) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) cols.col(MatrixIndex(r, c)) -= KE_inv.col(r) * omega[c];
  }
  cols.template middleCols<3>(kBias) -= KE_inv;
}

/// The sum over samples i of SubtractRateJacobian(K_i E^-1, omega_i, cols), given the sums
/// K_by_rate[c] = sum_i K_i omega_i,c and K_sum = sum_i K_i: E^-1 being the same for every
/// sample, the product with it is taken once, on the sums.
template <class Columns>
void SubtractSummedRateJacobian(const Mat3& E_inv, const std::array<Mat3, 3>& K_by_rate,
                                const Mat3& K_sum, Columns&& cols) {
  for (int c = 0; c < 3; ++c) {
    const Mat3 KE_inv = K_by_rate[static_cast<std::size_t>(c)] * E_inv;
    for (int r = 0; r < 3; ++r) cols.col(MatrixIndex(r, c)) -= KE_inv.col(r);
  }
  cols.template middleCols<3>(kBias) -= K_sum * E_inv;
}

/// The catalogue entry of gyro_linear (parameters, units, typical sizes); throws
/// plumb::Error on an option other than "triangular".
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty() && option != "triangular") {
    throw Error("gyro_linear's only option is 'triangular' (got '" + option + "')");
  }
  EffectInfo info;
  info.name = "gyro_linear";
  info.prefix = "gyro";
  info.option = option;
  info.sensor = Sensor::kGyro;
  info.linear_stage = true;
  info.term = option.empty() ? "y_g = E omega_b + b_g, E full"
                             : "y_g = E omega_b + b_g, E upper triangular";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      info.parameters.push_back({std::string("matrix.") + kAxisName[r] + kAxisName[c], "1",
                                 r == c ? 0.02 : 0.01, r == c ? 1.0 : 0.0});
    }
  }
  auto bias = AxisParameters("bias", "rad/s", 0.02);
  info.parameters.insert(info.parameters.end(), bias.begin(), bias.end());
  if (option == "triangular") {
    info.held = {MatrixIndex(1, 0), MatrixIndex(2, 0), MatrixIndex(2, 1)};
  }
  info.excitation.still_orientations = true;
  info.excitation.rotation = true;
  return info;
}

}  // namespace plumb::model::gyro_linear

namespace plumb::model {

class GyroLinear : public EffectBase<GyroLinear> {
 public:
  explicit GyroLinear(const std::string& option) : EffectBase(gyro_linear::Describe(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    const Mat3T<T> E = gyro_linear::Matrix(theta);
    Eigen::Map<const Vec3T<T>> b_g(theta + gyro_linear::kBias);
    out.E = E;
    out.gyr = E * in.omega_b + b_g;
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(gyro_linear, ::plumb::model::GyroLinear)

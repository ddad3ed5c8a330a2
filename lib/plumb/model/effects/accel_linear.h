// plumb/model/effects/accel_linear.h — the base accelerometer effect (SPEC section 2, the
// paper's Equation (1)) and its parameter block, owned here: nothing outside this file indexes
// it by hand.
//
//   y_a = F f_b + b_a,   F upper triangular (sensor and body x axes coincide, body y lies in
//                        the sensor x-y plane), b_a the bias.
//
// Block layout (9 values, 12 with option "full"; all zero = F = I, no bias):
//   [0..5]   F - I, upper triangle row-major: matrix.xx, matrix.xy, matrix.xz, matrix.yy,
//            matrix.yz, matrix.zz (dimensionless; the diagonals are reported as 1 + value)
//   [6..8]   b_a: bias.x, bias.y, bias.z (sensor output units; m/s^2 for SI input)
//   [9..11]  option "full" only: matrix.yx, matrix.zx, matrix.zy (dimensionless)
//
// Option "full": F full 3x3, for a frame that the data defines by known attitudes (the
// paper's benchmark platform, whose faces give the axes) rather than by the accelerometer
// itself. Without known attitudes, a full F is not determined (a rotation of the frame changes
// no prediction).
#pragma once

#include <string>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/core/types.h"
#include "plumb/model/effect.h"

namespace plumb::model::accel_linear {

inline constexpr int kSize = 9;       ///< values in the block (upper-triangular F)
inline constexpr int kSizeFull = 12;  ///< values in the block with option "full"
inline constexpr int kBias = 6;       ///< offset of b_a
inline constexpr int kLower = 9;      ///< offset of the lower triangle (option "full")

/// F from a block (`full`: the block has the lower triangle too).
template <typename T>
Mat3T<T> Matrix(const T* block, bool full) {
  Mat3T<T> F = Mat3T<T>::Identity();
  F(0, 0) += block[0];
  F(0, 1) = block[1];
  F(0, 2) = block[2];
  F(1, 1) += block[3];
  F(1, 2) = block[4];
  F(2, 2) += block[5];
  if (full) {
    F(1, 0) = block[kLower + 0];
    F(2, 0) = block[kLower + 1];
    F(2, 1) = block[kLower + 2];
  }
  return F;
}

/// b_a of a block, sensor output units.
inline Vec3 Bias(const std::vector<double>& block) {
  return Vec3(block[kBias + 0], block[kBias + 1], block[kBias + 2]);
}

/// Row and column of F that block value j (< kSizeFull, not a bias) moves.
inline constexpr int MatrixRow(int j) { return j < 3 ? 0 : j < 5 ? 1 : j < kBias ? 2 : j == kLower ? 1 : 2; }
inline constexpr int MatrixCol(int j) {
  return j < 3 ? j : j < 5 ? j - 2 : j < kBias ? 2 : j == kLower + 2 ? 1 : 0;
}

/// Offset of F(r, c) - [r == c] in the block: the upper triangle at [0..5], the lower one at
/// kLower.. (in a block with option "full" only). MatrixRow/MatrixCol's inverse.
inline constexpr int MatrixIndex(int r, int c) {
  if (r <= c) return r == 0 ? c : r == 1 ? c + 2 : 5;
  return r == 1 ? kLower : c == 0 ? kLower + 1 : kLower + 2;
}

/// True when block value j is a bias (b_a), and when it is a diagonal entry of F (a scale).
inline constexpr bool IsBias(int j) { return j >= kBias && j < kLower; }
inline constexpr bool IsDiagonal(int j) { return !IsBias(j) && MatrixRow(j) == MatrixCol(j); }

/// The corrected specific force of the base model is f = F^-1 (y_a - b_a), so
///   d f / d F_rc = -F^-1 e_r f_c,   d f / d b_a = -F^-1.
/// Subtracts K d f / d block from the block's columns `cols` (3 x kSize, or kSizeFull with
/// `full`), given KF_inv = K F^-1 and f.
template <class Columns>
void SubtractForceJacobian(const Mat3& KF_inv, const Vec3& f, bool full, Columns&& cols) {
  for (int j = 0; j < (full ? kSizeFull : kSize); ++j) {
    if (j >= kBias && j < kLower) continue;
    cols.col(j) -= KF_inv.col(MatrixRow(j)) * f[MatrixCol(j)];
  }
  cols.template middleCols<3>(kBias) -= KF_inv;
}

/// Sets the block to F = scale I (off-diagonals zero) and b_a = bias: the starting values of
/// the fit (estimation/initialization.h).
inline void SetIsotropic(std::vector<double>& block, double scale, const Vec3& bias) {
  block[0] = block[3] = block[5] = scale - 1.0;
  for (int i = 0; i < 3; ++i) block[static_cast<std::size_t>(kBias + i)] = bias[i];
}

/// The catalogue entry of accel_linear (parameters, units, typical sizes); throws
/// plumb::Error on an option other than "full".
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty() && option != "full") {
    throw Error("accel_linear's only option is 'full' (got '" + option + "')");
  }
  EffectInfo info;
  info.name = "accel_linear";
  info.prefix = "accel";
  info.option = option;
  info.sensor = Sensor::kAccel;
  info.linear_stage = true;
  info.term = option.empty() ? "y_a = F f_b + b_a, F upper triangular"
                             : "y_a = F f_b + b_a, F full";
  info.parameters = {{"matrix.xx", "1", 0.02, 1.0}, {"matrix.xy", "1", 0.01, 0.0},
                     {"matrix.xz", "1", 0.01, 0.0}, {"matrix.yy", "1", 0.02, 1.0},
                     {"matrix.yz", "1", 0.01, 0.0}, {"matrix.zz", "1", 0.02, 1.0}};
  auto bias = AxisParameters("bias", "m/s^2", 0.2);
  info.parameters.insert(info.parameters.end(), bias.begin(), bias.end());
  if (option == "full") {
    for (const char* name : {"matrix.yx", "matrix.zx", "matrix.zy"}) {
      info.parameters.push_back({name, "1", 0.01, 0.0});
    }
  }
  info.excitation.still_orientations = true;
  return info;
}

}  // namespace plumb::model::accel_linear

namespace plumb::model {

class AccelLinear : public EffectBase<AccelLinear> {
 public:
  explicit AccelLinear(const std::string& option)
      : EffectBase(accel_linear::Describe(option)), full_(option == "full") {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    const Mat3T<T> F = accel_linear::Matrix(theta, full_);
    Eigen::Map<const Vec3T<T>> b_a(theta + accel_linear::kBias);
    out.F = F;
    out.acc = F * in.f_b + b_a;
  }

 private:
  bool full_;
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(accel_linear, ::plumb::model::AccelLinear)

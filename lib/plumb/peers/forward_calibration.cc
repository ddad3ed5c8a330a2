#include "plumb/peers/forward_calibration.h"

#include <Eigen/LU>

#include "plumb/core/error.h"

namespace plumb::peers {
namespace {

void AppendMatrix(const std::string& prefix, const Mat3& m, std::vector<NamedValue>& out) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      out.push_back({prefix + kAxisName[r] + kAxisName[c], m(r, c)});
    }
  }
}

void AppendVector(const std::string& prefix, const Vec3& v, std::vector<NamedValue>& out) {
  for (int i = 0; i < 3; ++i) out.push_back({prefix + kAxisName[i], v(i)});
}

}  // namespace

std::vector<NamedValue> ForwardParameters(const ForwardCalibration& c) {
  std::vector<NamedValue> out;
  AppendMatrix("accel.matrix.", c.accel_matrix, out);
  AppendVector("accel.bias.", c.accel_bias, out);
  if (c.has_gyro) {
    AppendMatrix("gyro.matrix.", c.gyro_matrix, out);
    AppendVector("gyro.bias.", c.gyro_bias, out);
    if (c.has_g_sensitivity) AppendMatrix("gyro_g_sensitivity.G.", c.g_sensitivity, out);
  }
  return out;
}

Mat3 UpperTriangularFrame(const Mat3& M, Mat3& R_peer_b) {
  if (!(M.determinant() > 0.0)) {
    throw Error("the peer's accelerometer matrix is singular or a reflection (determinant " +
                std::to_string(M.determinant()) + "); cannot express it in plumb's frame");
  }
  // F = M Q with Q = R_peer_b: F's row z is (0, 0, F_zz), so Q's z column is along M's z row;
  // F_yx = 0, so Q's x column is orthogonal to M's y row; Q = [q_x q_y q_z] right-handed.
  const Vec3 q_z = M.row(2).transpose().normalized();
  const Vec3 m_y = M.row(1).transpose();
  const Vec3 q_y = (m_y - m_y.dot(q_z) * q_z).normalized();
  const Vec3 q_x = q_y.cross(q_z);
  R_peer_b.col(0) = q_x;
  R_peer_b.col(1) = q_y;
  R_peer_b.col(2) = q_z;
  Mat3 F = M * R_peer_b;
  // Exact zeros below the diagonal (they are rounding noise of order 1e-16 |M|).
  F(1, 0) = F(2, 0) = F(2, 1) = 0.0;
  return F;
}

}  // namespace plumb::peers

// plumb/residuals/strapdown.cc — see strapdown.h.
#include "plumb/residuals/strapdown.h"

namespace plumb::residuals::strapdown {

Mat3 IntegratedRotation(const std::vector<double>& t_s, const std::vector<Vec3>& w_b,
                        const Vec3& omega_b0) {
  if (omega_b0.squaredNorm() == 0.0) {
    // Without Earth rate a value needs no 3 x 3 matrix per step: the same rotation to rounding.
    Quat dR = Quat::Identity();
    for (std::size_t i = 0; i + 1 < t_s.size(); ++i) {
      dR *= so3::ExpQuat(so3::ConingIncrement(w_b[i], w_b[i + 1], t_s[i + 1] - t_s[i]));
    }
    return dR.normalized().toRotationMatrix();
  }
  Mat3 dR = Mat3::Identity();
  for (std::size_t i = 0; i + 1 < t_s.size(); ++i) {
    const Vec3 e = dR.transpose() * omega_b0;  // held over the step
    dR = dR * so3::Exp(so3::ConingIncrement(w_b[i] - e, w_b[i + 1] - e, t_s[i + 1] - t_s[i]));
  }
  return dR;
}

}  // namespace plumb::residuals::strapdown

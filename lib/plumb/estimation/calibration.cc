#include "plumb/estimation/calibration.h"

#include <Eigen/Core>
#include <cmath>

#include "plumb/model/board_mount.h"
#include "plumb/model/effects/accel_linear.h"
#include "plumb/model/effects/gyro_linear.h"

namespace plumb::estimation {

const char* LevelSourceName(LevelSource source) {
  switch (source) {
    case LevelSource::kNone: return "none";
    case LevelSource::kGiven: return "given";
    case LevelSource::kMeasured: return "allan";
    case LevelSource::kBounded: return "allan_bound";
    case LevelSource::kTypical: return "typical";
    case LevelSource::kEstimated: return "estimated";
  }
  return "none";
}

namespace {

// The forward quantities of SPEC section 1 from a model's blocks (IMU 0's, or a board IMU's,
// whose blocks end with its mount's, which the model does not read).
Mat3 AccelMatrixOf(const model::Model& model, const model::ParameterBlocks& theta) {
  return model.Predict(theta, model::SensorInput<double>()).F;
}

Vec3 AccelBiasOf(const model::Model& model, const model::ParameterBlocks& theta) {
  const int t = model.BaseTerm(model::Sensor::kAccel);
  return t < 0 ? Vec3::Zero() : model::accel_linear::Bias(theta[static_cast<std::size_t>(t)]);
}

Mat3 GyroMatrixOf(const model::Model& model, const model::ParameterBlocks& theta, bool has_gyro) {
  if (!has_gyro) return Mat3::Identity();
  return model.Predict(theta, model::SensorInput<double>()).E;
}

Vec3 GyroBiasOf(const model::Model& model, const model::ParameterBlocks& theta, bool has_gyro) {
  const int t = model.BaseTerm(model::Sensor::kGyro);
  if (!has_gyro || t < 0) return Vec3::Zero();
  return model::gyro_linear::Bias(theta[static_cast<std::size_t>(t)]);
}

}  // namespace

Mat3 Calibration::AccelMatrix() const { return AccelMatrixOf(model, theta); }
Vec3 Calibration::AccelBias() const { return AccelBiasOf(model, theta); }
Mat3 Calibration::GyroMatrix() const { return GyroMatrixOf(model, theta, has_gyro); }
Vec3 Calibration::GyroBias() const { return GyroBiasOf(model, theta, has_gyro); }

Quat BoardImuCalibration::R_b_i() const {
  return model::board_mount::Rotation(theta.back().data());
}

const ParameterEstimate& BoardImuCalibration::MountParameter(int index) const {
  return parameters.at(parameters.size() - model::board_mount::kSize +
                       static_cast<std::size_t>(index));
}

bool BoardImuCalibration::RotationDetermined() const {
  for (int i = 0; i < 3; ++i) {
    const ParameterEstimate& p = MountParameter(model::board_mount::kRotation + i);
    if (!p.observable || !std::isfinite(p.sigma)) return false;
  }
  return true;
}

Vec3 BoardImuCalibration::LeverArm() const {
  return Eigen::Map<const Vec3>(theta.back().data() + model::board_mount::kLeverArm);
}

double BoardImuCalibration::TimeOffset() const {
  return theta.back()[model::board_mount::kTimeOffset];
}

Mat3 BoardImuCalibration::AccelMatrix() const { return AccelMatrixOf(model, theta); }
Vec3 BoardImuCalibration::AccelBias() const { return AccelBiasOf(model, theta); }
Mat3 BoardImuCalibration::GyroMatrix() const { return GyroMatrixOf(model, theta, has_gyro); }
Vec3 BoardImuCalibration::GyroBias() const { return GyroBiasOf(model, theta, has_gyro); }

}  // namespace plumb::estimation

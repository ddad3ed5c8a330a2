#include "plumb/correction/calibration_file.h"

#include <algorithm>
#include <array>

#include "plumb/core/calibration_checks.h"
#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/model/board_mount.h"

namespace plumb::correction {
namespace {

std::string KeyPlace(const std::string& name) { return "key '" + name + "'"; }

/// The board mount's description (model/board_mount.h): its parameters' names.
const model::EffectInfo& MountInfo() {
  static const model::EffectInfo info = model::board_mount::Describe();
  return info;
}

/// The message of a key a calibration to apply requires and the document lacks.
std::string Missing() {
  return "missing: not a calibration written by " + OptionText(Option::kCalibrationJson);
}

/// The checks of core/calibration_checks.h on the sensors' matrices of `out`, as the
/// parameters give them.
void CheckMatrices(const CalibrationFile& out) {
  const model::SensorOutput<double> linear =
      out.model.Predict(out.theta, model::SensorInput<double>());
  if (const std::string p = SensorMatrixProblem(linear.F); !p.empty()) {
    throw InputError(out.path, "key 'parameters' (accel.matrix.*)",
                     "the accelerometer's matrix is " + p + ": not a calibration to apply");
  }
  if (!out.model.has_gyro()) return;
  if (const std::string p = SensorMatrixProblem(linear.E); !p.empty()) {
    throw InputError(out.path, "key 'parameters' (gyro.matrix.*)",
                     "the gyroscope's matrix is " + p + ": not a calibration to apply");
  }
}

}  // namespace

CalibrationFile CalibrationFromDocument(const document::CalibrationDocument& d) {
  const std::string& path = d.path;
  CalibrationFile out;
  out.path = path;
  if (!d.has_model) throw InputError(path, KeyPlace("model"), Missing(), {Option::kCalibrationJson});
  if (!d.model) throw InputError(path, KeyPlace("model"), d.model_problem);
  out.model = *d.model;
  if (!d.reference) {
    throw InputError(path, KeyPlace("model_reference"), Missing(), {Option::kCalibrationJson});
  }
  out.model.t_ref_s = d.reference->t_ref_s;
  out.model.temp_ref_c = d.reference->temp_ref_c;
  // An accelerometer-only session's fit dropped the gyroscope terms of its spec.
  const bool gyro_values = std::any_of(
      d.parameters.begin(), d.parameters.end(),
      [](const document::DocumentParameter& p) { return p.name.rfind("gyro", 0) == 0; });
  if (!gyro_values && out.model.has_gyro()) out.model.DropGyro();
  out.theta = out.model.ZeroParameters();
  const std::vector<std::string> names = out.model.ParameterNames();
  std::vector<bool> seen(names.size(), false);
  for (std::size_t k = 0; k < d.parameters.size(); ++k) {
    const document::DocumentParameter& p = d.parameters[k];
    const auto where = out.model.FindParameter(p.name);
    if (!where) {
      throw InputError(path, KeyPlace("parameters[" + std::to_string(k) + "].name"),
                       "'" + p.name + "' is not a parameter of the model '" + out.model.spec() +
                           "'");
    }
    const auto [t, i] = *where;
    const model::ParameterInfo& info = out.model.terms()[static_cast<std::size_t>(t)]
                                           .effect->info()
                                           .parameters[static_cast<std::size_t>(i)];
    out.theta[static_cast<std::size_t>(t)][static_cast<std::size_t>(i)] = p.value - info.nominal;
    seen[static_cast<std::size_t>(std::find(names.begin(), names.end(), p.name) - names.begin())] =
        true;
    if (!p.unit.empty()) {
      if (p.name == "accel.bias.x") out.acc_unit = p.unit;
      if (p.name == "gyro.bias.x") out.gyr_unit = p.unit;
    }
  }
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (!seen[j]) throw InputError(path, KeyPlace("parameters"), "no value for '" + names[j] + "'");
  }
  for (const document::DocumentParameter& p : d.parameters) {
    if (!p.observable && !p.fixed) out.undetermined.push_back(p.name);
  }
  CheckMatrices(out);
  for (std::size_t i = 0; i < d.covariance_names.size(); ++i) {
    if (!out.model.FindParameter(d.covariance_names[i])) {
      throw InputError(path, KeyPlace("covariance.parameters[" + std::to_string(i) + "]"),
                       "'" + d.covariance_names[i] + "' is not a parameter of the model '" +
                           out.model.spec() + "'");
    }
  }
  out.covariance_names = d.covariance_names;
  out.covariance = d.covariance;
  return out;
}

CalibrationFile ReadCalibrationFile(const nlohmann::json& doc, const std::string& path) {
  document::ReadOptions options;
  options.still_segments = false;  // apply reads no segment (a truth document's are poses)
  return CalibrationFromDocument(document::ReadCalibrationDocument(doc, path, options));
}

namespace {

/// The mount's rotation vector from its parameters "rotation.x|y|z".
Vec3 MountRotation(const document::BoardImuDocument& imu, const std::string& path) {
  Vec3 rho = Vec3::Zero();
  std::array<bool, 3> given = {false, false, false};
  for (const document::DocumentParameter& p : imu.mount) {
    if (const auto axis = MountRotationAxis(p.name)) {
      rho[*axis] = p.value;
      given[static_cast<std::size_t>(*axis)] = true;
    }
  }
  for (int a = 0; a < 3; ++a) {
    if (given[static_cast<std::size_t>(a)]) continue;
    const std::string name = MountInfo().parameters[static_cast<std::size_t>(
                                                     model::board_mount::kRotation + a)]
                                 .name;
    throw InputError(path, KeyPlace("imus"), "IMU " + std::to_string(imu.instance) +
                                                 " has no value for 'imu" +
                                                 std::to_string(imu.instance) + "." + name + "'");
  }
  return rho;
}

/// The block of the board's covariance over IMU k's free, observable parameters of `file`'s
/// model and its rotation, prefix taken off (the lever arm and time offset move no corrected
/// sample), as a lone IMU's "covariance" is over its determined parameters; an unobservable
/// rotation axis joins CalibrationFile::undetermined.
void SetBoardCovariance(const document::BoardDocument& board,
                        const document::BoardImuDocument& imu, CalibrationFile& file) {
  const std::string prefix = "imu" + std::to_string(imu.instance) + ".";
  std::vector<document::DocumentParameter> own_parameters = imu.document.parameters;
  own_parameters.insert(own_parameters.end(), imu.mount.begin(), imu.mount.end());
  const auto entry = [&](const std::string& name) -> const document::DocumentParameter* {
    for (const auto& p : own_parameters) {
      if (p.name == name) return &p;
    }
    return nullptr;
  };
  std::vector<Eigen::Index> rows;
  file.covariance_names.clear();
  file.covariance.resize(0, 0);
  for (std::size_t i = 0; i < board.covariance_names.size(); ++i) {
    const std::string& name = board.covariance_names[i];
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string own = name.substr(prefix.size());
    const bool rotation = MountRotationAxis(own).has_value();
    if (!file.model.FindParameter(own) && !rotation) continue;
    const document::DocumentParameter* p = entry(own);
    if (p != nullptr && p->fixed) continue;
    if (p != nullptr && !p->observable) {
      if (rotation) file.undetermined.push_back(own);
      continue;
    }
    rows.push_back(static_cast<Eigen::Index>(i));
    file.covariance_names.push_back(own);
  }
  const auto n = static_cast<Eigen::Index>(rows.size());
  file.covariance.resize(n, n);
  for (Eigen::Index r = 0; r < n; ++r) {
    for (Eigen::Index c = 0; c < n; ++c) file.covariance(r, c) = board.covariance(rows[r], rows[c]);
  }
}

}  // namespace

const CalibrationFile& ImuCalibration(const std::vector<CalibrationFile>& board, int instance) {
  std::string have;
  for (const CalibrationFile& c : board) {
    if (c.instance == instance) return c;
    have += (have.empty() ? "" : ", ") + std::to_string(c.instance);
  }
  throw InputError(board.front().path, KeyPlace("imus"),
                   "no calibration of IMU " + std::to_string(instance) + " (it calibrates IMU " +
                       have + "): choose the IMUs it calibrates (" + OptionText(Option::kImus) +
                       "), or calibrate the board with them",
                   {Option::kImus});
}

std::optional<int> MountRotationAxis(const std::string& name) {
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(model::board_mount::kRotation + a);
    if (MountInfo().parameters[i].name == name) return a;
  }
  return std::nullopt;
}

std::vector<CalibrationFile> ReadBoardCalibrationFile(const nlohmann::json& doc,
                                                      const std::string& path) {
  std::vector<CalibrationFile> out = {ReadCalibrationFile(doc, path)};
  const document::BoardDocument board = document::ReadBoardDocument(doc, path);
  for (const document::BoardImuDocument& imu : board.imus) {
    CalibrationFile file = CalibrationFromDocument(imu.document);
    file.instance = imu.instance;
    file.mount_rotation = MountRotation(imu, path);
    SetBoardCovariance(board, imu, file);
    out.push_back(std::move(file));
  }
  return out;
}

}  // namespace plumb::correction

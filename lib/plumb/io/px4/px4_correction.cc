// plumb/io/px4/px4_correction.cc — see px4_correction.h.
#include "plumb/io/px4/px4_correction.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/io/common/log_common.h"

namespace plumb::io {
namespace {

constexpr int kMaxCalSlots = 4;  // CAL_ACC0..CAL_ACC3, TC_A0..TC_A3

using Params = std::map<std::string, double>;

std::optional<double> Param(const Params& params, const std::string& name) {
  const auto it = params.find(name);
  if (it == params.end()) return std::nullopt;
  return it->second;
}

/// A parameter or id value as integer text (any double, NaN and huge values included).
std::string Integer(double v) {
  std::ostringstream out;
  out.precision(0);
  out << std::fixed << v;
  return out.str();
}

std::string Format(const Vec3& v) {
  std::ostringstream out;
  out.precision(9);
  out << v.x() << ", " << v.y() << ", " << v.z();
  return out.str();
}

/// The rotation R of a calibration whose offsets and scales are read: CAL_*n_ROT when >= 0,
/// else the board rotation. False with `*why` set when the rotation is not one PX4 defines.
bool ReadRotation(const Params& params, Px4Calibration* c, std::string* why) {
  const auto cal_rot = Param(params, c->prefix + "_ROT");
  if (cal_rot && *cal_rot >= 0) {
    const auto euler = Px4RotationEuler(*cal_rot);
    if (!euler) {
      *why = c->prefix + "_ROT = " + Integer(*cal_rot) + " is not a rotation plumb knows";
      return false;
    }
    c->rotation = Px4EulerRotation(*euler);
    c->rotation_text = c->prefix + "_ROT = " + Integer(*cal_rot);
    return true;
  }
  const double board = Param(params, "SENS_BOARD_ROT").value_or(0.0);
  const auto euler = Px4RotationEuler(board);
  if (!euler) {
    *why = "SENS_BOARD_ROT = " + Integer(board) + " is not a rotation plumb knows";
    return false;
  }
  const Vec3 trim(Param(params, "SENS_BOARD_X_OFF").value_or(0.0),
                  Param(params, "SENS_BOARD_Y_OFF").value_or(0.0),
                  Param(params, "SENS_BOARD_Z_OFF").value_or(0.0));
  c->rotation = Px4EulerRotation(trim) * Px4EulerRotation(*euler);
  c->rotation_text = "SENS_BOARD_ROT = " + Integer(board) + ", SENS_BOARD_X/Y/Z_OFF = " +
                     Format(trim) + " deg";
  return true;
}

std::optional<Px4Calibration> CalibrationOf(const Params& params, const Px4Sensors& sensors,
                                            bool acc, std::string* why) {
  return Px4CalibrationFor(params, acc ? "ACC" : "GYRO", acc ? sensors.acc_id : sensors.gyr_id,
                           acc ? sensors.acc_id_source : sensors.gyr_id_source, why);
}

/// Undoes the correction of one sensor (accelerometer when `acc`), with its warnings.
void UndoSensor(const Params& params, const Px4Sensors& sensors, bool acc,
                const std::string& who, ImuSeries* series, std::vector<Notice>* warnings,
                std::vector<std::string>* left) {
  const std::string what = acc ? "accelerometer" : "gyroscope";
  std::string why;
  const auto c = CalibrationOf(params, sensors, acc, &why);
  if (!c) {
    AddNotice(*warnings, "correction_kept",
        who + what + " taken as logged (calibrated by PX4; not undone: " + why + ")");
    left->push_back(who + "PX4 " + what + " calibration (" + why + ")");
    return;
  }
  // Thermal compensation (TC_A_ENABLE / TC_G_ENABLE = 1) at the sensor's logged temperature.
  const std::string tc = acc ? "TC_A_ENABLE" : "TC_G_ENABLE";
  std::optional<Px4Thermal> thermal;
  std::optional<Px4TemperatureTrack> temp;
  std::string thermal_text;
  if (Param(params, tc).value_or(0.0) == 1.0) {
    std::string tc_why;
    thermal = Px4ThermalFor(params, acc ? "A" : "G", c->device_id, &tc_why);
    temp = thermal ? sensors.temperature(acc, c->device_id) : std::nullopt;
    if (!thermal || !temp) {
      if (thermal) tc_why = "no temperature of device " + Integer(c->device_id) + " in the log";
      AddNotice(*warnings, "correction_not_undone",
          who + tc + " = 1: PX4's thermal " + what +
              " correction is in the samples and NOT undone (" + tc_why + ")");
      left->push_back(who + "PX4 thermal " + what + " correction (" + tc_why + ")");
      thermal.reset();
    } else {
      thermal_text = " + thermal offset " + thermal->prefix + "_X0..X3 (X0 " +
                     Format(thermal->x[0]) + ", X1 " + Format(thermal->x[1]) + ", X2 " +
                     Format(thermal->x[2]) + ", X3 " + Format(thermal->x[3]) + ", TREF " +
                     Number(thermal->t_ref_c) + " degC, clamped to [" +
                     Number(thermal->t_min_c) + ", " +
                     Number(thermal->t_max_c) + "]) at the temperature of " +
                     temp->source;
    }
  }
  UndoPx4Calibration(*c, thermal, temp, series->t_s, acc ? &series->acc : &series->gyr);
  const std::string unit = acc ? " m/s^2" : " rad/s";
  AddNotice(*warnings, "correction_undone",
      who + what + " reconstructed as R^T logged ./ " + c->prefix + "_*SCALE (" +
          Format(c->scale) + ") + " + c->prefix + "_*OFF (" + Format(c->offset) + ")" + unit +
          thermal_text + ", R from " + c->rotation_text + "; " + c->prefix +
          " chosen by device id " + Integer(c->device_id) + " from " + c->id_source);
}

}  // namespace

std::optional<Vec3> Px4RotationEuler(double value) {
  if (!(value >= 0.0 && value <= 25.0) || value != std::floor(value)) return std::nullopt;
  const int k = static_cast<int>(value);
  static const double kTable[26][3] = {
      {0, 0, 0},     {0, 0, 45},    {0, 0, 90},    {0, 0, 135},   {0, 0, 180},
      {0, 0, 225},   {0, 0, 270},   {0, 0, 315},   {180, 0, 0},   {180, 0, 45},
      {180, 0, 90},  {180, 0, 135}, {0, 180, 0},   {180, 0, 225}, {180, 0, 270},
      {180, 0, 315}, {90, 0, 0},    {90, 0, 45},   {90, 0, 90},   {90, 0, 135},
      {270, 0, 0},   {270, 0, 45},  {270, 0, 90},  {270, 0, 135}, {0, 90, 0},
      {0, 270, 0}};
  return Vec3(kTable[k][0], kTable[k][1], kTable[k][2]);
}

Mat3 Px4EulerRotation(const Vec3& rpy_deg) {
  const Vec3 r = rpy_deg * units::kRadPerDeg;
  return (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

std::optional<Px4Calibration> Px4CalibrationFor(const Params& params, const std::string& kind,
                                                std::optional<double> device_id,
                                                const std::string& id_source, std::string* why) {
  int slot = -1;
  if (device_id) {
    for (int n = 0; n < kMaxCalSlots; ++n) {
      const auto cal_id = Param(params, "CAL_" + kind + std::to_string(n) + "_ID");
      if (cal_id && *cal_id == *device_id) {
        slot = n;
        break;
      }
    }
  }
  if (slot < 0) {
    *why = device_id ? "no CAL_" + kind + "n_ID equals the device id " + Integer(*device_id) +
                           " (from " + id_source + ")"
                     : "the log does not say which sensor it is (no device id)";
    return std::nullopt;
  }
  Px4Calibration c;
  c.prefix = "CAL_" + kind + std::to_string(slot);
  c.device_id = *device_id;
  c.id_source = id_source;
  const char* axes[3] = {"X", "Y", "Z"};
  for (int i = 0; i < 3; ++i) {
    const auto off = Param(params, c.prefix + "_" + axes[i] + "OFF");
    if (!off) {
      *why = c.prefix + "_" + axes[i] + "OFF is not in the log";
      return std::nullopt;
    }
    c.offset[i] = *off;
    c.scale[i] = Param(params, c.prefix + "_" + axes[i] + "SCALE").value_or(1.0);
  }
  if ((c.scale.array() == 0.0).any() || !c.scale.allFinite() || !c.offset.allFinite()) {
    *why = c.prefix + " has a zero or non-finite scale or offset";
    return std::nullopt;
  }
  if (!ReadRotation(params, &c, why)) return std::nullopt;
  return c;
}

Vec3 Px4Thermal::Offset(double temp_c) const {
  const double dt = std::clamp(temp_c, t_min_c, std::max(t_min_c, t_max_c)) - t_ref_c;
  return x[0] + dt * (x[1] + dt * (x[2] + dt * x[3]));
}

std::optional<Px4Thermal> Px4ThermalFor(const Params& params, const std::string& kind,
                                        double device_id, std::string* why) {
  for (int n = 0; n < kMaxCalSlots; ++n) {
    const std::string prefix = "TC_" + kind + std::to_string(n);
    const auto id = Param(params, prefix + "_ID");
    if (!id || *id != device_id) continue;
    Px4Thermal t;
    t.prefix = prefix;
    const auto ref = Param(params, prefix + "_TREF");
    const auto tmin = Param(params, prefix + "_TMIN");
    const auto tmax = Param(params, prefix + "_TMAX");
    if (!ref || !tmin || !tmax) {
      *why = prefix + "_TREF/TMIN/TMAX missing";
      return std::nullopt;
    }
    t.t_ref_c = *ref;
    t.t_min_c = *tmin;
    t.t_max_c = *tmax;
    for (int k = 0; k < 4; ++k) {
      for (int i = 0; i < 3; ++i) {
        const std::string name = prefix + "_X" + std::to_string(k) + "_" + std::to_string(i);
        const auto v = Param(params, name);
        if (!v) {
          *why = name + " missing";
          return std::nullopt;
        }
        t.x[static_cast<std::size_t>(k)][i] = *v;
      }
    }
    return t;
  }
  *why = "no TC_" + kind + "n_ID equals the device id " + Integer(device_id);
  return std::nullopt;
}

double Px4TemperatureTrack::At(double t) const {
  const auto it = std::upper_bound(t_s.begin(), t_s.end(), t);
  const std::size_t i = it == t_s.begin() ? 0 : static_cast<std::size_t>(it - t_s.begin()) - 1;
  return temp_c[i];
}

void UndoPx4Calibration(const Px4Calibration& c, const std::optional<Px4Thermal>& thermal,
                        const std::optional<Px4TemperatureTrack>& temp,
                        const std::vector<double>& t_s, std::vector<Vec3f>* v) {
  const Mat3 rt = c.rotation.transpose();
  for (std::size_t k = 0; k < v->size(); ++k) {
    Vec3 m = (rt * (*v)[k].cast<double>()).cwiseQuotient(c.scale) + c.offset;
    if (thermal && temp) m += thermal->Offset(temp->At(t_s[k]));
    (*v)[k] = SaturatedFloat(m);
  }
}

std::string Px4AppliedText(const Params& params, const Px4Sensors& sensors) {
  std::string acc_why, gyr_why;
  const auto acc = CalibrationOf(params, sensors, true, &acc_why);
  const auto gyr = CalibrationOf(params, sensors, false, &gyr_why);
  std::string out = acc ? acc->prefix + "_*" : "CAL_ACCn_*";
  out += ", ";
  out += gyr ? gyr->prefix + "_*" : "CAL_GYROn_*";
  out += ", board rotation";
  if (Param(params, "TC_A_ENABLE").value_or(0.0) == 1.0) out += ", TC_A* thermal";
  if (Param(params, "TC_G_ENABLE").value_or(0.0) == 1.0) out += ", TC_G* thermal";
  return out;
}

bool Px4Undoable(const Params& params, const Px4Sensors& sensors, bool gyro) {
  std::string a, g;
  return CalibrationOf(params, sensors, true, &a).has_value() &&
         (!gyro || CalibrationOf(params, sensors, false, &g).has_value());
}

void UndoPx4Correction(const Params& params, const Px4Sensors& sensors, const std::string& who,
                       ImuSeries* series, std::vector<Notice>* warnings,
                       std::vector<std::string>* left) {
  UndoSensor(params, sensors, true, who, series, warnings, left);
  if (series->has_gyro()) UndoSensor(params, sensors, false, who, series, warnings, left);
}

}  // namespace plumb::io

// plumb/io/ardupilot/ardupilot_correction.cc — see ardupilot_correction.h.
#include "plumb/io/ardupilot/ardupilot_correction.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/units.h"

namespace plumb::io {
namespace {

/// One entry of ArduPilot's Rotation enum: name and Euler angles, degrees.
struct RotationEntry {
  const char* name;
  double roll_deg;
  double pitch_deg;
  double yaw_deg;
};

// libraries/AP_Math/rotations.h, values 0..43 in enum order.
constexpr RotationEntry kRotations[] = {
    {"NONE", 0, 0, 0},
    {"YAW_45", 0, 0, 45},
    {"YAW_90", 0, 0, 90},
    {"YAW_135", 0, 0, 135},
    {"YAW_180", 0, 0, 180},
    {"YAW_225", 0, 0, 225},
    {"YAW_270", 0, 0, 270},
    {"YAW_315", 0, 0, 315},
    {"ROLL_180", 180, 0, 0},
    {"ROLL_180_YAW_45", 180, 0, 45},
    {"ROLL_180_YAW_90", 180, 0, 90},
    {"ROLL_180_YAW_135", 180, 0, 135},
    {"PITCH_180", 0, 180, 0},
    {"ROLL_180_YAW_225", 180, 0, 225},
    {"ROLL_180_YAW_270", 180, 0, 270},
    {"ROLL_180_YAW_315", 180, 0, 315},
    {"ROLL_90", 90, 0, 0},
    {"ROLL_90_YAW_45", 90, 0, 45},
    {"ROLL_90_YAW_90", 90, 0, 90},
    {"ROLL_90_YAW_135", 90, 0, 135},
    {"ROLL_270", 270, 0, 0},
    {"ROLL_270_YAW_45", 270, 0, 45},
    {"ROLL_270_YAW_90", 270, 0, 90},
    {"ROLL_270_YAW_135", 270, 0, 135},
    {"PITCH_90", 0, 90, 0},
    {"PITCH_270", 0, 270, 0},
    {"PITCH_180_YAW_90", 0, 180, 90},
    {"PITCH_180_YAW_270", 0, 180, 270},
    {"ROLL_90_PITCH_90", 90, 90, 0},
    {"ROLL_180_PITCH_90", 180, 90, 0},
    {"ROLL_270_PITCH_90", 270, 90, 0},
    {"ROLL_90_PITCH_180", 90, 180, 0},
    {"ROLL_270_PITCH_180", 270, 180, 0},
    {"ROLL_90_PITCH_270", 90, 270, 0},
    {"ROLL_180_PITCH_270", 180, 270, 0},
    {"ROLL_270_PITCH_270", 270, 270, 0},
    {"ROLL_90_PITCH_180_YAW_90", 90, 180, 90},
    {"ROLL_90_YAW_270", 90, 0, 270},
    {"ROLL_90_PITCH_68_YAW_293", 90, 68.8, 293.3},  // ArduPilot: "actually 68.8, 293.3"
    {"PITCH_315", 0, 315, 0},
    {"ROLL_90_PITCH_315", 90, 315, 0},
    {"PITCH_7", 0, 7, 0},
    {"ROLL_45", 45, 0, 0},
    {"ROLL_315", 315, 0, 0},
};
constexpr int kRotationCount = static_cast<int>(sizeof(kRotations) / sizeof(kRotations[0]));
constexpr int kCustomFirst = 100;  // ROTATION_CUSTOM_OLD
constexpr int kCustomLast = 102;   // ROTATION_CUSTOM_2

constexpr double kTcalReference_degc = 35.0;  // TEMP_REFERENCE
constexpr double kTcalScale = 1e-6;           // INV_SCALE_FACTOR

/// cos and sin of a whole-degree multiple of 90 exactly, else of the angle.
void CosSin(double deg, double* c, double* s) {
  const double quarter = deg / 90.0;
  if (quarter == std::floor(quarter)) {
    static constexpr double kCos[] = {1, 0, -1, 0};
    static constexpr double kSin[] = {0, 1, 0, -1};
    const int q = static_cast<int>(std::fmod(std::fmod(quarter, 4.0) + 4.0, 4.0));
    *c = kCos[q];
    *s = kSin[q];
    return;
  }
  *c = std::cos(deg * units::kRadPerDeg);
  *s = std::sin(deg * units::kRadPerDeg);
}

std::optional<double> Param(const std::map<std::string, double>& params, const std::string& name) {
  const auto it = params.find(name);
  if (it == params.end()) return std::nullopt;
  return it->second;
}

std::optional<Vec3> Triad(const std::map<std::string, double>& params, const std::string& name) {
  Vec3 v;
  const char* axes[3] = {"_X", "_Y", "_Z"};
  for (int i = 0; i < 3; ++i) {
    const auto value = Param(params, name + axes[i]);
    if (!value || !std::isfinite(*value)) return std::nullopt;  // NaN is as good as absent
    v[i] = *value;
  }
  return v;
}

/// "INS_ACC", "INS_ACC2", "INS_ACC3" for kind "ACC" and instance 0, 1, 2 (likewise "GYR").
std::string Prefix(const std::string& kind, int instance) {
  return "INS_" + kind + (instance == 0 ? "" : std::to_string(instance + 1));
}

std::optional<ArdupilotTempCal> ReadTempCal(const std::map<std::string, double>& params,
                                            int instance) {
  const std::string n = std::to_string(instance + 1);
  const std::string p = "INS_TCAL" + n + "_";
  ArdupilotTempCal t;
  const auto t_min = Param(params, p + "TMIN");
  const auto t_max = Param(params, p + "TMAX");
  if (!t_min || !t_max) return std::nullopt;
  t.t_min_degc = *t_min;
  t.t_max_degc = *t_max;
  for (int k = 0; k < 3; ++k) {
    const auto acc = Triad(params, p + "ACC" + std::to_string(k + 1));
    const auto gyr = Triad(params, p + "GYR" + std::to_string(k + 1));
    if (!acc || !gyr) return std::nullopt;
    t.acc_coeff[static_cast<std::size_t>(k)] = *acc;
    t.gyr_coeff[static_cast<std::size_t>(k)] = *gyr;
  }
  t.acc_cal_temp_degc = Param(params, "INS_ACC" + n + "_CALTEMP").value_or(-300.0);
  t.gyr_cal_temp_degc = Param(params, "INS_GYR" + n + "_CALTEMP").value_or(-300.0);
  return t;
}

std::string Format(const Vec3& v) {
  std::ostringstream out;
  out.precision(9);
  out << v.x() << ", " << v.y() << ", " << v.z();
  return out.str();
}

std::string Format(const Mat3& m) {
  std::ostringstream out;
  out << "[" << Format(Vec3(m.row(0).transpose())) << "; "
      << Format(Vec3(m.row(1).transpose())) << "; " << Format(Vec3(m.row(2).transpose())) << "]";
  return out.str();
}

std::string Format(const std::array<Vec3, 3>& c) {
  return "c1 (" + Format(c[0]) + "), c2 (" + Format(c[1]) + "), c3 (" + Format(c[2]) + ")";
}

std::string Format(double v) {
  std::ostringstream out;
  out.precision(9);
  out << v;
  return out.str();
}


/// Step 1 of the undo: board = R_board^T logged.
void UndoRotation(const ArdupilotCorrection& c, const std::string& who, ImuSeries* series, std::vector<Notice>* warnings) {
  if (c.orientation == 0) return;
  const Mat3 Rt = c.R_board->transpose();
  for (auto& a : series->acc) a = (Rt * a.cast<double>()).cast<float>();
  for (auto& g : series->gyr) g = (Rt * g.cast<double>()).cast<float>();
  AddNotice(*warnings, "correction_undone",
      who + "AHRS_ORIENTATION = " + std::to_string(c.orientation) + " (" +
          ArdupilotRotationName(c.orientation) + ") undone: board = R^T logged, R = " +
          Format(*c.R_board));
}

/// Step 2: offsets and scales.
void UndoOffsets(const ArdupilotCorrection& c, const std::string& who, ImuSeries* series, std::vector<Notice>* warnings) {
  const std::string acc = Prefix("ACC", c.instance);
  const std::string gyr = Prefix("GYR", c.instance);
  if (c.acc_offset && c.acc_scale) {
    for (auto& a : series->acc) {
      a = (a.cast<double>().cwiseQuotient(*c.acc_scale) + *c.acc_offset).cast<float>();
    }
    AddNotice(*warnings, "correction_undone",
        who + "accelerometer reconstructed as logged ./ " + acc + "SCAL (" +
            Format(*c.acc_scale) + ") + " + acc + "OFFS (" + Format(*c.acc_offset) + ") m/s^2");
  } else {
    AddNotice(*warnings, "correction_not_undone",
        who + "no " + acc + "OFFS/" + acc +
            "SCAL in the log: accelerometer offsets/scales not undone");
  }
  if (!series->has_gyro()) return;
  if (c.gyr_offset) {
    for (auto& g : series->gyr) g = (g.cast<double>() + *c.gyr_offset).cast<float>();
    AddNotice(*warnings, "correction_undone",
        who + "gyroscope reconstructed as logged + " + gyr + "OFFS (" + Format(*c.gyr_offset) +
            ") rad/s");
  } else {
    AddNotice(*warnings, "correction_not_undone",
        who + "no " + gyr + "OFFS in the log: gyroscope offsets not undone");
  }
}

/// Step 3: the temperature calibration.
void UndoTempCal(const ArdupilotCorrection& c, const std::string& who, ImuSeries* series, std::vector<Notice>* warnings) {
  const std::string tcal = "INS_TCAL" + std::to_string(c.instance + 1);
  if (c.tcal_enable == 2) {
    AddNotice(*warnings, "correction_not_undone",
        who + tcal + "_ENABLE = 2 (learning): ArduPilot applied no temperature correction, "
                     "nothing to undo");
  }
  if (c.tcal_enable != 1) return;
  if (!c.tcal) {
    AddNotice(*warnings, "correction_not_undone",
        who + tcal + "_ENABLE = 1 but its TMIN/TMAX/ACC*/GYR* parameters are not all in the "
                     "log: temperature calibration not undone");
    return;
  }
  if (!series->has_temperature()) {
    AddNotice(*warnings, "correction_not_undone",
        who + tcal + "_ENABLE = 1 but the stream has no temperature: temperature calibration "
                     "not undone");
    return;
  }
  const ArdupilotTempCal& t = *c.tcal;
  ImuSeries& out = *series;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double temp_c = out.temp_c[i];
    out.acc[i] += ArdupilotTcalCorrection(t, t.acc_coeff, temp_c, t.acc_cal_temp_degc)
                         .cast<float>();
    if (out.has_gyro()) {
      out.gyr[i] += ArdupilotTcalCorrection(t, t.gyr_coeff, temp_c, t.gyr_cal_temp_degc)
                           .cast<float>();
    }
  }
  AddNotice(*warnings, "correction_undone",
      who + tcal + " temperature calibration undone: sensor = corrected + P(clamp(T) - 35) - "
            "P(clamp(T_cal) - 35), P(d) = (c1 + (c2 + c3 d) d) d * 1e-6, clamp to [" +
      Format(t.t_min_degc) + ", " + Format(t.t_max_degc) + "] degC, T from the stream; "
      "accelerometer T_cal " + Format(t.acc_cal_temp_degc) + " degC, " + Format(t.acc_coeff) +
      "; gyroscope T_cal " + Format(t.gyr_cal_temp_degc) + " degC, " + Format(t.gyr_coeff));
}

}  // namespace

std::optional<Mat3> ArdupilotRotation(int rotation) {
  if (rotation < 0 || rotation >= kRotationCount) return std::nullopt;
  const RotationEntry& e = kRotations[rotation];
  double cr, sr, cp, sp, cy, sy;
  CosSin(e.roll_deg, &cr, &sr);
  CosSin(e.pitch_deg, &cp, &sp);
  CosSin(e.yaw_deg, &cy, &sy);
  Mat3 Rx, Ry, Rz;
  Rx << 1, 0, 0, 0, cr, -sr, 0, sr, cr;
  Ry << cp, 0, sp, 0, 1, 0, -sp, 0, cp;
  Rz << cy, -sy, 0, sy, cy, 0, 0, 0, 1;
  return Mat3(Rz * Ry * Rx);
}

std::string ArdupilotRotationName(int rotation) {
  if (rotation >= 0 && rotation < kRotationCount) return kRotations[rotation].name;
  if (rotation >= kCustomFirst && rotation <= kCustomLast) return "CUSTOM";
  return "unknown";
}

Vec3 ArdupilotTcalPolynomial(const std::array<Vec3, 3>& coeff, double d_degc) {
  return (coeff[0] + (coeff[1] + coeff[2] * d_degc) * d_degc) * d_degc * kTcalScale;
}

Vec3 ArdupilotTcalCorrection(const ArdupilotTempCal& tcal, const std::array<Vec3, 3>& coeff,
                             double temp_c, double cal_temp_c) {
  const auto clamp = [&](double t) { return std::clamp(t, tcal.t_min_degc, tcal.t_max_degc); };
  return ArdupilotTcalPolynomial(coeff, clamp(temp_c) - kTcalReference_degc) -
         ArdupilotTcalPolynomial(coeff, clamp(cal_temp_c) - kTcalReference_degc);
}

std::string ArdupilotCorrection::Describe(bool accel, bool gyro) const {
  std::string out;
  const auto add = [&](const std::string& part) { out += (out.empty() ? "" : ", ") + part; };
  if (accel) add(Prefix("ACC", instance) + "OFFS/" + Prefix("ACC", instance) + "SCAL");
  if (gyro) add(Prefix("GYR", instance) + "OFFS");
  if (orientation != 0) {
    add("AHRS_ORIENTATION=" + std::to_string(orientation) + " (" +
        ArdupilotRotationName(orientation) + ")");
  }
  if (tcal_enable == 1) add("INS_TCAL" + std::to_string(instance + 1));
  return out;
}

bool ArdupilotCorrection::Undoable(bool accel, bool gyro, bool temperature) const {
  if (!R_board) return false;
  if (accel && (!acc_offset || !acc_scale)) return false;
  if (gyro && !gyr_offset) return false;
  if (tcal_enable == 1 && (!tcal || !temperature)) return false;
  return true;
}

ArdupilotCorrection ArdupilotCorrectionFor(const std::map<std::string, double>& params,
                                           int instance) {
  ArdupilotCorrection c;
  c.instance = instance;
  c.acc_offset = Triad(params, Prefix("ACC", instance) + "OFFS");
  c.acc_scale = Triad(params, Prefix("ACC", instance) + "SCAL");
  if (c.acc_scale && !(c.acc_scale->array() != 0.0).all()) c.acc_scale.reset();
  c.gyr_offset = Triad(params, Prefix("GYR", instance) + "OFFS");
  const double orientation = Param(params, "AHRS_ORIENTATION").value_or(0.0);
  c.orientation = std::isfinite(orientation) && std::abs(orientation) < 1e6
                      ? static_cast<int>(orientation)
                      : -1;
  if (static_cast<double>(c.orientation) == orientation) {
    c.R_board = ArdupilotRotation(c.orientation);
  }
  const double enable =
      Param(params, "INS_TCAL" + std::to_string(instance + 1) + "_ENABLE").value_or(0.0);
  c.tcal_enable = enable == 1.0 ? 1 : enable == 2.0 ? 2 : enable == 0.0 ? 0 : -1;
  if (c.tcal_enable == 1) c.tcal = ReadTempCal(params, instance);
  return c;
}

std::vector<Notice> UndoArdupilotCorrection(const ArdupilotCorrection& c, bool undo,
                                            const std::string& who, ImuSeries* series,
                                            std::vector<std::string>* left) {
  std::vector<Notice> lines;
  std::vector<Notice>* warnings = &lines;
  const std::string applied = c.Describe(true, series->has_gyro());
  auto leave = [&](const std::string& what) {
    if (left != nullptr) left->push_back(who + "ArduPilot " + what);
  };
  if (!undo) {
    AddNotice(*warnings, "correction_kept",
        who + "samples taken as logged (ArduPilot applied " + applied + ")");
    leave(applied);
    return lines;
  }
  if (!c.R_board) {
    AddNotice(*warnings, "correction_not_undone",
        who + "AHRS_ORIENTATION = " + std::to_string(c.orientation) + " (" +
            ArdupilotRotationName(c.orientation) +
            ") is not a rotation plumb knows: ArduPilot's correction (" + applied +
            ") is not undone, samples taken as logged");
    leave(applied);
    return lines;
  }
  UndoRotation(c, who, series, warnings);
  UndoOffsets(c, who, series, warnings);
  UndoTempCal(c, who, series, warnings);
  const std::string acc = Prefix("ACC", c.instance);
  if (!c.acc_offset || !c.acc_scale) {
    leave(acc + "OFFS/" + acc + "SCAL (missing or not finite in the log)");
  }
  if (series->has_gyro() && !c.gyr_offset) {
    leave(Prefix("GYR", c.instance) + "OFFS (missing or not finite in the log)");
  }
  if (c.tcal_enable == 1 && (!c.tcal || !series->has_temperature())) {
    leave("INS_TCAL" + std::to_string(c.instance + 1) + " temperature calibration");
  }
  return lines;
}

}  // namespace plumb::io

#include "plumb/export/formats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <tuple>

#include "plumb/core/error.h"

namespace plumb::exporter {
namespace {

constexpr double kArdupilotTempReference_c = 35.0;  // TEMP_REFERENCE
constexpr double kArdupilotTcalScale = 1e6;         // SCALE_FACTOR
constexpr int kQgcTypeReal32 = 9;                    // MAV_PARAM_TYPE_REAL32
constexpr int kQgcTypeInt32 = 6;                     // MAV_PARAM_TYPE_INT32
const char* const kAxes[3] = {"X", "Y", "Z"};

std::string Number(double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", value);
  return buf;
}

/// ArduPilot's per-instance stems: INS_ACCOFFS / INS_ACC2OFFS / INS_ACC3OFFS ...
std::string ArduStem(const char* sensor, const char* what, int imu) {
  return std::string("INS_") + sensor + (imu == 0 ? "" : std::to_string(imu + 1)) + what;
}

void CheckArdupilotImu(int imu) {
  if (imu < 0 || imu > 2) {
    throw Error("ArduPilot export: IMU instance " + std::to_string(imu) +
                " has no INS_ parameters here (instances 0, 1, 2: INS_ACC, INS_ACC2, INS_ACC3)");
  }
}

void CheckPx4Imu(int slot) {
  if (slot < 0 || slot > 3) {
    throw Error("PX4 export: instance " + std::to_string(slot) +
                " has no CAL_ACC/TC_A parameters (PX4's calibration slots are 0..3)");
  }
}

double Get(const std::map<std::string, double>& values, const std::string& name) {
  const auto it = values.find(name);
  if (it == values.end()) throw Error("parameter " + name + " is missing");
  return it->second;
}

double GetOr(const std::map<std::string, double>& values, const std::string& name, double def) {
  const auto it = values.find(name);
  return it == values.end() ? def : it->second;
}

Vec3 GetVector(const std::map<std::string, double>& values, const std::string& stem) {
  return Vec3(Get(values, stem + "_X"), Get(values, stem + "_Y"), Get(values, stem + "_Z"));
}

void AddVector(ParameterSet& set, const std::string& stem, const Vec3& v) {
  for (int a = 0; a < 3; ++a) set.parameters.push_back({stem + "_" + kAxes[a], v[a], false});
}

/// Splits a line on any of `separators`, dropping empty fields.
std::vector<std::string> Fields(const std::string& line, const char* separators) {
  std::vector<std::string> out;
  std::string field;
  for (char ch : line) {
    if (std::string(separators).find(ch) != std::string::npos) {
      if (!field.empty()) out.push_back(field);
      field.clear();
    } else {
      field += ch;
    }
  }
  if (!field.empty()) out.push_back(field);
  return out;
}

/// A finite number filling the whole field, or throws InputError.
double ParseValue(const std::string& text, const std::string& path, int line_no) {
  std::istringstream in(text);
  double value = 0;
  in >> value;
  if (!in || !in.eof() || !std::isfinite(value)) {
    throw InputError(path, "line " + std::to_string(line_no),
                     "a finite number as the parameter value, got '" + text + "'");
  }
  return value;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::string line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

bool Skip(const std::string& line) {
  const auto first = line.find_first_not_of(" \t");
  return first == std::string::npos || line[first] == '#';
}

/// The part of `fw`'s sensor correction that ArduPilot stores: OFFS and the temperature
/// coefficients x1e6 about 35 degC, given the calibration temperature (see formats.h).
struct ArduSensor {
  Vec3 offset;
  std::array<Vec3, 3> coeff;  // ACC1..3 / GYR1..3, x1e6
};

ArduSensor ToArdupilot(const DiagonalCorrection& c, double cal_temp_c) {
  ArduSensor s{c.offset, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}};
  if (!c.has_thermal) return s;
  const TemperaturePolynomial about35 = Rebase(c.thermal, kArdupilotTempReference_c);
  for (int k = 0; k < 3; ++k) s.coeff[k] = about35.c[k + 1] * kArdupilotTcalScale;
  s.offset = c.offset + c.thermal.At(cal_temp_c);
  return s;
}

DiagonalCorrection FromArdupilot(const Vec3& offset, const std::array<Vec3, 3>& coeff,
                                 bool enabled, double cal_temp_c, double t_min_c,
                                 double t_max_c) {
  DiagonalCorrection c;
  c.offset = offset;
  if (!enabled) return c;
  c.has_thermal = true;
  c.temp_min_c = t_min_c;
  c.temp_max_c = t_max_c;
  c.thermal.t0_c = kArdupilotTempReference_c;
  for (int k = 0; k < 3; ++k) c.thermal.c[k + 1] = coeff[k] / kArdupilotTcalScale;
  // tcal(T) = p(T - 35) - p(Tcal - 35): the constant term is -p(Tcal - 35).
  c.thermal.c[0] = -c.thermal.At(std::clamp(cal_temp_c, t_min_c, t_max_c));
  return c;
}

}  // namespace

std::map<std::string, double> ParameterSet::Values() const {
  std::map<std::string, double> out;
  for (const Parameter& p : parameters) out[p.name] = p.value;
  return out;
}

ParameterSet ArdupilotParameters(const FirmwareCorrection& fw, int imu) {
  CheckArdupilotImu(imu);
  ParameterSet set;
  set.target = "ardupilot";
  set.imu = imu;
  const bool thermal = fw.accel.has_thermal || (fw.has_gyro && fw.gyro.has_thermal);
  const DiagonalCorrection& ranged = fw.accel.has_thermal ? fw.accel : fw.gyro;
  const double t_min = thermal ? ranged.temp_min_c : kNaN;
  const double t_max = thermal ? ranged.temp_max_c : kNaN;
  // Calibration temperature: plumb's reference, inside the range the firmware clamps to.
  const double cal_acc = fw.accel.has_thermal ? std::clamp(fw.accel.thermal.t0_c, t_min, t_max) : kNaN;
  const double cal_gyr = fw.gyro.has_thermal ? std::clamp(fw.gyro.thermal.t0_c, t_min, t_max) : kNaN;
  const ArduSensor acc = ToArdupilot(fw.accel, cal_acc);
  AddVector(set, ArduStem("ACC", "OFFS", imu), acc.offset);
  AddVector(set, ArduStem("ACC", "SCAL", imu), fw.accel.scale);
  ArduSensor gyr{Vec3::Zero(), {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}};
  if (fw.has_gyro) {
    gyr = ToArdupilot(fw.gyro, cal_gyr);
    AddVector(set, ArduStem("GYR", "OFFS", imu), gyr.offset);
  }
  AddNotice(set.notes, "parameters_written", "ArduPilot parameters from plumb for IMU instance " + std::to_string(imu) +
                      " (" + ArduStem("ACC", "", imu) + "...): acc = (acc_sensor - tcal(T) - " +
                      ArduStem("ACC", "OFFS", imu) + ") .* " + ArduStem("ACC", "SCAL", imu) +
                      ", gyr = gyr_sensor - tcal(T) - " + ArduStem("GYR", "OFFS", imu));
  if (!thermal) {
    AddNotice(set.notes, "thermal_kept", "no temperature term in plumb's model: INS_TCAL" +
                        std::to_string(imu + 1) + "_* left as on the vehicle");
    return set;
  }
  const std::string tcal = "INS_TCAL" + std::to_string(imu + 1) + "_";
  set.parameters.push_back({tcal + "ENABLE", 1.0, true});
  set.parameters.push_back({tcal + "TMIN", t_min, false});
  set.parameters.push_back({tcal + "TMAX", t_max, false});
  for (int k = 0; k < 3; ++k) {
    AddVector(set, tcal + "ACC" + std::to_string(k + 1), acc.coeff[k]);
    AddVector(set, tcal + "GYR" + std::to_string(k + 1), gyr.coeff[k]);
  }
  const std::string n = std::to_string(imu + 1);
  if (fw.accel.has_thermal) set.parameters.push_back({"INS_ACC" + n + "_CALTEMP", cal_acc, false});
  if (fw.has_gyro && fw.gyro.has_thermal) {
    set.parameters.push_back({"INS_GYR" + n + "_CALTEMP", cal_gyr, false});
  }
  AddNotice(set.notes, "thermal_model", "tcal(T) = p(clamp(T) - 35) - p(clamp(CALTEMP) - 35), p(d) = (C1 + (C2 + "
                      "C3 d) d) d * 1e-6 (AP_InertialSensor_tempcal.cpp); valid for samples "
                      "with no temperature correction left in them (INS_TCAL" + n +
                      "_ENABLE = 0 in the log, or its correction undone by plumb)");
  return set;
}

FirmwareCorrection ArdupilotCorrection(const std::map<std::string, double>& v, int imu) {
  CheckArdupilotImu(imu);
  FirmwareCorrection fw;
  const std::string n = std::to_string(imu + 1);
  const std::string tcal = "INS_TCAL" + n + "_";
  const bool enabled = GetOr(v, tcal + "ENABLE", 0.0) == 1.0;
  const double t_min = enabled ? Get(v, tcal + "TMIN") : kNaN;
  const double t_max = enabled ? Get(v, tcal + "TMAX") : kNaN;
  std::array<Vec3, 3> acc_c{}, gyr_c{};
  for (int k = 0; k < 3 && enabled; ++k) {
    acc_c[k] = GetVector(v, tcal + "ACC" + std::to_string(k + 1));
    gyr_c[k] = GetVector(v, tcal + "GYR" + std::to_string(k + 1));
  }
  // ArduPilot's default CALTEMP is -300, which the clamp turns into TMIN.
  fw.accel = FromArdupilot(GetVector(v, ArduStem("ACC", "OFFS", imu)), acc_c, enabled,
                           GetOr(v, "INS_ACC" + n + "_CALTEMP", -300.0), t_min, t_max);
  fw.accel.scale = GetVector(v, ArduStem("ACC", "SCAL", imu));
  const std::string gyr_stem = ArduStem("GYR", "OFFS", imu);
  fw.has_gyro = v.count(gyr_stem + "_X") > 0;
  if (fw.has_gyro) {
    fw.gyro = FromArdupilot(GetVector(v, gyr_stem), gyr_c, enabled,
                            GetOr(v, "INS_GYR" + n + "_CALTEMP", -300.0), t_min, t_max);
  }
  return fw;
}

ParameterSet Px4Parameters(const FirmwareCorrection& fw, const Px4Slots& slots) {
  for (const int slot : {slots.acc, slots.gyro, slots.tc_acc, slots.tc_gyro}) CheckPx4Imu(slot);
  ParameterSet set;
  set.target = "px4";
  set.imu = slots.acc;
  const std::string i = std::to_string(slots.acc), g = std::to_string(slots.gyro);
  for (int a = 0; a < 3; ++a) {
    set.parameters.push_back({"CAL_ACC" + i + "_" + kAxes[a] + "OFF", fw.accel.offset[a], false});
  }
  for (int a = 0; a < 3; ++a) {
    set.parameters.push_back({"CAL_ACC" + i + "_" + kAxes[a] + "SCALE", fw.accel.scale[a], false});
  }
  if (fw.has_gyro) {
    for (int a = 0; a < 3; ++a) {
      set.parameters.push_back({"CAL_GYRO" + g + "_" + kAxes[a] + "OFF", fw.gyro.offset[a], false});
    }
  }
  AddNotice(set.notes, "parameters_written", "PX4 parameters from plumb: acc = (acc_sensor - thermal - CAL_ACC" +
                      i + "_OFF) .* CAL_ACC" + i + "_SCALE, gyr = gyr_sensor - thermal - CAL_GYRO" +
                      g + "_OFF");

  const std::tuple<const DiagonalCorrection*, const char*, int> sensors[] = {
      {&fw.accel, "A", slots.tc_acc}, {&fw.gyro, "G", slots.tc_gyro}};
  for (const auto& [c, letter, slot] : sensors) {
    if (!c->has_thermal || (c == &fw.gyro && !fw.has_gyro)) continue;
    const std::string tc = std::string("TC_") + letter + std::to_string(slot) + "_";
    set.parameters.push_back({std::string("TC_") + letter + "_ENABLE", 1.0, true});
    for (int k = 0; k < 4; ++k) {
      for (int a = 0; a < 3; ++a) {
        set.parameters.push_back(
            {tc + "X" + std::to_string(k) + "_" + std::to_string(a), c->thermal.c[k][a], false});
      }
    }
    set.parameters.push_back({tc + "TREF", c->thermal.t0_c, false});
    set.parameters.push_back({tc + "TMIN", c->temp_min_c, false});
    set.parameters.push_back({tc + "TMAX", c->temp_max_c, false});
  }
  return set;
}

FirmwareCorrection Px4Correction(const std::map<std::string, double>& v, const Px4Slots& slots) {
  for (const int slot : {slots.acc, slots.gyro, slots.tc_acc, slots.tc_gyro}) CheckPx4Imu(slot);
  const std::string i = std::to_string(slots.acc), g = std::to_string(slots.gyro);
  FirmwareCorrection fw;
  auto vec = [&](const std::string& prefix, const std::string& suffix) {
    return Vec3(Get(v, prefix + "X" + suffix), Get(v, prefix + "Y" + suffix),
                Get(v, prefix + "Z" + suffix));
  };
  fw.accel.offset = vec("CAL_ACC" + i + "_", "OFF");
  fw.accel.scale = vec("CAL_ACC" + i + "_", "SCALE");
  fw.has_gyro = v.count("CAL_GYRO" + g + "_XOFF") > 0;
  if (fw.has_gyro) fw.gyro.offset = vec("CAL_GYRO" + g + "_", "OFF");
  const std::tuple<DiagonalCorrection*, const char*, int> sensors[] = {
      {&fw.accel, "A", slots.tc_acc}, {&fw.gyro, "G", slots.tc_gyro}};
  for (const auto& [c, letter, slot] : sensors) {
    if (GetOr(v, std::string("TC_") + letter + "_ENABLE", 0.0) != 1.0) continue;
    const std::string tc = std::string("TC_") + letter + std::to_string(slot) + "_";
    c->has_thermal = true;
    c->thermal.t0_c = Get(v, tc + "TREF");
    c->temp_min_c = Get(v, tc + "TMIN");
    c->temp_max_c = Get(v, tc + "TMAX");
    for (int k = 0; k < 4; ++k) {
      const std::string stem = tc + "X" + std::to_string(k) + "_";
      c->thermal.c[k] = Vec3(Get(v, stem + "0"), Get(v, stem + "1"), Get(v, stem + "2"));
    }
  }
  return fw;
}

std::string ArdupilotParamFile(const ParameterSet& set) {
  std::string text;
  for (const Notice& note : set.notes) text += "# " + note.message + "\n";
  for (const Parameter& p : set.parameters) {
    text += p.name + "," + (p.integer ? std::to_string(std::lround(p.value)) : Number(p.value)) + "\n";
  }
  return text;
}

std::map<std::string, double> ReadArdupilotParamFile(const std::string& text,
                                                     const std::string& path) {
  std::map<std::string, double> out;
  const std::vector<std::string> lines = Lines(text);
  for (std::size_t n = 0; n < lines.size(); ++n) {
    if (Skip(lines[n])) continue;
    const int line_no = static_cast<int>(n + 1);
    const std::vector<std::string> f = Fields(lines[n], ", \t");
    if (f.size() != 2) {
      throw InputError(path, "line " + std::to_string(line_no),
                       "NAME,VALUE or NAME VALUE (two fields), got " + std::to_string(f.size()));
    }
    out[f[0]] = ParseValue(f[1], path, line_no);
  }
  return out;
}

std::string Px4ParamsFile(const ParameterSet& set) {
  std::string text;
  for (const Notice& note : set.notes) text += "# " + note.message + "\n";
  text += "#\n# Vehicle-Id Component-Id Name Value Type\n";
  for (const Parameter& p : set.parameters) {
    text += std::to_string(set.system_id) + "\t1\t" + p.name + "\t" +
            (p.integer ? std::to_string(std::lround(p.value)) : Number(p.value)) + "\t" +
            std::to_string(p.integer ? kQgcTypeInt32 : kQgcTypeReal32) + "\n";
  }
  return text;
}

std::map<std::string, double> ReadPx4ParamsFile(const std::string& text, const std::string& path) {
  std::map<std::string, double> out;
  const std::vector<std::string> lines = Lines(text);
  for (std::size_t n = 0; n < lines.size(); ++n) {
    if (Skip(lines[n])) continue;
    const int line_no = static_cast<int>(n + 1);
    const std::vector<std::string> f = Fields(lines[n], "\t");
    if (f.size() != 5) {
      throw InputError(path, "line " + std::to_string(line_no),
                       "five tab-separated fields (vehicle, component, name, value, type), got " +
                           std::to_string(f.size()));
    }
    out[f[2]] = ParseValue(f[3], path, line_no);
  }
  return out;
}

}  // namespace plumb::exporter

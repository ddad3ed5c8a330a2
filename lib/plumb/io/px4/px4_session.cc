// plumb/io/px4/px4_session.cc — see px4_session.h.
#include "plumb/io/px4/px4_session.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <Eigen/Geometry>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"

namespace plumb::io {
namespace {

constexpr double kUsToS = 1e-6;
constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr int kMaxCalSlots = 4;  // CAL_ACC0..CAL_ACC3

enum class StreamKind { kCombined, kVehicleImu, kSensorAccel };

/// Where a stream's samples come from.
struct StreamSource {
  StreamKind kind = StreamKind::kCombined;
  int instance = 0;
  const ULogTopic* topic = nullptr;  ///< sensor_combined, vehicle_imu or sensor_accel
  const ULogTopic* gyro = nullptr;   ///< sensor_gyro paired with sensor_accel, or nullptr
};

const char* KindName(StreamKind kind) {
  switch (kind) {
    case StreamKind::kCombined: return "sensor_combined";
    case StreamKind::kVehicleImu: return "vehicle_imu";
    case StreamKind::kSensorAccel: return "sensor_accel";
  }
  return "";
}

using Triad = std::array<int, 3>;

/// Columns base[0], base[1], base[2] of `t`, or nullopt when any is missing.
std::optional<Triad> ArrayColumns(const ULogTopic& t, const std::string& base) {
  Triad c;
  for (int i = 0; i < 3; ++i) {
    c[static_cast<std::size_t>(i)] = t.ColumnIndex(base + "[" + std::to_string(i) + "]");
    if (c[static_cast<std::size_t>(i)] < 0) return std::nullopt;
  }
  return c;
}

/// Columns x, y, z of `t`, or nullopt.
std::optional<Triad> XyzColumns(const ULogTopic& t) {
  const Triad c = {t.ColumnIndex("x"), t.ColumnIndex("y"), t.ColumnIndex("z")};
  if (c[0] < 0 || c[1] < 0 || c[2] < 0) return std::nullopt;
  return c;
}

/// The sample-time column: timestamp_sample when present, else timestamp; -1 if neither.
int TimeColumn(const ULogTopic& t) {
  const int sample = t.ColumnIndex("timestamp_sample");
  return sample >= 0 ? sample : t.timestamp_col;
}

/// double -> float with out-of-range values as +-infinity (a plain cast is undefined there).
float ToFloat(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::infinity();
  if (v < -kMax) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(v);
}

Vec3f ToFloat(const Vec3& v) { return Vec3f(ToFloat(v.x()), ToFloat(v.y()), ToFloat(v.z())); }

Vec3 Row3d(const ULogTopic& t, std::size_t row, const Triad& c) {
  return Vec3(t.Value(row, static_cast<std::size_t>(c[0])),
              t.Value(row, static_cast<std::size_t>(c[1])),
              t.Value(row, static_cast<std::size_t>(c[2])));
}

Vec3f Row3(const ULogTopic& t, std::size_t row, const Triad& c) {
  return ToFloat(Row3d(t, row, c));
}

double TimeS(const ULogTopic& t, std::size_t row, int col) {
  return t.Value(row, static_cast<std::size_t>(col)) * kUsToS;
}

/// Appends a sample when its time increases; returns whether it was kept.
bool Push(ImuSeries* s, double t_s, const Vec3f& acc, const Vec3f* gyr, const float* temp) {
  if (!std::isfinite(t_s) || (!s->t_s.empty() && !(t_s > s->t_s.back()))) return false;
  s->t_s.push_back(t_s);
  s->acc.push_back(acc);
  if (gyr != nullptr) s->gyr.push_back(*gyr);
  if (temp != nullptr) s->temp_c.push_back(*temp);
  return true;
}

ImuSeries FromCombined(const ULogTopic& t) {
  ImuSeries s;
  const auto acc = ArrayColumns(t, "accelerometer_m_s2");
  auto gyr = ArrayColumns(t, "gyro_rad");
  if (!gyr) gyr = ArrayColumns(t, "gyro_rad_s");
  if (!acc || !gyr || t.timestamp_col < 0) return s;
  s.reserve(t.rows);
  for (std::size_t r = 0; r < t.rows; ++r) {
    const Vec3f g = Row3(t, r, *gyr);
    Push(&s, TimeS(t, r, t.timestamp_col), Row3(t, r, *acc), &g, nullptr);
  }
  return s;
}

ImuSeries FromVehicleImu(const ULogTopic& t) {
  ImuSeries s;
  const auto dv = ArrayColumns(t, "delta_velocity");
  const auto da = ArrayColumns(t, "delta_angle");
  const int dv_dt = t.ColumnIndex("delta_velocity_dt");
  const int da_dt = t.ColumnIndex("delta_angle_dt");
  const int time = TimeColumn(t);
  if (!dv || !da || dv_dt < 0 || da_dt < 0 || time < 0) return s;
  s.reserve(t.rows);
  for (std::size_t r = 0; r < t.rows; ++r) {
    const double v_dt_s = t.Value(r, static_cast<std::size_t>(dv_dt)) * kUsToS;
    const double a_dt_s = t.Value(r, static_cast<std::size_t>(da_dt)) * kUsToS;
    if (!(v_dt_s > 0.0) || !(a_dt_s > 0.0)) continue;
    const Vec3f acc = ToFloat(Row3d(t, r, *dv) / v_dt_s);
    const Vec3f g = ToFloat(Row3d(t, r, *da) / a_dt_s);
    Push(&s, TimeS(t, r, time), acc, &g, nullptr);
  }
  return s;
}

/// Median of the positive differences of `t`, 0 when there are none.
double MedianStep(const std::vector<double>& t) {
  std::vector<double> d;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] > t[i - 1]) d.push_back(t[i] - t[i - 1]);
  }
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

ImuSeries FromSensorAccel(const ULogTopic& acc_topic, const ULogTopic* gyro_topic,
                          std::vector<std::string>* notes) {
  ImuSeries s;
  const auto acc = XyzColumns(acc_topic);
  const int time = TimeColumn(acc_topic);
  const int temp = acc_topic.ColumnIndex("temperature");
  if (!acc || time < 0) return s;
  std::vector<double> t_acc(acc_topic.rows);
  for (std::size_t r = 0; r < acc_topic.rows; ++r) t_acc[r] = TimeS(acc_topic, r, time);

  // Pairing with sensor_gyro: nearest gyro time within half the median accel interval.
  std::vector<long> match(acc_topic.rows, -1);
  std::size_t matched = 0;
  std::optional<Triad> gyr;
  if (gyro_topic != nullptr) {
    gyr = XyzColumns(*gyro_topic);
    const int gtime = TimeColumn(*gyro_topic);
    const double tolerance_s = 0.5 * MedianStep(t_acc);
    if (gyr && gtime >= 0 && tolerance_s > 0.0) {
      std::size_t g = 0;
      for (std::size_t r = 0; r < acc_topic.rows; ++r) {
        while (g + 1 < gyro_topic->rows &&
               std::abs(TimeS(*gyro_topic, g + 1, gtime) - t_acc[r]) <=
                   std::abs(TimeS(*gyro_topic, g, gtime) - t_acc[r])) {
          ++g;
        }
        if (g < gyro_topic->rows && std::abs(TimeS(*gyro_topic, g, gtime) - t_acc[r]) <= tolerance_s) {
          match[r] = static_cast<long>(g);
          ++matched;
        }
      }
    }
  }
  const bool paired = gyr && matched * 2 >= acc_topic.rows && matched > 0;
  if (gyro_topic != nullptr && !paired && notes != nullptr) {
    notes->push_back("sensor_gyro instance " + std::to_string(gyro_topic->multi_id) +
                     ": only " + std::to_string(matched) + " of " +
                     std::to_string(acc_topic.rows) +
                     " accel samples have a gyro sample within half an interval: "
                     "accelerometer only");
  }
  s.reserve(acc_topic.rows);
  for (std::size_t r = 0; r < acc_topic.rows; ++r) {
    if (paired && match[r] < 0) continue;
    const float tc =
        temp >= 0 ? ToFloat(acc_topic.Value(r, static_cast<std::size_t>(temp))) : 0.0f;
    Vec3f g;
    if (paired) g = Row3(*gyro_topic, static_cast<std::size_t>(match[r]), *gyr);
    // Temperature and gyro columns must stay aligned with t_s: Push keeps or drops all.
    Push(&s, t_acc[r], Row3(acc_topic, r, *acc), paired ? &g : nullptr, temp >= 0 ? &tc : nullptr);
  }
  return s;
}

ImuSeries Extract(const StreamSource& src, std::vector<std::string>* notes) {
  switch (src.kind) {
    case StreamKind::kCombined: return FromCombined(*src.topic);
    case StreamKind::kVehicleImu: return FromVehicleImu(*src.topic);
    case StreamKind::kSensorAccel: return FromSensorAccel(*src.topic, src.gyro, notes);
  }
  return {};
}

std::vector<StreamSource> Sources(const ULog& log) {
  std::vector<StreamSource> out;
  if (const ULogTopic* t = log.Find("sensor_combined", 0); t != nullptr && t->rows > 0) {
    out.push_back({StreamKind::kCombined, 0, t, nullptr});
  }
  for (int k = 0; k < 256; ++k) {
    if (const ULogTopic* t = log.Find("vehicle_imu", k); t != nullptr && t->rows > 0) {
      out.push_back({StreamKind::kVehicleImu, k, t, nullptr});
    }
  }
  for (int k = 0; k < 256; ++k) {
    if (const ULogTopic* t = log.Find("sensor_accel", k); t != nullptr && t->rows > 0) {
      const ULogTopic* g = log.Find("sensor_gyro", k);
      out.push_back({StreamKind::kSensorAccel, k, t, g != nullptr && g->rows > 0 ? g : nullptr});
    }
  }
  return out;
}

std::optional<double> Param(const ULog& log, const std::string& name) {
  const auto it = log.params.find(name);
  if (it == log.params.end()) return std::nullopt;
  return it->second;
}

/// A parameter or id value as integer text (any double, NaN and huge values included).
std::string Integer(double v) {
  std::ostringstream out;
  out.precision(0);
  out << std::fixed << v;
  return out.str();
}

/// PX4's rotation enum as (roll, pitch, yaw) degrees, for the integers 0..25; nullopt
/// otherwise (other values, fractions, NaN).
std::optional<Vec3> RotationEuler(double value) {
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

/// R = Rz(yaw) Ry(pitch) Rx(roll), angles in degrees.
Mat3 EulerDeg(const Vec3& rpy_deg) {
  const Vec3 r = rpy_deg * kDegToRad;
  return (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

std::string Format(const Vec3& v) {
  std::ostringstream out;
  out.precision(9);
  out << v.x() << ", " << v.y() << ", " << v.z();
  return out.str();
}

/// What PX4 applied to one sensor (accel or gyro) of a calibrated stream.
struct Correction {
  std::string prefix;   ///< e.g. "CAL_ACC0"
  Vec3 offset = Vec3::Zero();
  Vec3 scale = Vec3::Ones();
  Mat3 rotation = Mat3::Identity();
  std::string rotation_text;  ///< how R was obtained
  double device_id = 0.0;     ///< the sensor's device id (0 when unknown)
  std::string id_source;      ///< where the device id came from
};

/// PX4's thermal offset of one sensor (TemperatureCompensation): with T clamped to
/// [t_min_c, t_max_c] and dT = T - t_ref_c, offset_i = x[0]_i + x[1]_i dT + x[2]_i dT^2 +
/// x[3]_i dT^3 (sensor units: m/s^2 or rad/s).
struct Thermal {
  std::string prefix;        ///< e.g. "TC_A1"
  double t_ref_c = 0.0;      ///< TC_An_TREF, degC
  double t_min_c = 0.0;      ///< TC_An_TMIN, degC
  double t_max_c = 0.0;      ///< TC_An_TMAX, degC
  std::array<Vec3, 4> x;     ///< TC_An_X0_* .. TC_An_X3_*, per axis

  Vec3 Offset(double temp_c) const {
    const double dt = std::clamp(temp_c, t_min_c, std::max(t_min_c, t_max_c)) - t_ref_c;
    return x[0] + dt * (x[1] + dt * (x[2] + dt * x[3]));
  }
};

/// A sensor temperature over time, degC at t_s (s), sorted by time.
struct TemperatureTrack {
  std::vector<double> t_s;
  std::vector<double> temp_c;
  std::string source;  ///< topic(s) it came from

  /// The latest temperature at or before t_s (the first one before the track starts).
  double At(double t) const {
    const auto it = std::upper_bound(t_s.begin(), t_s.end(), t);
    const std::size_t i = it == t_s.begin() ? 0 : static_cast<std::size_t>(it - t_s.begin()) - 1;
    return temp_c[i];
  }
};

/// The device id of the accel ("ACC") or gyro ("GYRO") behind a calibrated stream; nullopt
/// when the log does not say. `how` explains the choice.
std::optional<double> DeviceId(const ULog& log, const StreamSource& src, const std::string& kind,
                               std::string* how) {
  const std::string field = kind == "ACC" ? "accel_device_id" : "gyro_device_id";
  const ULogTopic* imu = src.kind == StreamKind::kVehicleImu ? src.topic : nullptr;
  if (src.kind == StreamKind::kCombined) {
    if (const auto prime = Param(log, "CAL_" + kind + "_PRIME"); prime && *prime != 0.0) {
      *how = "CAL_" + kind + "_PRIME";
      return prime;
    }
    imu = log.Find("vehicle_imu", 0);
    *how = "vehicle_imu instance 0 " + field + " (assumed primary)";
  } else {
    *how = "vehicle_imu " + field;
  }
  if (imu == nullptr || imu->rows == 0) return std::nullopt;
  const int c = imu->ColumnIndex(field);
  if (c < 0) return std::nullopt;
  return imu->Value(0, static_cast<std::size_t>(c));
}

/// The correction PX4 applied for `kind` ("ACC" or "GYRO"), or nullopt with `why` set.
std::optional<Correction> FindCorrection(const ULog& log, const StreamSource& src,
                                         const std::string& kind, std::string* why) {
  std::string how;
  const std::optional<double> id = DeviceId(log, src, kind, &how);
  int slot = -1;
  if (id) {
    for (int n = 0; n < kMaxCalSlots; ++n) {
      const auto cal_id = Param(log, "CAL_" + kind + std::to_string(n) + "_ID");
      if (cal_id && *cal_id == *id) {
        slot = n;
        break;
      }
    }
  }
  if (slot < 0) {
    *why = id ? "no CAL_" + kind + "n_ID equals the device id " +
                    Integer(*id) + " (from " + how + ")"
              : "the log does not say which sensor it is (no device id)";
    return std::nullopt;
  }
  Correction c;
  c.prefix = "CAL_" + kind + std::to_string(slot);
  c.device_id = *id;
  c.id_source = how;
  const char* axes[3] = {"X", "Y", "Z"};
  for (int i = 0; i < 3; ++i) {
    const auto off = Param(log, c.prefix + "_" + axes[i] + "OFF");
    if (!off) {
      *why = c.prefix + "_" + axes[i] + "OFF is not in the log";
      return std::nullopt;
    }
    c.offset[i] = *off;
    c.scale[i] = Param(log, c.prefix + "_" + axes[i] + "SCALE").value_or(1.0);
  }
  if ((c.scale.array() == 0.0).any() || !c.scale.allFinite() || !c.offset.allFinite()) {
    *why = c.prefix + " has a zero or non-finite scale or offset";
    return std::nullopt;
  }
  const auto cal_rot = Param(log, c.prefix + "_ROT");
  if (cal_rot && *cal_rot >= 0) {
    const auto euler = RotationEuler(*cal_rot);
    if (!euler) {
      *why = c.prefix + "_ROT = " + Integer(*cal_rot) + " is not a rotation plumb knows";
      return std::nullopt;
    }
    c.rotation = EulerDeg(*euler);
    c.rotation_text = c.prefix + "_ROT = " + Integer(*cal_rot);
  } else {
    const double board = Param(log, "SENS_BOARD_ROT").value_or(0.0);
    const auto euler = RotationEuler(board);
    if (!euler) {
      *why = "SENS_BOARD_ROT = " + Integer(board) + " is not a rotation plumb knows";
      return std::nullopt;
    }
    const Vec3 trim(Param(log, "SENS_BOARD_X_OFF").value_or(0.0),
                    Param(log, "SENS_BOARD_Y_OFF").value_or(0.0),
                    Param(log, "SENS_BOARD_Z_OFF").value_or(0.0));
    c.rotation = EulerDeg(trim) * EulerDeg(*euler);
    c.rotation_text = "SENS_BOARD_ROT = " + Integer(board) + ", SENS_BOARD_X/Y/Z_OFF = " +
                      Format(trim) + " deg";
  }
  return c;
}

/// The TC_An / TC_Gn coefficients whose TC_*n_ID equals `device_id` (kind "A" or "G").
std::optional<Thermal> FindThermal(const ULog& log, const std::string& kind, double device_id,
                                   std::string* why) {
  for (int n = 0; n < kMaxCalSlots; ++n) {
    const std::string prefix = "TC_" + kind + std::to_string(n);
    const auto id = Param(log, prefix + "_ID");
    if (!id || *id != device_id) continue;
    Thermal t;
    t.prefix = prefix;
    const auto ref = Param(log, prefix + "_TREF");
    const auto tmin = Param(log, prefix + "_TMIN");
    const auto tmax = Param(log, prefix + "_TMAX");
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
        const auto v = Param(log, name);
        if (!v) {
          *why = name + " missing";
          return std::nullopt;
        }
        t.x[static_cast<std::size_t>(k)][i] = *v;
      }
    }
    return t;
  }
  *why = "no TC_" + kind + "n_ID equals the device id " +
         Integer(device_id);
  return std::nullopt;
}

/// The temperature of the sensor with `device_id` from sensor_accel/sensor_gyro (device_id,
/// temperature) and vehicle_imu_status (accel_device_id/gyro_device_id,
/// temperature_accel/temperature_gyro) messages; nullopt when none is logged.
std::optional<TemperatureTrack> SensorTemperature(const ULog& log, bool accel, double device_id) {
  std::vector<std::pair<double, double>> points;
  std::string source;
  for (const ULogTopic& t : log.topics) {
    int id_col = -1, temp_col = -1;
    if (t.name == (accel ? "sensor_accel" : "sensor_gyro")) {
      id_col = t.ColumnIndex("device_id");
      temp_col = t.ColumnIndex("temperature");
    } else if (t.name == "vehicle_imu_status") {
      id_col = t.ColumnIndex(accel ? "accel_device_id" : "gyro_device_id");
      temp_col = t.ColumnIndex(accel ? "temperature_accel" : "temperature_gyro");
    }
    const int time = TimeColumn(t);
    if (id_col < 0 || temp_col < 0 || time < 0) continue;
    const std::size_t before = points.size();
    for (std::size_t r = 0; r < t.rows; ++r) {
      if (t.Value(r, static_cast<std::size_t>(id_col)) != device_id) continue;
      const double temp = t.Value(r, static_cast<std::size_t>(temp_col));
      const double when = TimeS(t, r, time);
      if (std::isfinite(temp) && std::isfinite(when)) points.emplace_back(when, temp);
    }
    if (points.size() > before) {
      source += (source.empty() ? "" : ", ") + t.name + " instance " + std::to_string(t.multi_id);
    }
  }
  if (points.empty()) return std::nullopt;
  std::sort(points.begin(), points.end());
  TemperatureTrack track;
  track.source = source;
  for (const auto& [when, temp] : points) {
    track.t_s.push_back(when);
    track.temp_c.push_back(temp);
  }
  return track;
}

/// m = R^T logged ./ scale + offset (+ thermal offset at the sample's temperature), in place.
void Undo(const Correction& c, const std::optional<Thermal>& thermal,
          const std::optional<TemperatureTrack>& temp, const std::vector<double>& t_s,
          std::vector<Vec3f>* v) {
  const Mat3 rt = c.rotation.transpose();
  for (std::size_t k = 0; k < v->size(); ++k) {
    Vec3 m = (rt * (*v)[k].cast<double>()).cwiseQuotient(c.scale) + c.offset;
    if (thermal && temp) m += thermal->Offset(temp->At(t_s[k]));
    (*v)[k] = ToFloat(m);
  }
}

std::string CalibrationNames(const ULog& log, const StreamSource& src) {
  std::string acc_why, gyr_why;
  const auto acc = FindCorrection(log, src, "ACC", &acc_why);
  const auto gyr = FindCorrection(log, src, "GYRO", &gyr_why);
  std::string out = acc ? acc->prefix + "_*" : "CAL_ACCn_*";
  out += ", ";
  out += gyr ? gyr->prefix + "_*" : "CAL_GYROn_*";
  out += ", board rotation";
  if (Param(log, "TC_A_ENABLE").value_or(0.0) == 1.0) out += ", TC_A* thermal";
  if (Param(log, "TC_G_ENABLE").value_or(0.0) == 1.0) out += ", TC_G* thermal";
  return out;
}

std::string Who(const StreamSource& src) {
  return std::string(KindName(src.kind)) + " instance " + std::to_string(src.instance) + ": ";
}

void UndoCorrection(const ULog& log, const StreamSource& src, Session* s) {
  const std::string who = Who(src);
  for (const char* kind : {"ACC", "GYRO"}) {
    const bool acc = std::string(kind) == "ACC";
    const std::string what = acc ? "accelerometer" : "gyroscope";
    if (!acc && !s->series.has_gyro()) continue;
    std::string why;
    const auto c = FindCorrection(log, src, kind, &why);
    if (!c) {
      s->warnings.push_back(who + what + " taken as logged (calibrated by PX4; not undone: " +
                            why + ")");
      s->firmware_left.push_back(who + "PX4 " + what + " calibration (" + why + ")");
      continue;
    }
    // Thermal compensation (TC_A_ENABLE / TC_G_ENABLE = 1) at the sensor's logged temperature.
    const std::string tc = acc ? "TC_A_ENABLE" : "TC_G_ENABLE";
    std::optional<Thermal> thermal;
    std::optional<TemperatureTrack> temp;
    std::string thermal_text;
    if (Param(log, tc).value_or(0.0) == 1.0) {
      std::string tc_why;
      thermal = FindThermal(log, acc ? "A" : "G", c->device_id, &tc_why);
      temp = thermal ? SensorTemperature(log, acc, c->device_id) : std::nullopt;
      if (!thermal || !temp) {
        if (thermal) tc_why = "no temperature of device " +
                              Integer(c->device_id) + " in the log";
        s->warnings.push_back(who + tc + " = 1: PX4's thermal " + what +
                              " correction is in the samples and NOT undone (" + tc_why + ")");
        s->firmware_left.push_back(who + "PX4 thermal " + what + " correction (" + tc_why + ")");
        thermal.reset();
      } else {
        thermal_text = " + thermal offset " + thermal->prefix + "_X0..X3 (X0 " +
                       Format(thermal->x[0]) + ", X1 " + Format(thermal->x[1]) + ", X2 " +
                       Format(thermal->x[2]) + ", X3 " + Format(thermal->x[3]) + ", TREF " +
                       std::to_string(thermal->t_ref_c) + " degC, clamped to [" +
                       std::to_string(thermal->t_min_c) + ", " +
                       std::to_string(thermal->t_max_c) + "]) at the temperature of " +
                       temp->source;
      }
    }
    Undo(*c, thermal, temp, s->series.t_s, acc ? &s->series.acc : &s->series.gyr);
    const std::string unit = acc ? " m/s^2" : " rad/s";
    s->warnings.push_back(who + what + " reconstructed as R^T logged ./ " + c->prefix +
                          "_*SCALE (" + Format(c->scale) + ") + " + c->prefix + "_*OFF (" +
                          Format(c->offset) + ")" + unit + thermal_text + ", R from " +
                          c->rotation_text + "; " + c->prefix + " chosen by device id " +
                          Integer(c->device_id) + " from " +
                          c->id_source);
  }
}

void WarnParamChanges(const ULog& log, Session* s) {
  std::size_t changes = 0;
  std::string first;
  for (const ULogParamChange& c : log.param_changes) {
    if (c.name.rfind("CAL_", 0) == 0 || c.name.rfind("TC_", 0) == 0 ||
        c.name.rfind("SENS_BOARD_", 0) == 0) {
      if (changes++ == 0) first = c.name;
    }
  }
  if (changes > 0) {
    s->warnings.push_back(std::to_string(changes) + " calibration parameter change(s) during " +
                          "the log (first: " + first + "); the initial values were used");
  }
}

const StreamSource* Select(const std::vector<StreamSource>& sources,
                           const std::vector<ImuStreamInfo>& infos,
                           const FlightLogSelection& sel) {
  const StreamSource* best = nullptr;
  double best_rate = -1.0;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    if (infos[i].instance != sel.imu) continue;
    if (!sel.stream.empty()) {
      if (infos[i].name == sel.stream) return &sources[i];
      continue;
    }
    const bool both = infos[i].has_accel && infos[i].has_gyro;
    const double score = (both ? 1e9 : 0.0) + infos[i].rate_hz;
    if (score > best_rate) {
      best_rate = score;
      best = &sources[i];
    }
  }
  return best;
}

ImuStreamInfo Describe(const ULog& log, const StreamSource& src, const ImuSeries& s) {
  ImuStreamInfo info;
  info.name = KindName(src.kind);
  info.instance = src.instance;
  info.samples = s.size();
  if (!s.empty()) {
    info.t_start_s = s.t_s.front();
    info.t_end_s = s.t_s.back();
  }
  const double span = info.t_end_s - info.t_start_s;
  if (s.size() >= 2 && span > 0.0) info.rate_hz = static_cast<double>(s.size() - 1) / span;
  info.has_accel = true;
  info.has_gyro = s.has_gyro();
  info.has_temperature = s.has_temperature();
  if (src.kind != StreamKind::kSensorAccel) {
    info.applied = CalibrationNames(log, src);
    std::string a, g;
    info.undoable = FindCorrection(log, src, "ACC", &a).has_value() &&
                    (!s.has_gyro() || FindCorrection(log, src, "GYRO", &g).has_value());
  }
  return info;
}

}  // namespace

std::vector<ImuStreamInfo> ULogImuStreams(const ULog& log) {
  std::vector<ImuStreamInfo> out;
  for (const StreamSource& src : Sources(log)) {
    out.push_back(Describe(log, src, Extract(src, nullptr)));
  }
  return out;
}

std::optional<SiteInput> SiteFromULog(const ULog& log) {
  std::vector<double> lats, lons, alts;
  for (const ULogTopic& t : log.topics) {
    if (t.name != "vehicle_gps_position" && t.name != "sensor_gps") continue;
    const int fix = t.ColumnIndex("fix_type");
    int lat = t.ColumnIndex("latitude_deg");
    int lon = t.ColumnIndex("longitude_deg");
    int alt = t.ColumnIndex("altitude_msl_m");
    double lat_scale = 1.0, alt_scale = 1.0;
    if (lat < 0 || lon < 0) {  // old layout: int32 1e-7 deg, alt int32 mm
      lat = t.ColumnIndex("lat");
      lon = t.ColumnIndex("lon");
      alt = t.ColumnIndex("alt");
      lat_scale = 1e-7;
      alt_scale = 1e-3;
    }
    if (fix < 0 || lat < 0 || lon < 0) continue;
    for (std::size_t r = 0; r < t.rows; ++r) {
      if (t.Value(r, static_cast<std::size_t>(fix)) < 3) continue;
      const double la = t.Value(r, static_cast<std::size_t>(lat)) * lat_scale;
      const double lo = t.Value(r, static_cast<std::size_t>(lon)) * lat_scale;
      if (!std::isfinite(la) || !std::isfinite(lo) || (la == 0.0 && lo == 0.0)) continue;
      if (std::abs(la) > 90.0 || std::abs(lo) > 180.0) continue;
      const double h = alt >= 0 ? t.Value(r, static_cast<std::size_t>(alt)) * alt_scale : 0.0;
      lats.push_back(la);
      lons.push_back(lo);
      alts.push_back(std::isfinite(h) ? h : 0.0);
    }
  }
  return MedianSite(std::move(lats), std::move(lons), std::move(alts));
}

std::map<std::string, double> ULogParams(const ULog& log) {
  std::map<std::string, double> out;
  for (const auto& [name, value] : log.params) {
    for (const char* prefix : {"CAL_ACC", "CAL_GYRO", "TC_A", "TC_G", "SENS_BOARD_"}) {
      if (name.rfind(prefix, 0) == 0) {
        out[name] = value;
        break;
      }
    }
  }
  return out;
}

Session ULogSession(const ULog& log, const FlightLogSelection& selection) {
  const std::vector<StreamSource> sources = Sources(log);
  std::vector<ImuStreamInfo> infos;
  std::vector<ImuSeries> all;
  std::vector<std::vector<std::string>> notes(sources.size());
  for (std::size_t i = 0; i < sources.size(); ++i) {
    all.push_back(Extract(sources[i], &notes[i]));
    infos.push_back(Describe(log, sources[i], all.back()));
  }
  const StreamSource* src = Select(sources, infos, selection);
  const std::string wanted = (selection.stream.empty() ? std::string("IMU") : selection.stream) +
                             " instance " + std::to_string(selection.imu);
  if (src == nullptr) {
    throw InputError(log.source, "", "no " + wanted +
                                         " stream (sensor_combined, vehicle_imu or sensor_accel)");
  }
  const auto chosen = static_cast<std::size_t>(src - sources.data());
  Session s;
  s.source = log.source + " (" + KindName(src->kind) + " instance " +
             std::to_string(src->instance) + ")";
  for (const auto& w : log.warnings.Describe()) s.warnings.push_back(log.source + ": " + w);
  if (log.dropouts > 0) {
    s.warnings.push_back(log.source + ": " + std::to_string(log.dropouts) +
                         " logging dropout(s), " + std::to_string(log.dropout_total_ms) +
                         " ms in total");
  }
  for (auto& n : notes[chosen]) s.warnings.push_back(std::move(n));
  const ImuSeries& whole = all[chosen];

  ImuSeries& out = s.series;
  for (std::size_t i = 0; i < whole.size(); ++i) {
    const double t = whole.t_s[i];
    if (selection.from_s && t < *selection.from_s) continue;
    if (selection.to_s && t > *selection.to_s) continue;
    out.t_s.push_back(t);
    out.acc.push_back(whole.acc[i]);
    if (whole.has_gyro()) out.gyr.push_back(whole.gyr[i]);
    if (whole.has_temperature()) out.temp_c.push_back(whole.temp_c[i]);
  }
  if (out.size() < 2) {
    throw InputError(log.source, std::string(KindName(src->kind)) + " instance " +
                                     std::to_string(src->instance),
                     "fewer than 2 samples in the time window");
  }
  const std::string who = Who(*src);
  if (src->kind == StreamKind::kSensorAccel) {
    s.warnings.push_back(who + "raw driver output (not calibrated by PX4), taken as logged");
  } else if (!selection.undo_correction) {
    s.warnings.push_back(who + "samples taken as logged (calibrated by PX4 with " +
                         infos[chosen].applied + ")");
    s.firmware_left.push_back(who + "PX4 " + infos[chosen].applied);
  } else {
    UndoCorrection(log, *src, &s);
    WarnParamChanges(log, &s);
  }
  s.site = SiteFromULog(log);
  return s;
}

FlightLogSummary ULogSummary(const ULog& log) {
  FlightLogSummary out;
  out.source = log.source;
  out.format = "px4-ulog";
  out.format_detail = "ULog version " + std::to_string(log.version) + ", " +
                      std::to_string(log.topics.size()) + " subscriptions";
  if (log.data_appended) {
    out.format_detail += ", data appended at " + std::to_string(log.appended_offsets.size()) +
                         " offset(s)";
  }
  out.size_bytes = log.size_bytes;
  out.imus = ULogImuStreams(log);
  out.site = SiteFromULog(log);
  out.params = ULogParams(log);
  out.messages = log.MessageCounts();
  out.warnings = log.warnings.Describe();
  if (log.dropouts > 0) {
    out.warnings.push_back(std::to_string(log.dropouts) + " logging dropout(s), " +
                           std::to_string(log.dropout_total_ms) + " ms in total");
  }
  return out;
}

bool LooksLikeULog(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[7] = {0, 0, 0, 0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(head), 7);
  static const unsigned char kMagic[7] = {'U', 'L', 'o', 'g', 0x01, 0x12, 0x35};
  return in.gcount() == 7 && std::equal(head, head + 7, kMagic);
}

}  // namespace plumb::io

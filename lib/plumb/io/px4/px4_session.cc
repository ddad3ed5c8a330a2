// plumb/io/px4/px4_session.cc — see px4_session.h.
#include "plumb/io/px4/px4_session.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/px4/px4_correction.h"
#include "plumb/io/px4/ulog_format.h"
#include "plumb/io/common/stream_spool.h"

namespace plumb::io {
namespace {

constexpr double kUsToS = 1e-6;

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

/// One column of a topic read straight from its message bodies: ULogTopic::Value without the
/// look-ups per value (the decoding loops below read every row).
struct Col {
  std::size_t offset = 0;
  ULogType type = ULogType::kUInt8;

  double Read(const std::uint8_t* body) const { return DecodeULogValue(body + offset, type); }
};

/// The reader of column `c` (>= 0) of `t`; throws as ULogTopic::Value when `t` has rows whose
/// bodies were not kept.
Col ColOf(const ULogTopic& t, int c) {
  if (t.rows > 0 && !t.bodies_kept) (void)t.Value(0, static_cast<std::size_t>(c));  // throws
  const ULogColumn& column = t.columns[static_cast<std::size_t>(c)];
  return {column.offset, column.type};
}

double TimeS(const ULogTopic& t, std::size_t row, int col) {
  return t.Value(row, static_cast<std::size_t>(col)) * kUsToS;
}

using Cols = std::array<Col, 3>;

Cols ColsOf(const ULogTopic& t, const Triad& c) {
  return {ColOf(t, c[0]), ColOf(t, c[1]), ColOf(t, c[2])};
}

Vec3 Read3d(const std::uint8_t* body, const Cols& c) {
  return Vec3(c[0].Read(body), c[1].Read(body), c[2].Read(body));
}

Vec3f Read3(const std::uint8_t* body, const Cols& c) { return SaturatedFloat(Read3d(body, c)); }

/// Reserves `n` samples of `s` (gyr with `gyr`, temp_c with `temp`), large buffers backed by
/// huge pages (AdviseHugePages: fewer page faults as they are filled).
void Reserve(ImuSeries* s, std::size_t n, bool gyr, bool temp) {
  ReserveHugePages(s->t_s, n);
  ReserveHugePages(s->acc, n);
  if (gyr) ReserveHugePages(s->gyr, n);
  if (temp) ReserveHugePages(s->temp_c, n);
}

/// Appends a message's sample, whatever its time (Extract leaves bad times out after).
void Push(ImuSeries* s, double t_s, const Vec3f& acc, const Vec3f* gyr, const float* temp) {
  s->t_s.push_back(t_s);
  s->acc.push_back(acc);
  if (gyr != nullptr) s->gyr.push_back(*gyr);
  if (temp != nullptr) s->temp_c.push_back(*temp);
}

ImuSeries FromCombined(const ULogTopic& t) {
  ImuSeries s;
  const auto acc = ArrayColumns(t, "accelerometer_m_s2");
  auto gyr = ArrayColumns(t, "gyro_rad");
  if (!gyr) gyr = ArrayColumns(t, "gyro_rad_s");
  if (!acc || !gyr || t.timestamp_col < 0) return s;
  if (t.imu_decoded) return CopySeries(t.imu);  // decoded by the reader, the same way
  const Cols a = ColsOf(t, *acc), w = ColsOf(t, *gyr);
  const Col time = ColOf(t, t.timestamp_col);
  Reserve(&s, t.rows, true, false);
  for (std::size_t r = 0; r < t.rows; ++r) {
    const std::uint8_t* body = t.bodies.Row(r);
    const Vec3f g = Read3(body, w);
    Push(&s, time.Read(body) * kUsToS, Read3(body, a), &g, nullptr);
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
  const Cols v = ColsOf(t, *dv), a = ColsOf(t, *da);
  const Col v_dt = ColOf(t, dv_dt), a_dt = ColOf(t, da_dt), time_col = ColOf(t, time);
  Reserve(&s, t.rows, true, false);
  for (std::size_t r = 0; r < t.rows; ++r) {
    const std::uint8_t* body = t.bodies.Row(r);
    const double v_dt_s = v_dt.Read(body) * kUsToS;
    const double a_dt_s = a_dt.Read(body) * kUsToS;
    if (!(v_dt_s > 0.0) || !(a_dt_s > 0.0)) continue;
    const Vec3f acc = SaturatedFloat(Read3d(body, v) / v_dt_s);
    const Vec3f g = SaturatedFloat(Read3d(body, a) / a_dt_s);
    Push(&s, time_col.Read(body) * kUsToS, acc, &g, nullptr);
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
  const Cols a = ColsOf(acc_topic, *acc);
  const Col time_col = ColOf(acc_topic, time);
  std::vector<double> t_acc(acc_topic.rows);
  for (std::size_t r = 0; r < acc_topic.rows; ++r) {
    t_acc[r] = time_col.Read(acc_topic.bodies.Row(r)) * kUsToS;
  }

  // Pairing with sensor_gyro: nearest gyro time within half the median accel interval.
  std::vector<long> match(acc_topic.rows, -1);
  std::size_t matched = 0;
  std::optional<Triad> gyr;
  if (gyro_topic != nullptr) {
    gyr = XyzColumns(*gyro_topic);
    const int gtime = TimeColumn(*gyro_topic);
    const double tolerance_s = 0.5 * MedianStep(t_acc);
    if (gyr && gtime >= 0 && tolerance_s > 0.0) {
      const Col g_time = ColOf(*gyro_topic, gtime);
      const auto time_s = [&](std::size_t g) {
        return g_time.Read(gyro_topic->bodies.Row(g)) * kUsToS;
      };
      std::size_t g = 0;
      for (std::size_t r = 0; r < acc_topic.rows; ++r) {
        while (g + 1 < gyro_topic->rows &&
               std::abs(time_s(g + 1) - t_acc[r]) <= std::abs(time_s(g) - t_acc[r])) {
          ++g;
        }
        if (g < gyro_topic->rows && std::abs(time_s(g) - t_acc[r]) <= tolerance_s) {
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
  const Col temp_col = temp >= 0 ? ColOf(acc_topic, temp) : Col{};
  const Cols w = paired ? ColsOf(*gyro_topic, *gyr) : Cols{};
  Reserve(&s, acc_topic.rows, paired, temp >= 0);
  for (std::size_t r = 0; r < acc_topic.rows; ++r) {
    if (paired && match[r] < 0) continue;
    const std::uint8_t* body = acc_topic.bodies.Row(r);
    const float tc = temp >= 0 ? SaturatedFloat(temp_col.Read(body)) : 0.0f;
    Vec3f g;
    if (paired) g = Read3(gyro_topic->bodies.Row(static_cast<std::size_t>(match[r])), w);
    // Temperature and gyro columns must stay aligned with t_s: Push keeps or drops all.
    Push(&s, t_acc[r], Read3(body, a), paired ? &g : nullptr, temp >= 0 ? &tc : nullptr);
  }
  return s;
}

/// The samples of a stream, with what their times left out.
struct Extracted {
  ImuSeries series;
  LeftOutTimes left_out;  ///< KeepIncreasingTimes's
};

/// The samples of `src`, those with bad times left out (KeepIncreasingTimes: the reader did
/// it already for sensor_combined decoded in its pass); with `notes`, the pairing of
/// sensor_accel with sensor_gyro is said there.
Extracted Extract(const StreamSource& src, std::vector<std::string>* notes) {
  Extracted out;
  switch (src.kind) {
    case StreamKind::kCombined: out.series = FromCombined(*src.topic); break;
    case StreamKind::kVehicleImu: out.series = FromVehicleImu(*src.topic); break;
    case StreamKind::kSensorAccel: out.series = FromSensorAccel(*src.topic, src.gyro, notes); break;
  }
  out.left_out = src.kind == StreamKind::kCombined && src.topic->imu_decoded
                     ? src.topic->imu_left_out
                     : KeepIncreasingTimes(out.series);
  return out;
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

/// The device id of the accel ("ACC") or gyro ("GYRO") behind a calibrated stream; nullopt
/// when the log does not say. `how` explains the choice.
std::optional<double> DeviceId(const ULog& log, const StreamSource& src, const std::string& kind,
                               std::string* how) {
  const std::string field = kind == "ACC" ? "accel_device_id" : "gyro_device_id";
  const ULogTopic* imu = src.kind == StreamKind::kVehicleImu ? src.topic : nullptr;
  if (src.kind == StreamKind::kSensorAccel) {  // the driver's own topics name their device
    const ULogTopic* raw = kind == "ACC" ? src.topic : src.gyro;
    *how = (kind == "ACC" ? "sensor_accel" : "sensor_gyro") + std::string(" device_id");
    const int c = raw == nullptr || raw->rows == 0 ? -1 : raw->ColumnIndex("device_id");
    if (c < 0) return std::nullopt;
    return raw->Value(0, static_cast<std::size_t>(c));
  }
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

/// The temperature of the sensor with `device_id` from sensor_accel/sensor_gyro (device_id,
/// temperature) and vehicle_imu_status (accel_device_id/gyro_device_id,
/// temperature_accel/temperature_gyro) messages; nullopt when none is logged.
std::optional<Px4TemperatureTrack> SensorTemperature(const ULog& log, bool accel,
                                                     double device_id) {
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
  Px4TemperatureTrack track;
  track.source = source;
  for (const auto& [when, temp] : points) {
    track.t_s.push_back(when);
    track.temp_c.push_back(temp);
  }
  return track;
}

/// The sensors behind a calibrated stream (sensor_combined, vehicle_imu): their device ids and
/// logged temperatures.
Px4Sensors SensorsOf(const ULog& log, const StreamSource& src) {
  Px4Sensors sensors;
  sensors.acc_id = DeviceId(log, src, "ACC", &sensors.acc_id_source);
  sensors.gyr_id = DeviceId(log, src, "GYRO", &sensors.gyr_id_source);
  sensors.temperature = [&log](bool accel, double device_id) {
    return SensorTemperature(log, accel, device_id);
  };
  return sensors;
}

std::string Who(const StreamSource& src) {
  return std::string(KindName(src.kind)) + " instance " + std::to_string(src.instance) + ": ";
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
    s->warnings.push_back(Notice{"correction_changed",
                                 std::to_string(changes) +
                                     " calibration parameter change(s) during the log (first: " +
                                     first + "); the initial values were used",
                                 {}});
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

ImuStreamInfo Describe(const ULog& log, const StreamSource& src, const ImuSeries& s,
                       const LeftOutTimes& left_out) {
  ImuStreamInfo info = StreamInfoOf(s, left_out);
  info.name = KindName(src.kind);
  info.instance = src.instance;
  info.has_temperature = s.has_temperature();
  if (src.kind != StreamKind::kSensorAccel) {
    const Px4Sensors sensors = SensorsOf(log, src);
    info.applied = Px4AppliedText(log.params, sensors);
    info.undoable = Px4Undoable(log.params, sensors, s.has_gyro());
  }
  return info;
}

}  // namespace

std::vector<ImuStreamInfo> ULogImuStreams(const ULog& log) {
  std::vector<ImuStreamInfo> out;
  for (const StreamSource& src : Sources(log)) {
    if (src.kind == StreamKind::kCombined && src.topic->imu_decoded) {
      // No copy of the reader's samples.
      out.push_back(Describe(log, src, src.topic->imu, src.topic->imu_left_out));
    } else {
      const Extracted e = Extract(src, nullptr);
      out.push_back(Describe(log, src, e.series, e.left_out));
    }
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

namespace {

/// The velocity reports of the log's first GPS: vehicle_gps_position instance 0, else
/// sensor_gps instance 0; vel_m_s the ground speed, vel_d_m_s the vertical (down) speed, m/s;
/// fix_type >= 3 a 3D fix. Times are the topic's timestamp (us since boot), as the samples'.
std::vector<GpsVelocity> ULogGpsVelocity(const ULog& log, std::string* source) {
  std::vector<GpsVelocity> out;
  for (const char* name : {"vehicle_gps_position", "sensor_gps"}) {
    for (const ULogTopic& t : log.topics) {
      if (t.name != name || t.multi_id != 0 || !t.bodies_kept) continue;
      const int fix = t.ColumnIndex("fix_type");
      const int speed = t.ColumnIndex("vel_m_s");
      const int down = t.ColumnIndex("vel_d_m_s");
      if (fix < 0 || speed < 0 || t.timestamp_col < 0) continue;
      for (std::size_t r = 0; r < t.rows; ++r) {
        GpsVelocity v;
        v.t_s = static_cast<double>(t.TimestampUs(r)) * 1e-6;
        v.fix_3d = t.Value(r, static_cast<std::size_t>(fix)) >= 3;
        v.ground_speed_m_s = t.Value(r, static_cast<std::size_t>(speed));
        v.climb_m_s = down >= 0 ? -t.Value(r, static_cast<std::size_t>(down)) : 0.0;
        out.push_back(v);
      }
      *source = name;
      return out;
    }
  }
  return out;
}

/// vehicle_land_detected's `landed` field as a land detector's states (landed false:
/// airborne), repeated states kept (AirborneIntervals reads the changes).
std::vector<LandedState> ULogLandedStates(const ULog& log) {
  std::vector<LandedState> out;
  for (const ULogTopic& t : log.topics) {
    if (t.name != "vehicle_land_detected" || t.multi_id != 0 || !t.bodies_kept) continue;
    const int landed = t.ColumnIndex("landed");
    if (landed < 0 || t.timestamp_col < 0) continue;
    for (std::size_t r = 0; r < t.rows; ++r) {
      const bool down = t.Value(r, static_cast<std::size_t>(landed)) != 0.0;
      out.push_back({static_cast<double>(t.TimestampUs(r)) * 1e-6, !down,
                     down ? "landed" : "not landed"});
    }
  }
  return out;
}

}  // namespace

std::vector<LogMotion> ULogMotion(const ULog& log, double t_end_s) {
  std::vector<LogMotion> out =
      AirborneIntervals(ULogLandedStates(log), t_end_s, "vehicle_land_detected");
  std::string source;
  const std::vector<GpsVelocity> gps = ULogGpsVelocity(log, &source);
  for (LogMotion& m : GpsMotion(gps, source)) out.push_back(std::move(m));
  return out;
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

Session ULogSession(const ULog& log, const FlightLogSelection& selection,
                    ImuStreamInfo* chosen_info) {
  // The candidates: the sources of the instance (and the stream) selected, the only ones whose
  // samples are decoded (Select looks at no other).
  std::vector<StreamSource> sources;
  for (const StreamSource& src : Sources(log)) {
    if (src.instance != selection.imu) continue;
    if (!selection.stream.empty() && KindName(src.kind) != selection.stream) continue;
    sources.push_back(src);
  }
  std::vector<ImuStreamInfo> infos;
  std::vector<ImuSeries> all;
  std::vector<std::vector<Notice>> notes(sources.size());
  for (std::size_t i = 0; i < sources.size(); ++i) {
    std::vector<std::string> unpaired;  // a gyro topic not paired with the accelerometer's
    Extracted e = Extract(sources[i], &unpaired);
    AddNotices(notes[i], "gyro_unpaired", std::move(unpaired));
    infos.push_back(Describe(log, sources[i], e.series, e.left_out));
    if (auto w = DroppedRecordsWarning(infos.back())) {
      notes[i].push_back(Notice{"records_dropped", std::move(*w), {}});
    }
    all.push_back(std::move(e.series));
  }
  const StreamSource* src = Select(sources, infos, selection);
  const std::string wanted = (selection.stream.empty() ? std::string("IMU") : selection.stream) +
                             " instance " + std::to_string(selection.imu);
  if (src == nullptr) {
    throw InputError(log.source, "", "no " + wanted +
                                         " stream (sensor_combined, vehicle_imu or sensor_accel)");
  }
  const auto chosen = static_cast<std::size_t>(src - sources.data());
  if (chosen_info != nullptr) *chosen_info = infos[chosen];
  Session s;
  s.source = log.source + " (" + KindName(src->kind) + " instance " +
             std::to_string(src->instance) + ")";
  s.log_params = log.params;
  if (const auto id = log.params.find("MAV_SYS_ID"); id != log.params.end()) {
    s.system_id = static_cast<int>(id->second);
  }
  for (const auto& w : log.warnings.Describe()) {
    s.warnings.push_back(Notice{"log_damaged", log.source + ": " + w, {}});
  }
  if (log.dropouts > 0) {
    s.warnings.push_back(Notice{"records_dropped",
                                log.source + ": " + std::to_string(log.dropouts) +
                                    " logging dropout(s), " +
                                    std::to_string(log.dropout_total_ms) + " ms in total",
                                {}});
  }
  for (auto& n : notes[chosen]) s.warnings.push_back(std::move(n));
  const ImuSeries& whole = all[chosen];

  s.series = WindowOf(whole, selection);
  if (s.series.size() < 2) {
    throw InputError(log.source, std::string(KindName(src->kind)) + " instance " +
                                     std::to_string(src->instance),
                     EmptyWindowMessage(selection.from_s, selection.to_s,
                                        whole.t_s.empty() ? 0.0 : whole.t_s.front(),
                                        whole.t_s.empty() ? 0.0 : whole.t_s.back()));
  }
  const std::string who = Who(*src);
  const Px4Sensors sensors = SensorsOf(log, *src);
  if (src->kind == StreamKind::kSensorAccel) {
    s.warnings.push_back(Notice{
        "raw_sensor", who + "raw driver output (not calibrated by PX4), taken as logged", {}});
  } else if (!selection.undo_correction) {
    s.warnings.push_back(Notice{"correction_kept",
                                who + "samples taken as logged (calibrated by PX4 with " +
                                    infos[chosen].applied + ")",
                                {}});
    s.firmware_left.push_back(who + "PX4 " + infos[chosen].applied);
  } else {
    UndoPx4Correction(log.params, sensors, who, &s.series, &s.warnings,
                      &s.firmware_left);
    WarnParamChanges(log, &s);
  }
  s.device_ids = {sensors.acc_id, sensors.gyr_id};
  s.site = SiteFromULog(log);
  s.log_motion = ULogMotion(log, s.series.t_s.back());
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
  out.motion = ULogMotion(log, LogSpan(out.imus).second);
  out.params = ULogParams(log);
  out.messages = log.MessageCounts();
  AddNotices(out.warnings, "log_damaged", log.warnings.Describe());
  if (log.dropouts > 0) {
    AddNotice(out.warnings, "records_dropped",
              std::to_string(log.dropouts) + " logging dropout(s), " +
                  std::to_string(log.dropout_total_ms) + " ms in total");
  }
  return out;
}

bool LooksLikeULog(const std::string& path) {
  std::ifstream in(OpenPath(path), std::ios::binary);
  unsigned char head[sizeof(detail::kULogMagic)] = {};
  in.read(reinterpret_cast<char*>(head), sizeof(head));
  return in.gcount() == static_cast<std::streamsize>(sizeof(head)) &&
         std::equal(head, head + sizeof(head), detail::kULogMagic);
}

RecordFilter Px4SessionTopics() {
  RecordFilter filter;
  // sensor_combined: decoded in the reader's pass (a session and `plumb info` read its samples).
  filter.decode = [](std::string_view name) { return name == "sensor_combined"; };
  filter.keep = [](std::string_view name) {
    for (const char* topic : {"sensor_combined", "vehicle_imu", "vehicle_imu_status",
                              "sensor_accel", "sensor_gyro", "sensor_gps",
                              "vehicle_gps_position", "vehicle_land_detected"}) {
      if (name == topic) return true;
    }
    return false;
  };
  return filter;
}

}  // namespace plumb::io

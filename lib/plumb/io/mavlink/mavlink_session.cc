// plumb/io/mavlink/mavlink_session.cc — see mavlink_session.h.
#include "plumb/io/mavlink/mavlink_session.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <string_view>
#include <unordered_set>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/ardupilot/ardupilot_correction.h"
#include "plumb/io/common/stream_spool.h"

namespace plumb::io {
namespace {

constexpr double kMilliRad = 1e-3;             // rad/s per mrad/s
constexpr double kCentiDegC = 0.01;            // degC per cdegC
constexpr double kMicro = 1e-6;                // s per µs
constexpr double kDegE7 = 1e-7;                // degrees per degE7
constexpr double kMilli = 1e-3;                // m per mm
constexpr int kMinFix3d = 3;                   // GPS_FIX_TYPE_3D_FIX
constexpr std::uint16_t kUnknownU16 = 65535;   // GPS_RAW_INT: a field not known
constexpr std::uint64_t kWrap32 = 1ull << 32;  // a 32-bit µs counter wraps here (71.6 min)
constexpr std::uint64_t kWrapMargin_us = 60000000ull;  // 60 s either side of the wrap

/// The IMU messages, in stream order.
enum class Kind { kRaw, kScaled, kScaled2, kScaled3, kHighres };
constexpr Kind kKinds[] = {Kind::kRaw, Kind::kScaled, Kind::kScaled2, Kind::kScaled3,
                           Kind::kHighres};

const char* KindName(Kind k) {
  switch (k) {
    case Kind::kRaw: return "RAW_IMU";
    case Kind::kScaled: return "SCALED_IMU";
    case Kind::kScaled2: return "SCALED_IMU2";
    case Kind::kScaled3: return "SCALED_IMU3";
    case Kind::kHighres: return "HIGHRES_IMU";
  }
  return "";
}

const std::vector<MavlinkInt16Imu>* Int16Records(const MavlinkLog& log, Kind k) {
  switch (k) {
    case Kind::kRaw: return &log.raw_imu;
    case Kind::kScaled: return &log.scaled_imu;
    case Kind::kScaled2: return &log.scaled_imu2;
    case Kind::kScaled3: return &log.scaled_imu3;
    case Kind::kHighres: return nullptr;
  }
  return nullptr;
}

/// Instance of a record: the id field for RAW_IMU and HIGHRES_IMU, fixed for SCALED_IMU*.
int Int16Instance(Kind k, const MavlinkInt16Imu& r) {
  switch (k) {
    case Kind::kRaw: return r.id;
    case Kind::kScaled2: return 1;
    case Kind::kScaled3: return 2;
    default: return 0;
  }
}

/// One sample of a stream in the session's units (see ToSample).
struct Sample {
  std::uint64_t time_us = 0;
  double log_time_s = 0.0;
  Vec3 acc = Vec3::Zero();
  Vec3 gyr = Vec3::Zero();
  double temp_c = 0.0;
  bool has_temp = false;
};

/// Units of a stream: scale factors from the message's units to the session's.
struct Units {
  double acc = 1.0;          // session acc unit per message unit
  double gyr = 1.0;          // session gyr unit per message unit
  std::string acc_unit = "m/s^2";
  std::string gyr_unit = "rad/s";
  std::string text;          // for the warnings
};

Units StreamUnits(Kind k, bool ardupilot) {
  Units u;
  if (k == Kind::kHighres) {
    u.text = "m/s^2 and rad/s as sent";
  } else if (k == Kind::kRaw && !ardupilot) {
    u.acc_unit = "counts";
    u.gyr_unit = "counts";
    u.text = "raw sensor counts as sent (RAW_IMU from a non-ArduPilot autopilot)";
  } else {
    u.acc = units::kMilliG;
    u.gyr = kMilliRad;
    u.text = "mG * 9.80665e-3 -> m/s^2 and mrad/s * 1e-3 -> rad/s (steps of 1 mG and 1 mrad/s)";
  }
  return u;
}

/// The samples of stream (kind, instance) sent by `v`, in log order, converted with `u`.
std::vector<Sample> StreamSamples(const MavlinkLog& log, const MavlinkVehicle& v, Kind k,
                                  int instance, const Units& u) {
  std::vector<Sample> out;
  const auto from_vehicle = [&](std::uint8_t sys, std::uint8_t comp) {
    return sys == v.system_id && comp == v.component_id;
  };
  if (k == Kind::kHighres) {
    for (const MavlinkHighresImu& r : log.highres_imu) {
      if (!from_vehicle(r.system_id, r.component_id) || r.id != instance) continue;
      Sample& s = out.emplace_back();
      s.time_us = r.time_us;
      s.log_time_s = r.log_time_s;
      for (int i = 0; i < 3; ++i) {
        s.acc[i] = r.acc[static_cast<std::size_t>(i)];
        s.gyr[i] = r.gyr[static_cast<std::size_t>(i)];
      }
      s.temp_c = r.temperature_degc;
      s.has_temp = r.temperature_degc != 0.0f;
    }
    return out;
  }
  for (const MavlinkInt16Imu& r : *Int16Records(log, k)) {
    if (!from_vehicle(r.system_id, r.component_id) || Int16Instance(k, r) != instance) continue;
    Sample& s = out.emplace_back();
    s.time_us = r.time_us;
    s.log_time_s = r.log_time_s;
    for (int i = 0; i < 3; ++i) {
      s.acc[i] = r.acc[static_cast<std::size_t>(i)] * u.acc;
      s.gyr[i] = r.gyr[static_cast<std::size_t>(i)] * u.gyr;
    }
    s.temp_c = r.temperature_cdegc * kCentiDegC;
    s.has_temp = r.temperature_cdegc != 0;
  }
  return out;
}

/// Sample times, s: the message's own time (a 32-bit µs counter's wrap undone), or the tlog
/// time when every message time is zero. `*used_log_time` says which.
std::vector<double> SampleTimes(const std::vector<Sample>& samples, bool* used_log_time) {
  std::vector<double> t(samples.size());
  const bool all_zero = std::all_of(samples.begin(), samples.end(),
                                    [](const Sample& s) { return s.time_us == 0; });
  *used_log_time = all_zero && !samples.empty();
  std::uint64_t offset = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (*used_log_time) {
      t[i] = samples[i].log_time_s;
      continue;
    }
    const std::uint64_t cur = samples[i].time_us;
    if (i > 0) {
      const std::uint64_t prev = samples[i - 1].time_us;
      if (prev < kWrap32 && prev >= kWrap32 - kWrapMargin_us && cur < kWrapMargin_us) {
        offset += kWrap32;
      }
    }
    t[i] = static_cast<double>(cur + offset) * kMicro;
  }
  return t;
}

struct SourceKey {
  std::uint8_t system_id;
  std::uint8_t component_id;
};

bool IsArdupilot(const std::optional<MavlinkVehicle>& v) {
  return v && v->autopilot == kMavAutopilotArdupilotMega;
}

std::string AutopilotName(int autopilot) {
  if (autopilot == kMavAutopilotArdupilotMega) return "ArduPilot";
  if (autopilot == kMavAutopilotPx4) return "PX4";
  if (autopilot < 0) return "unknown autopilot (no HEARTBEAT)";
  return "MAV_AUTOPILOT " + std::to_string(autopilot);
}

/// Every (kind, instance) stream of `v`, with its samples in session units.
struct StreamData {
  Kind kind;
  int instance;
  std::vector<Sample> samples;
  std::vector<double> t_s;
  bool used_log_time = false;
};

std::vector<StreamData> AllStreams(const MavlinkLog& log, const MavlinkVehicle& v) {
  const bool ardupilot = v.autopilot == kMavAutopilotArdupilotMega;
  std::vector<StreamData> out;
  for (Kind k : kKinds) {
    std::array<bool, 256> seen{};
    if (k == Kind::kHighres) {
      for (const MavlinkHighresImu& r : log.highres_imu) {
        if (r.system_id == v.system_id && r.component_id == v.component_id) seen[r.id] = true;
      }
    } else {
      for (const MavlinkInt16Imu& r : *Int16Records(log, k)) {
        if (r.system_id == v.system_id && r.component_id == v.component_id) {
          seen[static_cast<std::size_t>(Int16Instance(k, r))] = true;
        }
      }
    }
    for (int instance = 0; instance < 256; ++instance) {
      if (!seen[static_cast<std::size_t>(instance)]) continue;
      StreamData d{k, instance, {}, {}, false};
      d.samples = StreamSamples(log, v, k, instance, StreamUnits(k, ardupilot));
      d.t_s = SampleTimes(d.samples, &d.used_log_time);
      out.push_back(std::move(d));
    }
  }
  return out;
}

ImuStreamInfo Describe(const StreamData& d, const MavlinkVehicle& v,
                       const std::map<std::string, double>& params) {
  ImuStreamInfo info;
  info.name = KindName(d.kind);
  info.instance = d.instance;
  info.samples = d.samples.size();
  if (!d.t_s.empty()) {
    info.t_start_s = d.t_s.front();
    info.t_end_s = d.t_s.back();
    const double span = info.t_end_s - info.t_start_s;
    if (d.t_s.size() >= 2 && span > 0.0) {
      info.rate_hz = static_cast<double>(d.t_s.size() - 1) / span;
    }
  }
  info.has_temperature = std::any_of(d.samples.begin(), d.samples.end(),
                                     [](const Sample& s) { return s.has_temp; });
  if (v.autopilot == kMavAutopilotArdupilotMega) {
    const ArdupilotCorrection c = ArdupilotCorrectionFor(params, d.instance);
    info.applied = c.Describe(true, true);
    info.undoable = c.Undoable(true, true, info.has_temperature);
  } else if (d.kind == Kind::kRaw) {
    info.applied = "";
  } else {
    info.applied = "autopilot calibration (unknown)";
  }
  return info;
}

/// Index in `streams` of the selected stream, or -1: by name (at instance selection.imu, or
/// the only instance of that name), else the default of instance selection.imu (highest rate,
/// then most samples, then stream order).
int ChooseStream(const std::vector<ImuStreamInfo>& infos, const FlightLogSelection& selection) {
  if (!selection.stream.empty()) {
    int only = -1;
    int named = 0;
    for (std::size_t i = 0; i < infos.size(); ++i) {
      if (infos[i].name != selection.stream) continue;
      if (infos[i].instance == selection.imu) return static_cast<int>(i);
      only = static_cast<int>(i);
      ++named;
    }
    return named == 1 ? only : -1;
  }
  int best = -1;
  for (std::size_t i = 0; i < infos.size(); ++i) {
    if (infos[i].instance != selection.imu) continue;
    if (best < 0) {
      best = static_cast<int>(i);
      continue;
    }
    const ImuStreamInfo& b = infos[static_cast<std::size_t>(best)];
    if (infos[i].rate_hz > b.rate_hz ||
        (infos[i].rate_hz == b.rate_hz && infos[i].samples > b.samples)) {
      best = static_cast<int>(i);
    }
  }
  return best;
}

/// The samples of `d` inside the selection's window as a series in `units`. A sample is
/// dropped (counted in `*dropped`) when its time is not finite, does not exceed the last kept
/// sample's, or is not below the next sample's (a corrupted spike), as in the DataFlash reader.
ImuSeries WindowedSeries(const StreamData& d, const FlightLogSelection& selection,
                         const Units& units, bool has_temp, LeftOutTimes* dropped) {
  ImuSeries out;
  out.acc_unit = units.acc_unit;
  out.gyr_unit = units.gyr_unit;
  double last_t = 0.0;
  bool any = false;
  for (std::size_t i = 0; i < d.samples.size(); ++i) {
    const double t = d.t_s[i];
    const bool spike = i + 1 < d.samples.size() && !(t < d.t_s[i + 1]);
    if (!std::isfinite(t) || (any && !(t > last_t)) || spike) {
      if (dropped->count++ == 0) dropped->first_t_s = t;
      continue;
    }
    any = true;
    last_t = t;
    if (selection.from_s && t < *selection.from_s) continue;
    if (selection.to_s && t > *selection.to_s) continue;
    const Sample& x = d.samples[i];
    out.t_s.push_back(t);
    out.acc.push_back(x.acc.cast<float>());
    out.gyr.push_back(x.gyr.cast<float>());
    if (has_temp) out.temp_c.push_back(static_cast<float>(x.temp_c));
  }
  return out;
}

}  // namespace

std::optional<MavlinkVehicle> TlogVehicle(const MavlinkLog& log) {
  // (system, component) -> frames, first log time.
  std::map<std::pair<int, int>, std::pair<std::size_t, double>> sources;
  auto last = sources.end();  // the source of the record before: most often this one's
  const auto add = [&](std::uint8_t sys, std::uint8_t comp, double t) {
    const std::pair<int, int> key{sys, comp};
    if (last == sources.end() || last->first != key) last = sources.try_emplace(key, 0, t).first;
    ++last->second.first;
    last->second.second = std::min(last->second.second, t);
  };
  for (Kind k : kKinds) {
    if (k == Kind::kHighres) {
      for (const auto& r : log.highres_imu) add(r.system_id, r.component_id, r.log_time_s);
    } else {
      for (const auto& r : *Int16Records(log, k)) add(r.system_id, r.component_id, r.log_time_s);
    }
  }
  if (sources.empty()) return std::nullopt;
  auto best = sources.begin();
  for (auto it = sources.begin(); it != sources.end(); ++it) {
    if (it->second.first > best->second.first ||
        (it->second.first == best->second.first && it->second.second < best->second.second)) {
      best = it;
    }
  }
  MavlinkVehicle v;
  v.system_id = static_cast<std::uint8_t>(best->first.first);
  v.component_id = static_cast<std::uint8_t>(best->first.second);
  v.imu_frames = best->second.first;
  v.other_sources = sources.size() - 1;
  for (const MavlinkHeartbeat& h : log.heartbeat) {
    if (h.system_id == v.system_id && h.component_id == v.component_id) {
      v.autopilot = h.autopilot;
      break;
    }
  }
  if (v.autopilot < 0) {
    // No HEARTBEAT (a cut log): ArduPilot is recognised by its INS_ parameters.
    for (const MavlinkParamValue& p : log.param_value) {
      if (p.system_id == v.system_id && p.NameView() == "INS_ACCOFFS_X") {
        v.autopilot = kMavAutopilotArdupilotMega;
        break;
      }
    }
  }
  return v;
}

std::vector<ImuStreamInfo> TlogImuStreams(const MavlinkLog& log) {
  const std::optional<MavlinkVehicle> v = TlogVehicle(log);
  if (!v) return {};
  const std::map<std::string, double> params = TlogParams(log);
  std::vector<ImuStreamInfo> out;
  for (const StreamData& d : AllStreams(log, *v)) out.push_back(Describe(d, *v, params));
  return out;
}

std::optional<SiteInput> SiteFromTlog(const MavlinkLog& log) {
  const std::optional<MavlinkVehicle> v = TlogVehicle(log);
  std::vector<double> lats, lons, alts;
  for (const MavlinkGpsRawInt& g : log.gps_raw_int) {
    if (v && g.system_id != v->system_id) continue;
    if (g.fix_type < kMinFix3d) continue;
    const double lat = g.lat_e7 * kDegE7;
    const double lon = g.lon_e7 * kDegE7;
    if ((g.lat_e7 == 0 && g.lon_e7 == 0) || std::abs(lat) > 90.0 || std::abs(lon) > 180.0) {
      continue;
    }
    lats.push_back(lat);
    lons.push_back(lon);
    alts.push_back(g.alt_mm * kMilli);
  }
  return MedianSite(std::move(lats), std::move(lons), std::move(alts));
}

std::vector<LogMotion> TlogMotion(const MavlinkLog& log, const std::vector<double>& log_time_s,
                                  const std::vector<double>& t_s) {
  std::vector<GpsVelocity> reports;
  if (log_time_s.empty() || log_time_s.size() != t_s.size()) return {};
  const std::optional<MavlinkVehicle> v = TlogVehicle(log);
  for (const MavlinkGpsRawInt& g : log.gps_raw_int) {
    if (v && g.system_id != v->system_id) continue;
    if (g.vel_cm_s == kUnknownU16) continue;
    // The IMU sample received nearest in tlog time carries the offset between the clocks.
    const auto it = std::lower_bound(log_time_s.begin(), log_time_s.end(), g.log_time_s);
    std::size_t k = static_cast<std::size_t>(it - log_time_s.begin());
    if (k == log_time_s.size() ||
        (k > 0 && g.log_time_s - log_time_s[k - 1] < log_time_s[k] - g.log_time_s)) {
      --k;
    }
    GpsVelocity r;
    r.t_s = t_s[k] + (g.log_time_s - log_time_s[k]);
    r.fix_3d = g.fix_type >= kMinFix3d;
    r.ground_speed_m_s = g.vel_cm_s * 0.01;
    reports.push_back(r);
  }
  return GpsMotion(reports, "GPS_RAW_INT");
}

namespace {

/// TlogMotion on the clock of stream `d`: the pairs (tlog time, sample time) of its samples in
/// tlog order, tlog time increasing.
std::vector<LogMotion> StreamMotion(const MavlinkLog& log, const StreamData& d) {
  std::vector<double> log_time, t;
  for (std::size_t i = 0; i < d.samples.size(); ++i) {
    const bool later = log_time.empty() || d.samples[i].log_time_s > log_time.back();
    if (!std::isfinite(d.t_s[i]) || !later) continue;
    log_time.push_back(d.samples[i].log_time_s);
    t.push_back(d.t_s[i]);
  }
  return TlogMotion(log, log_time, t);
}

}  // namespace

std::map<std::string, double> TlogParams(const MavlinkLog& log) {
  const std::optional<MavlinkVehicle> v = TlogVehicle(log);
  const bool bytewise = v && v->autopilot == kMavAutopilotPx4;
  // The last value of each name wins: from the last message back, the first one met is kept
  // (a log may hold the whole list many times over, and names are compared once each here).
  std::map<std::string, double> params;
  std::unordered_set<std::string_view> seen;
  for (auto p = log.param_value.rbegin(); p != log.param_value.rend(); ++p) {
    if (v && p->system_id != v->system_id) continue;
    const std::string_view name = p->NameView();
    if (name.empty() || !seen.insert(name).second) continue;
    double value = p->value;
    if (bytewise && p->type >= 1 && p->type <= 6) {
      std::uint32_t bits = 0;
      std::memcpy(&bits, &p->value, sizeof(bits));
      switch (p->type) {
        case 1: value = static_cast<std::uint8_t>(bits & 0xFFu); break;
        case 2: value = static_cast<std::int8_t>(bits & 0xFFu); break;
        case 3: value = static_cast<std::uint16_t>(bits & 0xFFFFu); break;
        case 4: value = static_cast<std::int16_t>(bits & 0xFFFFu); break;
        case 5: value = bits; break;
        default: value = static_cast<std::int32_t>(bits); break;
      }
    }
    params.emplace(std::string(name), value);
  }
  return params;
}

Session TlogSession(const MavlinkLog& log, const FlightLogSelection& selection,
                    ImuStreamInfo* chosen_info) {
  if (selection.imu < 0) throw Error("TlogSession: the IMU instance must be >= 0");
  const std::optional<MavlinkVehicle> vehicle = TlogVehicle(log);
  if (!vehicle) {
    throw InputError(log.source, "",
                     "no IMU message (RAW_IMU, SCALED_IMU, SCALED_IMU2, SCALED_IMU3, "
                     "HIGHRES_IMU) in the tlog");
  }
  const MavlinkVehicle& v = *vehicle;
  const bool ardupilot = IsArdupilot(vehicle);
  const std::map<std::string, double> params = TlogParams(log);
  const std::vector<StreamData> streams = AllStreams(log, v);
  std::vector<ImuStreamInfo> infos;
  for (const StreamData& d : streams) infos.push_back(Describe(d, v, params));
  const int chosen = ChooseStream(infos, selection);
  const std::string wanted = (selection.stream.empty() ? "IMU" : selection.stream) +
                             " instance " + std::to_string(selection.imu);
  if (chosen < 0) {
    std::string have;
    for (const ImuStreamInfo& i : infos) {
      have += (have.empty() ? "" : ", ") + i.name + " instance " + std::to_string(i.instance);
    }
    throw InputError(log.source, "", "no " + wanted + " stream; the log has " + have);
  }
  const StreamData& d = streams[static_cast<std::size_t>(chosen)];
  const ImuStreamInfo& info = infos[static_cast<std::size_t>(chosen)];
  if (chosen_info != nullptr) *chosen_info = info;
  const Units units = StreamUnits(d.kind, ardupilot);

  Session s;
  s.source = log.source + " (" + info.name + " instance " + std::to_string(d.instance) + ")";
  s.log_params = params;
  s.system_id = v.system_id;
  for (const auto& w : log.warnings.Describe(log.message_counts)) {
    s.warnings.push_back(Notice{"log_damaged", log.source + ": " + w, {}});
  }
  if (v.other_sources > 0) {
    s.warnings.push_back(Notice{"other_senders",
                                std::to_string(v.other_sources) +
                                    " other system/component(s) sent IMU messages; using "
                                    "system " + std::to_string(v.system_id) + " component " +
                                    std::to_string(v.component_id) + " (most IMU frames)",
                                {}});
  }
  const std::string who = info.name + " instance " + std::to_string(d.instance) + ": ";
  s.warnings.push_back(Notice{"sample_source",
                              who + "from system " + std::to_string(v.system_id) +
                                  " component " + std::to_string(v.component_id) + " (" +
                                  AutopilotName(v.autopilot) + "), " + units.text,
                              {}});
  s.warnings.push_back(
      Notice{"sample_times",
             who + (d.used_log_time ? "message times all zero: times from the tlog (unix s)"
                                    : "times from the message's own time stamps (s)"),
             {}});

  LeftOutTimes dropped;
  s.series = WindowedSeries(d, selection, units, info.has_temperature, &dropped);
  ImuSeries& out = s.series;
  if (dropped.count > 0) {
    s.warnings.push_back(Notice{
        "samples_out_of_order",
        who + "dropped " + std::to_string(dropped.count) +
            " sample(s) whose time did not increase past the last kept one, or ran ahead of the "
            "next (a reboot or a corrupted time); the first with time " +
            LeftOutTimeText(*dropped.first_t_s),
        {}});
  }
  if (out.size() < 2) {
    throw InputError(log.source, info.name + " instance " + std::to_string(d.instance),
                     EmptyWindowMessage(selection.from_s, selection.to_s, info.t_start_s,
                                        info.t_end_s));
  }

  // ArduPilot's correction, undone (ardupilot_correction.h has the equations).
  if (ardupilot) {
    const std::vector<Notice> undo =
        UndoArdupilotCorrection(ArdupilotCorrectionFor(params, d.instance),
                                selection.undo_correction, who, &out, &s.firmware_left);
    s.warnings.insert(s.warnings.end(), undo.begin(), undo.end());
  } else if (!info.applied.empty()) {
    s.warnings.push_back(Notice{"correction_kept",
                                who + "calibrated by " + AutopilotName(v.autopilot) +
                                    " in a way the tlog does not state: samples taken as sent",
                                {}});
    s.firmware_left.push_back(who + info.applied);
  } else {
    s.warnings.push_back(Notice{"raw_sensor", who + "raw sensor output as sent", {}});
  }
  s.site = SiteFromTlog(log);
  s.log_motion = StreamMotion(log, d);
  return s;
}

FlightLogSummary TlogSummary(const MavlinkLog& log) {
  FlightLogSummary out;
  out.source = log.source;
  out.format = "mavlink-tlog";
  out.size_bytes = log.size_bytes;
  out.format_detail = "MAVLink v1 " + std::to_string(log.frames_v1) + " frames, v2 " +
                      std::to_string(log.frames_v2) + " frames (" +
                      std::to_string(log.frames_signed) + " signed), " +
                      std::to_string(log.checked_frames) + " CRC-checked";
  if (const std::optional<MavlinkVehicle> v = TlogVehicle(log)) {
    out.format_detail += ", " + AutopilotName(v->autopilot) + " (system " +
                         std::to_string(v->system_id) + ", component " +
                         std::to_string(v->component_id) + ")";
  }
  out.imus = TlogImuStreams(log);
  out.site = SiteFromTlog(log);
  if (const std::optional<MavlinkVehicle> v = TlogVehicle(log)) {
    const std::vector<StreamData> streams = AllStreams(log, *v);
    if (!streams.empty()) out.motion = StreamMotion(log, streams.front());
  }
  for (const auto& [name, value] : TlogParams(log)) {
    for (const char* prefix :
         {"INS_ACC", "INS_GYR", "INS_TCAL", "AHRS_ORIENTATION", "CAL_ACC", "CAL_GYRO"}) {
      if (name.rfind(prefix, 0) == 0) {
        out.params[name] = value;
        break;
      }
    }
  }
  out.messages = log.MessageCounts();
  AddNotices(out.warnings, "log_damaged", log.warnings.Describe(log.message_counts));
  return out;
}

bool LooksLikeTlog(const std::string& path) {
  std::ifstream in(OpenPath(path), std::ios::binary);
  std::uint8_t head[9] = {};
  in.read(reinterpret_cast<char*>(head), sizeof(head));
  return in.gcount() == static_cast<std::streamsize>(sizeof(head)) &&
         LooksLikeTlogRecord(head, sizeof(head));
}

}  // namespace plumb::io

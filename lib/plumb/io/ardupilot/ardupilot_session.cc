// plumb/io/ardupilot/ardupilot_session.cc — see ardupilot_session.h.
#include "plumb/io/ardupilot/ardupilot_session.h"

#include <algorithm>
#include <vector>
#include <map>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/ardupilot/ardupilot_correction.h"
#include "plumb/io/ardupilot/dataflash_format.h"
#include "plumb/io/ardupilot/dataflash_parser.h"
#include "plumb/io/common/stream_spool.h"

namespace plumb::io {
namespace {

/// Warns when a parameter of ArduPilot's IMU correction takes more than one value in the log's
/// PARM records: the undo uses the last value for every sample, so samples logged before a
/// recalibration are reconstructed with the later values.
void WarnCorrectionChanges(const DataflashLog& log, const std::string& who,
                           std::vector<Notice>* warnings) {
  const DataflashType* parm = log.Find("PARM");
  if (parm == nullptr) return;
  const int name_col = parm->ColumnIndex("Name");
  const int value_col = parm->ColumnIndex("Value");
  if (name_col < 0 || value_col < 0) return;
  std::map<std::string, std::vector<double>> values;
  for (std::size_t r = 0; r < parm->rows; ++r) {
    const std::string name = parm->Text(r, static_cast<std::size_t>(name_col));
    const bool correction = name.rfind("INS_ACC", 0) == 0 || name.rfind("INS_GYR", 0) == 0 ||
                            name.rfind("INS_TCAL", 0) == 0 || name == "AHRS_ORIENTATION";
    if (!correction) continue;
    const double v = parm->Value(r, static_cast<std::size_t>(value_col));
    std::vector<double>& seen = values[name];
    if (std::find(seen.begin(), seen.end(), v) == seen.end()) seen.push_back(v);
  }
  std::string changed;
  for (const auto& [name, seen] : values) {
    if (seen.size() > 1) changed += (changed.empty() ? "" : ", ") + name;
  }
  if (!changed.empty()) {
    warnings->push_back(Notice{"correction_changed",
                               who + "parameters of ArduPilot's correction changed during the "
                                     "log (" + changed + "): the last values are used for "
                                     "every sample",
                               {}});
  }
}

/// The time column of a GPS record, s since boot: TimeUS, or in the oldest layout (TimeMS the
/// GPS's time of week, beside Week) the boot time T in ms. {-1, 0} without one.
detail::DataflashTimeColumn GpsBootTime(const DataflashType& gps) {
  if (const int c = gps.ColumnIndex("TimeUS"); c >= 0) return {c, 1e-6};
  if (const int c = gps.ColumnIndex("T"); c >= 0 && gps.ColumnIndex("Week") >= 0) {
    return {c, 1e-3};
  }
  return {};
}

/// The first GPS's velocity reports (GPS, or its records with I = 0), Status >= 3 a 3D fix,
/// Spd the ground speed and VZ the vertical speed, m/s.
std::vector<GpsVelocity> DataflashGpsVelocity(const DataflashLog& log) {
  std::vector<GpsVelocity> out;
  const DataflashType* gps = log.Find("GPS");
  if (gps == nullptr || !gps->bodies_kept) return out;
  const detail::DataflashTimeColumn time = GpsBootTime(*gps);
  const int status = gps->ColumnIndex("Status");
  const int spd = gps->ColumnIndex("Spd");
  const int vz = gps->ColumnIndex("VZ");
  const int instance = gps->ColumnIndex("I");
  if (time.col < 0 || status < 0 || spd < 0) return out;
  const auto at = [&](std::size_t r, int c) { return gps->Value(r, static_cast<std::size_t>(c)); };
  for (std::size_t r = 0; r < gps->rows; ++r) {
    if (instance >= 0 && at(r, instance) != 0.0) continue;
    GpsVelocity v;
    v.t_s = at(r, time.col) * time.scale;
    v.fix_3d = at(r, status) >= 3;
    v.ground_speed_m_s = at(r, spd);
    v.climb_m_s = vz >= 0 ? at(r, vz) : 0.0;
    if (std::isfinite(v.t_s)) out.push_back(v);
  }
  return out;
}

/// ArduPilot's land detector as its EV records give it (AP_Logger's LogEvent: NOT_LANDED 28
/// airborne; LAND_COMPLETE 18 and DISARMED 11 landed). Only records with a TimeUS: the oldest
/// layout's EV has no time, and its place among the other messages is not kept.
std::vector<LandedState> DataflashLandedStates(const DataflashLog& log) {
  std::vector<LandedState> out;
  const DataflashType* ev = log.Find("EV");
  if (ev == nullptr || !ev->bodies_kept) return out;
  const int time = ev->ColumnIndex("TimeUS");
  const int id = ev->ColumnIndex("Id");
  if (time < 0 || id < 0) return out;
  for (std::size_t r = 0; r < ev->rows; ++r) {
    const double t = ev->Value(r, static_cast<std::size_t>(time)) * 1e-6;
    const double e = ev->Value(r, static_cast<std::size_t>(id));
    if (!std::isfinite(t)) continue;
    if (e == 28.0) out.push_back({t, true, "NOT_LANDED"});
    if (e == 18.0) out.push_back({t, false, "LAND_COMPLETE"});
    if (e == 11.0) out.push_back({t, false, "DISARMED"});
  }
  return out;
}

}  // namespace

std::vector<LogMotion> DataflashMotion(const DataflashLog& log, double t_end_s) {
  std::vector<LogMotion> out =
      AirborneIntervals(DataflashLandedStates(log), t_end_s, "EV");
  for (LogMotion& m : GpsMotion(DataflashGpsVelocity(log), "GPS")) out.push_back(std::move(m));
  return out;
}

std::optional<SiteInput> SiteFromDataflash(const DataflashLog& log) {
  const DataflashType* gps = log.Find("GPS");
  if (gps == nullptr) return std::nullopt;
  const int status = gps->ColumnIndex("Status");
  const int lat = gps->ColumnIndex("Lat");
  const int lng = gps->ColumnIndex("Lng");
  const int alt = gps->ColumnIndex("Alt");
  if (status < 0 || lat < 0 || lng < 0) return std::nullopt;
  std::vector<double> lats, lngs, alts;
  for (std::size_t r = 0; r < gps->rows; ++r) {
    if (gps->Value(r, static_cast<std::size_t>(status)) < 3) continue;
    const double la = gps->Value(r, static_cast<std::size_t>(lat));
    const double lo = gps->Value(r, static_cast<std::size_t>(lng));
    if (!std::isfinite(la) || !std::isfinite(lo) || (la == 0.0 && lo == 0.0)) continue;
    if (std::abs(la) > 90.0 || std::abs(lo) > 180.0) continue;
    lats.push_back(la);
    lngs.push_back(lo);
    alts.push_back(alt >= 0 ? gps->Value(r, static_cast<std::size_t>(alt)) : 0.0);
  }
  return MedianSite(std::move(lats), std::move(lngs), std::move(alts));
}

Session ArdupilotSession(const DataflashLog& log, const FlightLogSelection& selection,
                         ImuStreamInfo* chosen) {
  if (selection.imu < 0) throw Error("ArdupilotSession: the IMU instance must be >= 0");
  ImuStreamInfo info;
  Session s;
  // Throws when absent, gyro-only or empty; the stream's samples are decoded once.
  s.series = DataflashStream(log, selection, &info);
  if (chosen != nullptr) *chosen = info;
  const std::string stream = info.name;
  const int instance = info.instance;
  const std::string label = stream + " of IMU instance " + std::to_string(instance);
  s.source = log.source + " " + stream + " (IMU instance " + std::to_string(instance) + ")";
  for (const auto& w : log.warnings.Describe()) {
    s.warnings.push_back(Notice{"log_damaged", log.source + ": " + w, {}});
  }
  if (auto w = DroppedRecordsWarning(info)) {
    s.warnings.push_back(Notice{"records_dropped", log.source + ": " + *w, {}});
  }
  if (s.series.size() < 2) {
    throw InputError(log.source, label,
                     EmptyWindowMessage(selection.from_s, selection.to_s,
                                        info.t_start_s, info.t_end_s));
  }
  const ArdupilotCorrection correction = ArdupilotCorrectionFor(log.params, instance);
  const std::vector<Notice> undone =
      UndoArdupilotCorrection(correction, selection.undo_correction, label + ": ", &s.series,
                              &s.firmware_left);
  s.warnings.insert(s.warnings.end(), undone.begin(), undone.end());
  WarnCorrectionChanges(log, label + ": ", &s.warnings);
  s.site = SiteFromDataflash(log);
  s.log_motion = DataflashMotion(log, s.series.t_s.back());
  s.log_params = log.params;
  if (const auto id = log.params.find("SYSID_THISMAV"); id != log.params.end()) {
    s.system_id = static_cast<int>(id->second);
  }
  return s;
}

Session ArdupilotSession(const DataflashLog& log, const ArdupilotSessionOptions& options) {
  FlightLogSelection selection;
  selection.imu = options.imu;
  selection.from_s = options.from_s;
  selection.to_s = options.to_s;
  selection.undo_correction = options.undo_correction;
  return ArdupilotSession(log, selection);
}

bool LooksLikeDataflash(const std::string& path) {
  std::ifstream in(OpenPath(path), std::ios::binary);
  unsigned char head[2] = {0, 0};
  in.read(reinterpret_cast<char*>(head), 2);
  return in.gcount() == 2 && head[0] == detail::kDataflashHead1 &&
         head[1] == detail::kDataflashHead2;
}

RecordFilter ArdupilotSessionRecords() {
  RecordFilter filter;
  filter.keep = [](std::string_view name) {
    for (const char* exact : {"FMT", "FMTU", "UNIT", "MULT", "PARM", "ISBH", "ISBD", "EV"}) {
      if (name == exact) return true;
    }
    // A family and its numbered instances: IMU, IMU2, IMU3; ACC, ACC1; GPS, GPS2.
    for (std::string_view family : {"IMU", "ACC", "GYR", "GPS"}) {
      if (name.substr(0, family.size()) != family) continue;
      const std::string_view rest = name.substr(family.size());
      if (std::all_of(rest.begin(), rest.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        return true;
      }
    }
    return false;
  };
  // IMU, IMU2, IMU3: decoded in the reader's pass (what a session and `plumb info` read of
  // them is their samples).
  filter.decode = [](std::string_view name) {
    if (name.substr(0, 3) != "IMU") return false;
    const std::string_view rest = name.substr(3);
    return std::all_of(rest.begin(), rest.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  return filter;
}

}  // namespace plumb::io

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

namespace plumb::io {
namespace {

/// Warns when a parameter of ArduPilot's IMU correction takes more than one value in the log's
/// PARM records: the undo uses the last value for every sample, so samples logged before a
/// recalibration are reconstructed with the later values.
void WarnCorrectionChanges(const DataflashLog& log, const std::string& who,
                           std::vector<std::string>* warnings) {
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
    warnings->push_back(who + "parameters of ArduPilot's correction changed during the log (" +
                        changed + "): the last values are used for every sample");
  }
}

}  // namespace

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

Session ArdupilotSession(const DataflashLog& log, const FlightLogSelection& selection) {
  if (selection.imu < 0) throw Error("ArdupilotSession: the IMU instance must be >= 0");
  ImuStreamInfo info;
  Session s;
  // Throws when absent, gyro-only or empty; the stream's samples are decoded once.
  s.series = DataflashStream(log, selection, &info);
  const std::string stream = info.name;
  const int instance = info.instance;
  const std::string label = stream + " of IMU instance " + std::to_string(instance);
  s.source = log.source + " " + stream + " (IMU instance " + std::to_string(instance) + ")";
  for (const auto& w : log.warnings.Describe()) s.warnings.push_back(log.source + ": " + w);
  if (s.series.size() < 2) {
    throw InputError(log.source, label,
                     EmptyWindowMessage(selection.from_s, selection.to_s,
                                        info.t_start_s, info.t_end_s));
  }
  const ArdupilotCorrection correction = ArdupilotCorrectionFor(log.params, instance);
  const std::vector<std::string> undone =
      UndoArdupilotCorrection(correction, selection.undo_correction, label + ": ", &s.series,
                              &s.firmware_left);
  s.warnings.insert(s.warnings.end(), undone.begin(), undone.end());
  WarnCorrectionChanges(log, label + ": ", &s.warnings);
  s.site = SiteFromDataflash(log);
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
  std::ifstream in(path, std::ios::binary);
  unsigned char head[2] = {0, 0};
  in.read(reinterpret_cast<char*>(head), 2);
  return in.gcount() == 2 && head[0] == detail::kDataflashHead1 &&
         head[1] == detail::kDataflashHead2;
}

RecordFilter ArdupilotSessionRecords() {
  RecordFilter filter;
  filter.keep = [](std::string_view name) {
    for (const char* exact : {"FMT", "FMTU", "UNIT", "MULT", "PARM", "ISBH", "ISBD"}) {
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

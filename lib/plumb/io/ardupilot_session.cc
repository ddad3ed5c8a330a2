// plumb/io/ardupilot_session.cc — see ardupilot_session.h.
#include "plumb/io/ardupilot_session.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include "plumb/core/error.h"
#include "plumb/io/ardupilot_params.h"

namespace plumb::io {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
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
  if (lats.empty()) return std::nullopt;
  SiteInput site;
  site.lat_deg = Median(lats);
  site.lon_deg = Median(lngs);
  site.height_m = Median(alts);
  site.source = "gps";
  return site;
}

Session ArdupilotSession(const DataflashLog& log, const ArdupilotSessionOptions& options) {
  if (options.imu < 0) throw Error("ArdupilotSession: the IMU instance must be >= 0");
  Session s;
  s.source = log.source + " (IMU instance " + std::to_string(options.imu) + ")";
  ImuSeries all = ImuFromDataflash(log, options.imu);
  for (const auto& w : log.warnings.Describe()) s.warnings.push_back(log.source + ": " + w);

  // The time window.
  ImuSeries& out = s.series;
  out.acc_unit = all.acc_unit;
  out.gyr_unit = all.gyr_unit;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const double t = all.t_s[i];
    if (options.from_s && t < *options.from_s) continue;
    if (options.to_s && t > *options.to_s) continue;
    out.t_s.push_back(t);
    out.acc.push_back(all.acc[i]);
    if (all.has_gyro()) out.gyr.push_back(all.gyr[i]);
    if (all.has_temperature()) out.temp_c.push_back(all.temp_c[i]);
  }
  if (out.size() < 2) {
    throw InputError(log.source, "IMU instance " + std::to_string(options.imu),
                     "fewer than 2 samples in the time window");
  }

  // ArduPilot's correction, undone (ardupilot_params.h has the equations).
  const std::vector<std::string> undo =
      UndoInsCorrection(log.params, options.imu, options.undo_correction,
                        "IMU instance " + std::to_string(options.imu) + ": ", &out);
  s.warnings.insert(s.warnings.end(), undo.begin(), undo.end());
  s.site = SiteFromDataflash(log);
  return s;
}

bool LooksLikeDataflash(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[2] = {0, 0};
  in.read(reinterpret_cast<char*>(head), 2);
  return in.gcount() == 2 && head[0] == 0xA3 && head[1] == 0x95;
}

}  // namespace plumb::io

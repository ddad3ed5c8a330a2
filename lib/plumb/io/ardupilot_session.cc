// plumb/io/ardupilot_session.cc — see ardupilot_session.h.
#include "plumb/io/ardupilot_session.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "plumb/core/error.h"

namespace plumb::io {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// INS parameter prefix of an instance: "INS_ACC" / "INS_ACC2" / "INS_ACC3" (kind "ACC"),
/// "INS_GYR" / "INS_GYR2" / ... (kind "GYR").
std::string Prefix(const std::string& kind, int instance) {
  return "INS_" + kind + (instance == 0 ? "" : std::to_string(instance + 1));
}

/// The triad PREFIX+SUFFIX_X/Y/Z, or nullopt when any is missing.
std::optional<Vec3> Triad(const DataflashLog& log, const std::string& name) {
  Vec3 v;
  const char* axes[3] = {"_X", "_Y", "_Z"};
  for (int i = 0; i < 3; ++i) {
    const auto it = log.params.find(name + axes[i]);
    if (it == log.params.end()) return std::nullopt;
    v[i] = it->second;
  }
  return v;
}

std::string Format(const Vec3& v) {
  std::ostringstream out;
  out << v.x() << ", " << v.y() << ", " << v.z();
  return out.str();
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

  // ArduPilot's correction, undone.
  const auto orientation = log.params.find("AHRS_ORIENTATION");
  const bool rotated = orientation != log.params.end() && orientation->second != 0.0;
  const auto offs = Triad(log, Prefix("ACC", options.imu) + "OFFS");
  const auto scal = Triad(log, Prefix("ACC", options.imu) + "SCAL");
  const auto gyr_offs = Triad(log, Prefix("GYR", options.imu) + "OFFS");
  const std::string who = "IMU instance " + std::to_string(options.imu) + ": ";
  if (!options.undo_correction) {
    s.warnings.push_back(who + "samples taken as logged (corrected by ArduPilot with INS_*)");
  } else if (rotated) {
    s.warnings.push_back(who + "AHRS_ORIENTATION = " + std::to_string(orientation->second) +
                         ": the logged samples are rotated into the vehicle frame; the INS_* "
                         "correction is not undone (samples taken as logged)");
  } else {
    if (offs && scal && (scal->array() != 0.0).all()) {
      for (auto& a : out.acc) {
        a = (a.cast<double>().cwiseQuotient(*scal) + *offs).cast<float>();
      }
      const std::string acc = Prefix("ACC", options.imu);
      s.warnings.push_back(who + "accelerometer reconstructed as logged ./ " + acc + "SCAL (" +
                           Format(*scal) + ") + " + acc + "OFFS (" + Format(*offs) + ") m/s^2");
    } else {
      s.warnings.push_back(who + "no INS accelerometer offsets/scales in the log: taken as logged");
    }
    if (gyr_offs) {
      for (auto& g : out.gyr) g = (g.cast<double>() + *gyr_offs).cast<float>();
      s.warnings.push_back(who + "gyroscope reconstructed as logged + " +
                           Prefix("GYR", options.imu) + "OFFS (" + Format(*gyr_offs) + ") rad/s");
    } else {
      s.warnings.push_back(who + "no INS gyroscope offsets in the log: taken as logged");
    }
  }
  for (int k = 1; k <= 3; ++k) {
    const auto tcal = log.params.find("INS_TCAL" + std::to_string(k) + "_ENABLE");
    if (tcal != log.params.end() && tcal->second == 1.0) {
      s.warnings.push_back("INS_TCAL" + std::to_string(k) + "_ENABLE = 1: ArduPilot's "
                           "temperature calibration is in the logged samples and not undone");
    }
  }
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

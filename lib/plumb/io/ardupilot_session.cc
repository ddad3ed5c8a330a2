// plumb/io/ardupilot_session.cc — see ardupilot_session.h.
#include "plumb/io/ardupilot_session.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/io/ardupilot_correction.h"

namespace plumb::io {
namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
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

/// "INS_ACC", "INS_ACC2", ... for kind "ACC"; "INS_GYR", ... for "GYR".
std::string Prefix(const std::string& kind, int instance) {
  return "INS_" + kind + (instance == 0 ? "" : std::to_string(instance + 1));
}

/// Step 1 of the undo: board = R_board^T logged.
void UndoRotation(const ArdupilotCorrection& c, const std::string& who, Session* s) {
  if (c.orientation == 0) return;
  const Mat3 Rt = c.R_board->transpose();
  for (auto& a : s->series.acc) a = (Rt * a.cast<double>()).cast<float>();
  for (auto& g : s->series.gyr) g = (Rt * g.cast<double>()).cast<float>();
  s->warnings.push_back(who + "AHRS_ORIENTATION = " + std::to_string(c.orientation) + " (" +
                        ArdupilotRotationName(c.orientation) +
                        ") undone: board = R^T logged, R = " + Format(*c.R_board));
}

/// Step 2: offsets and scales.
void UndoOffsets(const ArdupilotCorrection& c, const std::string& who, Session* s) {
  const std::string acc = Prefix("ACC", c.instance);
  const std::string gyr = Prefix("GYR", c.instance);
  if (c.acc_offset && c.acc_scale) {
    for (auto& a : s->series.acc) {
      a = (a.cast<double>().cwiseQuotient(*c.acc_scale) + *c.acc_offset).cast<float>();
    }
    s->warnings.push_back(who + "accelerometer reconstructed as logged ./ " + acc + "SCAL (" +
                          Format(*c.acc_scale) + ") + " + acc + "OFFS (" +
                          Format(*c.acc_offset) + ") m/s^2");
  } else {
    s->warnings.push_back(who + "no " + acc + "OFFS/" + acc +
                          "SCAL in the log: accelerometer offsets/scales not undone");
  }
  if (!s->series.has_gyro()) return;
  if (c.gyr_offset) {
    for (auto& g : s->series.gyr) g = (g.cast<double>() + *c.gyr_offset).cast<float>();
    s->warnings.push_back(who + "gyroscope reconstructed as logged + " + gyr + "OFFS (" +
                          Format(*c.gyr_offset) + ") rad/s");
  } else {
    s->warnings.push_back(who + "no " + gyr + "OFFS in the log: gyroscope offsets not undone");
  }
}

/// Step 3: the temperature calibration.
void UndoTempCal(const ArdupilotCorrection& c, const std::string& who, Session* s) {
  const std::string tcal = "INS_TCAL" + std::to_string(c.instance + 1);
  if (c.tcal_enable == 2) {
    s->warnings.push_back(who + tcal + "_ENABLE = 2 (learning): ArduPilot applied no "
                                "temperature correction, nothing to undo");
  }
  if (c.tcal_enable != 1) return;
  if (!c.tcal) {
    s->warnings.push_back(who + tcal + "_ENABLE = 1 but its TMIN/TMAX/ACC*/GYR* parameters "
                                "are not all in the log: temperature calibration not undone");
    return;
  }
  if (!s->series.has_temperature()) {
    s->warnings.push_back(who + tcal + "_ENABLE = 1 but the stream has no temperature: "
                                "temperature calibration not undone");
    return;
  }
  const ArdupilotTempCal& t = *c.tcal;
  ImuSeries& series = s->series;
  for (std::size_t i = 0; i < series.size(); ++i) {
    const double temp_c = series.temp_c[i];
    series.acc[i] += ArdupilotTcalCorrection(t, t.acc_coeff, temp_c, t.acc_cal_temp_degc)
                         .cast<float>();
    if (series.has_gyro()) {
      series.gyr[i] += ArdupilotTcalCorrection(t, t.gyr_coeff, temp_c, t.gyr_cal_temp_degc)
                           .cast<float>();
    }
  }
  s->warnings.push_back(
      who + tcal + " temperature calibration undone: sensor = corrected + P(clamp(T) - 35) - "
            "P(clamp(T_cal) - 35), P(d) = (c1 + (c2 + c3 d) d) d * 1e-6, clamp to [" +
      Format(t.t_min_degc) + ", " + Format(t.t_max_degc) + "] degC, T from the stream; "
      "accelerometer T_cal " + Format(t.acc_cal_temp_degc) + " degC, " + Format(t.acc_coeff) +
      "; gyroscope T_cal " + Format(t.gyr_cal_temp_degc) + " degC, " + Format(t.gyr_coeff));
}

/// Undoes ArduPilot's correction on s->series (see the header), saying what was done.
void UndoCorrection(const ArdupilotCorrection& c, bool undo, const std::string& who,
                    Session* s) {
  const std::string applied = c.Describe(true, s->series.has_gyro());
  if (!undo) {
    s->warnings.push_back(who + "samples taken as logged (ArduPilot applied " + applied + ")");
    return;
  }
  if (!c.R_board) {
    s->warnings.push_back(who + "AHRS_ORIENTATION = " + std::to_string(c.orientation) + " (" +
                          ArdupilotRotationName(c.orientation) +
                          ") is not a rotation plumb knows: ArduPilot's correction (" + applied +
                          ") is not undone, samples taken as logged");
    return;
  }
  UndoRotation(c, who, s);
  UndoOffsets(c, who, s);
  UndoTempCal(c, who, s);
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

Session ArdupilotSession(const DataflashLog& log, const FlightLogSelection& selection) {
  if (selection.imu < 0) throw Error("ArdupilotSession: the IMU instance must be >= 0");
  const std::optional<ImuStreamInfo> info = FindDataflashStream(log, selection);
  Session s;
  s.series = DataflashStream(log, selection);  // throws when absent, gyro-only or empty
  const std::string stream = info ? info->name : selection.stream;
  const int instance = info ? info->instance : selection.imu;
  const std::string label = stream + " of IMU instance " + std::to_string(instance);
  s.source = log.source + " " + stream + " (IMU instance " + std::to_string(instance) + ")";
  for (const auto& w : log.warnings.Describe()) s.warnings.push_back(log.source + ": " + w);
  if (s.series.size() < 2) {
    throw InputError(log.source, label, "fewer than 2 samples in the time window");
  }
  const ArdupilotCorrection correction = ArdupilotCorrectionFor(log.params, instance);
  UndoCorrection(correction, selection.undo_correction, label + ": ", &s);
  s.site = SiteFromDataflash(log);
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
  return in.gcount() == 2 && head[0] == 0xA3 && head[1] == 0x95;
}

}  // namespace plumb::io

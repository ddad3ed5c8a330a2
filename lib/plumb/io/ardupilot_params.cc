// plumb/io/ardupilot_params.cc — see ardupilot_params.h.
#include "plumb/io/ardupilot_params.h"

#include <sstream>

namespace plumb::io {
namespace {

/// The triad NAME_X/_Y/_Z, or nullopt when any is missing.
std::optional<Vec3> Triad(const std::map<std::string, double>& params, const std::string& name) {
  Vec3 v;
  const char* axes[3] = {"_X", "_Y", "_Z"};
  for (int i = 0; i < 3; ++i) {
    const auto it = params.find(name + axes[i]);
    if (it == params.end()) return std::nullopt;
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

std::string InsParamPrefix(const std::string& kind, int instance) {
  return "INS_" + kind + (instance == 0 ? "" : std::to_string(instance + 1));
}

bool InsCorrection::AccUndoable() const {
  return ahrs_orientation == 0.0 && acc_offs_m_s2 && acc_scal && (acc_scal->array() != 0.0).all();
}

bool InsCorrection::GyrUndoable() const {
  return ahrs_orientation == 0.0 && gyr_offs_rad_s.has_value();
}

InsCorrection InsCorrectionFromParams(const std::map<std::string, double>& params,
                                      int instance) {
  InsCorrection c;
  c.acc_offs_m_s2 = Triad(params, InsParamPrefix("ACC", instance) + "OFFS");
  c.acc_scal = Triad(params, InsParamPrefix("ACC", instance) + "SCAL");
  c.gyr_offs_rad_s = Triad(params, InsParamPrefix("GYR", instance) + "OFFS");
  const auto orientation = params.find("AHRS_ORIENTATION");
  if (orientation != params.end()) c.ahrs_orientation = orientation->second;
  return c;
}

std::string InsAppliedDescription(int instance) {
  const std::string acc = InsParamPrefix("ACC", instance);
  return acc + "OFFS/" + acc + "SCAL, " + InsParamPrefix("GYR", instance) + "OFFS";
}

std::vector<std::string> UndoInsCorrection(const std::map<std::string, double>& params,
                                           int instance, bool undo, const std::string& who,
                                           ImuSeries* series) {
  std::vector<std::string> lines;
  const InsCorrection c = InsCorrectionFromParams(params, instance);
  if (!undo) {
    lines.push_back(who + "samples taken as logged (corrected by ArduPilot with INS_*)");
  } else if (c.ahrs_orientation != 0.0) {
    lines.push_back(who + "AHRS_ORIENTATION = " + std::to_string(c.ahrs_orientation) +
                    ": the logged samples are rotated into the vehicle frame; the INS_* "
                    "correction is not undone (samples taken as logged)");
  } else {
    if (c.AccUndoable()) {
      for (auto& a : series->acc) {
        a = (a.cast<double>().cwiseQuotient(*c.acc_scal) + *c.acc_offs_m_s2).cast<float>();
      }
      const std::string acc = InsParamPrefix("ACC", instance);
      lines.push_back(who + "accelerometer reconstructed as logged ./ " + acc + "SCAL (" +
                      Format(*c.acc_scal) + ") + " + acc + "OFFS (" + Format(*c.acc_offs_m_s2) +
                      ") m/s^2");
    } else {
      lines.push_back(who + "no INS accelerometer offsets/scales in the log: taken as logged");
    }
    if (c.GyrUndoable()) {
      for (auto& g : series->gyr) g = (g.cast<double>() + *c.gyr_offs_rad_s).cast<float>();
      lines.push_back(who + "gyroscope reconstructed as logged + " +
                      InsParamPrefix("GYR", instance) + "OFFS (" + Format(*c.gyr_offs_rad_s) +
                      ") rad/s");
    } else {
      lines.push_back(who + "no INS gyroscope offsets in the log: taken as logged");
    }
  }
  for (int k = 1; k <= 3; ++k) {
    const auto tcal = params.find("INS_TCAL" + std::to_string(k) + "_ENABLE");
    if (tcal != params.end() && tcal->second == 1.0) {
      lines.push_back("INS_TCAL" + std::to_string(k) + "_ENABLE = 1: ArduPilot's "
                      "temperature calibration is in the logged samples and not undone");
    }
  }
  return lines;
}

}  // namespace plumb::io

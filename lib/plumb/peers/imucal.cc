#include "plumb/peers/imucal.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/core/units.h"
#include "plumb/document/json_fields.h"

namespace plumb::peers {

namespace detail = document::detail;

namespace {

using nlohmann::json;

Mat3 MatrixKey(const json& root, const std::string& path, const std::string& key) {
  return detail::Matrix3(detail::Field(root, key, path, key, "3 rows of 3 numbers"), path, key);
}

Vec3 VectorKey(const json& root, const std::string& path, const std::string& key) {
  return detail::Vector3(detail::Field(root, key, path, key, "[x, y, z]"), path, key);
}

std::string Text(const json& root, const std::string& key, const std::string& fallback) {
  return root.contains(key) && root.at(key).is_string() ? root.at(key).get<std::string>() : fallback;
}

/// SI value of one output unit; unknown units are kept as they are (1), with a note.
double OutputScale(const std::string& unit, const std::string& what, ForwardCalibration& f) {
  const double si = SiPerUnit(unit);
  if (si > 0.0) return si;
  AddNotice(f.notes, "unit_kept", what + " output unit '" + unit +
                    "' is not one plumb converts: values kept in that unit (give plumb the "
                    "same raw data without unit conversion)");
  return 1.0;
}

double CalibratedScale(const std::string& unit, const std::string& what) {
  const double si = SiPerUnit(unit);
  if (si > 0.0) return si;
  throw Error("imucal " + what + " calibrated unit '" + unit +
              "' is unknown (expected m/s^2, g, rad/s or deg/s)");
}

}  // namespace

double SiPerUnit(const std::string& unit) {
  if (unit == "m/s^2" || unit == "m/s2") return 1.0;
  if (unit == "g") return units::kStandardGravity;
  if (unit == "rad/s") return 1.0;
  if (unit == "deg/s" || unit == "dps") return units::kRadPerDeg;
  return 0.0;
}

ImucalFerraris ReadImucalJson(const std::string& path) {
  const json root = detail::ParseJsonFile(path);
  if (!root.is_object()) throw InputError(path, "", "expected imucal's calibration JSON object");
  ImucalFerraris c;
  c.cal_type = Text(root, "cal_type", "");
  if (c.cal_type != "Ferraris" && c.cal_type != "Turntable") {
    throw InputError(path, "key 'cal_type'",
                     "expected \"Ferraris\" or \"Turntable\", found '" + c.cal_type + "'");
  }
  c.acc_unit = Text(root, "acc_unit", "m/s^2");
  c.gyr_unit = Text(root, "gyr_unit", "deg/s");
  c.from_acc_unit = Text(root, "from_acc_unit", "a.u.");
  c.from_gyr_unit = Text(root, "from_gyr_unit", "a.u.");
  c.K_a = MatrixKey(root, path, "K_a");
  c.R_a = MatrixKey(root, path, "R_a");
  c.b_a = VectorKey(root, path, "b_a");
  c.K_g = MatrixKey(root, path, "K_g");
  c.R_g = MatrixKey(root, path, "R_g");
  c.K_ga = MatrixKey(root, path, "K_ga");
  c.b_g = VectorKey(root, path, "b_g");
  return c;
}

ForwardCalibration ImucalToForward(const ImucalFerraris& cal, const std::string& source,
                                   ImucalFrame frame) {
  ForwardCalibration f;
  f.peer = "imucal";
  f.sources = {source};
  const double out_a = OutputScale(cal.from_acc_unit, "accelerometer", f);
  const double out_g = OutputScale(cal.from_gyr_unit, "gyroscope", f);
  const double cal_a = CalibratedScale(cal.acc_unit, "accelerometer");
  const double cal_g = CalibratedScale(cal.gyr_unit, "gyroscope");
  // The outputs' units after conversion: SI for a unit plumb converts, else kept.
  f.acc_unit = SiPerUnit(cal.from_acc_unit) > 0.0 ? "m/s^2" : cal.from_acc_unit;
  f.gyr_unit = SiPerUnit(cal.from_gyr_unit) > 0.0 ? "rad/s" : cal.from_gyr_unit;
  const Mat3 M = (out_a / cal_a) * cal.K_a * cal.R_a;
  if (frame == ImucalFrame::kPoses) {
    if (!(M.determinant() > 0.0)) {
      throw Error("imucal's K_a R_a is singular or a reflection (determinant " +
                  std::to_string(M.determinant()) + ")");
    }
    f.accel_matrix = M;
    f.R_peer_b = Mat3::Identity();
  } else {
    f.accel_matrix = UpperTriangularFrame(M, f.R_peer_b);
  }
  f.accel_bias = out_a * cal.b_a;
  f.has_gyro = true;
  f.gyro_matrix = (out_g / cal_g) * cal.K_g * cal.R_g * f.R_peer_b;
  f.gyro_bias = out_g * cal.b_g;
  f.has_g_sensitivity = true;
  f.g_sensitivity = (out_g / cal_a) * cal.K_ga * f.R_peer_b;
  f.notes.push_back(Notice{
      "peer_form",
      "imucal applies acc_cal = R_a^-1 K_a^-1 (acc - b_a), gyr_cal = R_g^-1 K_g^-1 (gyr - K_ga "
      "acc_cal - b_g); forward form F = s_a K_a R_a R, E = s_g K_g R_g R, G = (S_g / C_a) K_ga "
      "R, S_a b_a, S_g b_g, with R = R_peer_b, S (C) the SI value of one output (calibrated) "
      "unit, s = S / C: output " + cal.from_acc_unit + ", " + cal.from_gyr_unit + " -> " +
          f.acc_unit + ", " + f.gyr_unit + " (plumb's units for data read with " +
          OptionText(Option::kGyrUnit, "deg/s") + "); calibrated " + cal.acc_unit + ", " +
          cal.gyr_unit + " -> m/s^2, rad/s",
      {Option::kGyrUnit}});
  if (frame == ImucalFrame::kPoses) {
    AddNotice(f.notes, "peer_frame", "compared in imucal's own frame, that of its six poses (R_peer_b = I): "
                      "plumb's F is full and determined, its frame also the poses'");
  } else {
    const double angle_deg =
        std::acos(std::clamp((f.R_peer_b.trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / units::kPi;
    AddNotice(f.notes, "peer_frame", "imucal's frame (its six poses) is turned by " +
                      Number(angle_deg) +
                      " deg from plumb's accelerometer-defined frame (R_peer_b)");
  }
  AddNotice(
      f.notes, "peer_convention",
      "imucal's gyroscope bias is the mean of its six static poses, Earth rate included; its "
      "turns are taken as clockwise (expected_angle -360), a right-handed rate like plumb's");
  return f;
}

}  // namespace plumb::peers

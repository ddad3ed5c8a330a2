#include "plumb/export/kalibr.h"

#include "plumb/core/number_text.h"

#include <cmath>
#include <cstdio>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/core/option_name.h"
#include "plumb/signal/allan.h"
#include "plumb/signal/axis_view.h"
#include "plumb/signal/noise_terms.h"

namespace plumb::exporter {
namespace {

constexpr double kAllanCheckTau_s = 1.0;      // N is ADEV at 1 s for white noise
constexpr double kMinSegmentForCheck_s = 3.0; // 1 s clusters need a few seconds of data
constexpr double kRandomWalkSlope = 0.4;      // log-log slope taken as the +1/2 rise
constexpr std::size_t kMaxClusterFraction = 3;  // clusters up to a third of the segment

/// The longest still segment that is not turning, or nullptr.
const StillSegment* LongestStill(const std::vector<estimation::StillSegmentFit>& still, std::size_t n) {
  const StillSegment* best = nullptr;
  for (const auto& s : still) {
    if (s.segment.spinning() || s.segment.end > n || s.segment.count() < 2) continue;
    if (!best || s.segment.count() > best->count()) best = &s.segment;
  }
  return best;
}

/// N from the whitening noise, ADEV(1 s) and the random-walk bound of one sensor.
SensorNoise Measure(const ImuSeries& series, signal::Sensor sensor, const Vec3& sigma,
                    double tau_samples, double dt_s, const StillSegment* seg,
                    std::array<bool, 3>& slope_seen) {
  slope_seen = {false, false, false};
  SensorNoise noise;
  noise.white_sample = sigma * std::sqrt(dt_s);
  noise.white_low = sigma * std::sqrt(std::max(1.0, tau_samples) * dt_s);
  noise.white = noise.white_sample.cwiseMax(noise.white_low);
  noise.walk = Vec3::Constant(kNaN);
  if (!seg) return noise;
  noise.low_from_allan = true;
  const std::size_t n = seg->count();
  bool all_resolved = true;
  for (int axis = 0; axis < 3; ++axis) {
    bool allan_at_1s = false;
    const signal::AxisView x = signal::ViewAxis(series, sensor, axis, seg->begin, seg->end);
    signal::AllanOptions options;
    const std::size_t m_max = std::max<std::size_t>(1, n / kMaxClusterFraction);
    const auto adev = signal::OverlappingAllanDeviation(x, dt_s, options);
    double bound = kNaN;
    std::size_t last = 0;
    for (std::size_t j = 0; j < adev.tau_s.size(); ++j) {
      if (adev.cluster_size[j] > m_max) break;
      const double k = adev.adev[j] * std::sqrt(3.0 / adev.tau_s[j]);
      if (!(k >= bound)) bound = k;  // NaN-initialised minimum
      last = j;
    }
    noise.walk[axis] = bound;
    // +1/2 slope over the last decade-ish of cluster times: a resolved random walk.
    bool resolved = false;
    if (last >= 5) {
      const std::size_t from = last - 5;
      const double slope = std::log(adev.adev[last] / adev.adev[from]) /
                           std::log(adev.tau_s[last] / adev.tau_s[from]);
      resolved = slope >= kRandomWalkSlope;
    }
    all_resolved = all_resolved && resolved;
    slope_seen[axis] = resolved;
    const double seg_s = static_cast<double>(n) * dt_s;
    if (seg_s >= kMinSegmentForCheck_s) {
      const std::size_t m1 = static_cast<std::size_t>(std::lround(kAllanCheckTau_s / dt_s));
      if (m1 >= 1 && m1 <= n / 2) {
        signal::AllanOptions at1;
        at1.cluster_sizes = {m1};
        const auto one = signal::OverlappingAllanDeviation(x, dt_s, at1);
        // ADEV at the rounded cluster time, scaled to exactly 1 s by the white-noise law.
        noise.white_low[axis] = one.adev[0] * std::sqrt(one.tau_s[0] / kAllanCheckTau_s);
        allan_at_1s = true;
      }
    }
    noise.low_from_allan = noise.low_from_allan && allan_at_1s;
  }
  noise.white = noise.white_sample.cwiseMax(noise.white_low);
  noise.walk_resolved = all_resolved;
  return noise;
}

/// Where the IEEE fit of the still data resolves N or K on an axis, it replaces the fallback.
/// `slope_seen`: the fallback's own +1/2 test per axis.
void UseIeeeTerms(const signal::StillNoise* noise, signal::Sensor sensor,
                  const std::array<bool, 3>& slope_seen, SensorNoise& n) {
  bool resolved = true;
  for (int axis = 0; axis < 3; ++axis) {
    const signal::AxisNoise* a = noise != nullptr ? noise->Find(sensor, axis) : nullptr;
    if (a != nullptr && a->fit.term(signal::NoiseTermKind::kWhite).resolved) {
      n.white_ieee[axis] = a->fit.term(signal::NoiseTermKind::kWhite).fitted;
      n.white[axis] = n.white_ieee[axis];
      n.white_from_ieee[axis] = true;
    }
    if (a != nullptr && a->fit.term(signal::NoiseTermKind::kRandomWalk).resolved) {
      n.walk_ieee[axis] = a->fit.term(signal::NoiseTermKind::kRandomWalk).fitted;
      n.walk[axis] = n.walk_ieee[axis];
      n.walk_from_ieee[axis] = true;
    }
    resolved = resolved && (n.walk_from_ieee[axis] || slope_seen[axis]);
  }
  n.walk_resolved = resolved;
}

/// "x, y, z", "x", ... the axes where `which` is `value`; "none" when there is none.
std::string Axes(const std::array<bool, 3>& which, bool value) {
  std::string out;
  for (int axis = 0; axis < 3; ++axis) {
    if (which[axis] == value) out += std::string(out.empty() ? "" : ", ") + "xyz"[axis];
  }
  return out.empty() ? "none" : out;
}

/// The note that says which axes' N and K came from the IEEE fit.
std::string SourceNote(const char* sensor, const SensorNoise& n) {
  return std::string(sensor) + ": N from the IEEE fit on " + Axes(n.white_from_ieee, true) +
         " (fallback on " + Axes(n.white_from_ieee, false) + "), K from the IEEE fit on " +
         Axes(n.walk_from_ieee, true) + " (fallback on " + Axes(n.walk_from_ieee, false) + ")";
}

}  // namespace

std::string RosTopicProblem(const std::string& topic) {
  if (topic.empty()) return "an empty name";
  const auto letter = [](char ch) { return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z'); };
  const auto digit = [](char ch) { return ch >= '0' && ch <= '9'; };
  for (std::size_t k = 0; k < topic.size(); ++k) {
    const char ch = topic[k];
    const bool allowed = letter(ch) || digit(ch) || ch == '_' || ch == '/' || (k == 0 && ch == '~');
    if (!allowed) {
      const unsigned code = static_cast<unsigned char>(ch);
      char what[32];
      std::snprintf(what, sizeof what, code < 32 || code > 126 ? "byte 0x%02x" : "'%c'", code);
      return std::string(what) + " at " + std::to_string(k) +
             ": a ROS name holds letters, digits, '_' and '/' only";
    }
  }
  const std::size_t start = topic.find_first_not_of("~/");
  if (start == std::string::npos || !letter(topic[start])) {
    return "a ROS name starts with a letter (after a leading '/' or '~')";
  }
  if (topic.find("//") != std::string::npos || topic.back() == '/') {
    return "an empty part between '/' separators";
  }
  return "";
}

KalibrImu KalibrNoise(const estimation::Calibration& c, const ImuSeries& series,
                      const std::vector<estimation::StillSegmentFit>& still,
                      const std::string& rostopic) {
  if (const std::string p = RosTopicProblem(rostopic); !p.empty()) {
    throw Error("the Kalibr topic is not a ROS topic name (" + p + ")");
  }
  if (c.acc_unit != "m/s^2" || (c.has_gyro && c.gyr_unit != "rad/s")) {
    throw Error("the session's samples are in " + c.acc_unit + " and " + c.gyr_unit +
                ", not m/s^2 and rad/s: Kalibr's noise densities are in SI, so plumb cannot "
                "export them; give the sensor's scale (" + OptionText(Option::kAccScale) + ", " +
                OptionText(Option::kGyrScale) + ")",
                {Option::kAccScale, Option::kGyrScale});
  }
  const double dt_s = series.median_dt_s();
  if (!(dt_s > 0)) throw Error("Kalibr export: the session has no sample interval");
  KalibrImu imu;
  imu.rostopic = rostopic;
  imu.update_rate_hz = 1.0 / dt_s;
  imu.has_gyro = c.has_gyro && series.has_gyro();
  const StillSegment* seg = LongestStill(still, series.size());
  // Kalibr refuses a random walk <= 0 (kalibr_common ConfigReader.py, ImuParameters).
  if (seg == nullptr) {
    throw Error("Kalibr export: the session has no still segment, so the bias random walks "
                "Kalibr needs (it refuses 0) cannot be measured; record the IMU still for a "
                "minute or more");
  }
  imu.longest_still_s = static_cast<double>(seg->count()) * dt_s;
  std::array<bool, 3> accel_slope{}, gyro_slope{};
  imu.accel = Measure(series, signal::Sensor::kAccel, c.noise.acc, c.noise.tau_acc, dt_s, seg,
                      accel_slope);
  if (imu.has_gyro) {
    imu.gyro = Measure(series, signal::Sensor::kGyro, c.noise.gyr, c.noise.tau_gyr, dt_s, seg,
                       gyro_slope);
  }
  AddNotice(imu.notes, "noise_model_only", "Kalibr's imu.yaml holds the noise model only: plumb's scale, "
                      "misalignment, biases and effects are not in it (Kalibr estimates its own "
                      "IMU intrinsics)");
  // The IEEE terms of the still data (every still segment that does not turn, pooled).
  std::vector<StillSegment> segments;
  for (const auto& s : still) segments.push_back(s.segment);
  std::optional<signal::StillNoise> ieee;
  try {
    ieee = signal::AnalyseStillNoise(series, segments);
  } catch (const InsufficientDataError& e) {
    AddNotice(imu.notes, "noise_terms_unresolved", std::string("no IEEE noise terms: ") + e.what());
  }
  UseIeeeTerms(ieee ? &*ieee : nullptr, signal::Sensor::kAccel, accel_slope, imu.accel);
  if (imu.has_gyro) {
    UseIeeeTerms(ieee ? &*ieee : nullptr, signal::Sensor::kGyro, gyro_slope, imu.gyro);
  }
  if (ieee) {
    AddNotice(imu.notes, "noise_terms_fitted", "IEEE noise terms fitted to the Allan deviation of " +
                        Number(ieee->still_s) + " s of still data in " +
                        std::to_string(ieee->segments.size()) + " segment(s) (plumb allan)");
    AddNotice(imu.notes, "noise_terms_source", SourceNote("accel", imu.accel));
    if (imu.has_gyro) AddNotice(imu.notes, "noise_terms_source", SourceNote("gyro", imu.gyro));
  }
  const bool resolved = imu.accel.walk_resolved && (!imu.has_gyro || imu.gyro.walk_resolved);
  if (!resolved) {
    AddNotice(imu.notes, "walk_upper_bound", "random walks not resolved by the IEEE fit are upper bounds (min over t "
                        "of ADEV(t) sqrt(3/t)): the longest still segment (" +
                        Number(imu.longest_still_s) + " s) is too short to show the +1/2 slope");
  }
  return imu;
}

namespace {

/// `v` as a YAML float that Kalibr's reader (PyYAML safe_load, YAML 1.1) reads as a number:
/// 6 significant digits with a '.' always, "5.0e-05" rather than "5e-05" (YAML 1.1 reads a
/// float without a '.' as a string, and Kalibr's check `value <= 0.0` then fails).
std::string YamlFloat(double v) {
  if (!std::isfinite(v)) throw Error("Kalibr export: a value is not finite (" + Number(v) + ")");
  std::string text = FormattedText("%.6g", v == 0.0 ? 0.0 : v);
  if (text.find('.') == std::string::npos) {
    const std::size_t e = text.find('e');
    text.insert(e == std::string::npos ? text.size() : e, ".0");
  }
  return text;
}

/// Kalibr's keys of one IMU, each line led by `indent`.
std::string KalibrImuKeys(const KalibrImu& imu, const std::string& indent) {
  const bool bound = !(imu.accel.walk_resolved && (!imu.has_gyro || imu.gyro.walk_resolved));
  const std::string walk_comment = bound ? "  # upper bound from a short session" : "";
  std::string text = indent + "rostopic: " + imu.rostopic + "\n";
  text += indent + "update_rate: " + YamlFloat(imu.update_rate_hz) + "  # Hz\n";
  // Where the written (largest) value came from.
  const auto origin = [](const Vec3& v, const std::array<bool, 3>& ieee) {
    Eigen::Index axis = 0;
    v.maxCoeff(&axis);
    return std::string(ieee[axis] ? ", N of the IEEE noise fit" : "");
  };
  text += indent + "accelerometer_noise_density: " + YamlFloat(imu.accelerometer_noise_density()) +
          "  # m/s^2/sqrt(Hz)" + origin(imu.accel.white, imu.accel.white_from_ieee) + "\n";
  text += indent + "accelerometer_random_walk: " + YamlFloat(imu.accelerometer_random_walk()) +
          "  # m/s^3/sqrt(Hz)" + walk_comment + "\n";
  if (imu.has_gyro) {
    text += indent + "gyroscope_noise_density: " + YamlFloat(imu.gyroscope_noise_density()) +
            "  # rad/s/sqrt(Hz)" + origin(imu.gyro.white, imu.gyro.white_from_ieee) + "\n";
    text += indent + "gyroscope_random_walk: " + YamlFloat(imu.gyroscope_random_walk()) +
            "  # rad/s^2/sqrt(Hz)" + walk_comment + "\n";
  }
  return text;
}

}  // namespace

std::string KalibrYaml(const KalibrImu& imu) {
  std::string text = "# Kalibr IMU noise model from plumb (white noise densities and bias random "
                     "walks of the session)\n";
  for (const Notice& note : imu.notes) text += "# " + note.message + "\n";
  return text + KalibrImuKeys(imu, "");
}

std::string KalibrImuSetYaml(const std::vector<KalibrBoardImu>& imus) {
  std::string text = "# Kalibr IMU set from plumb: imu0 defines the body frame; each IMU's "
                     "noise model, T_i_b (body to IMU) and time_offset (s, added to its stamps)\n";
  for (std::size_t k = 0; k < imus.size(); ++k) {
    for (const Notice& note : imus[k].noise.notes) {
      text += "# imu" + std::to_string(k) + ": " + note.message + "\n";
    }
  }
  for (std::size_t k = 0; k < imus.size(); ++k) {
    const KalibrBoardImu& imu = imus[k];
    // T_i_b maps body coordinates into the IMU's: rotation R_b_i^T, and the body origin
    // (IMU 0) seen from the IMU, -R_b_i^T r.
    const Mat3 C_i_b = imu.R_b_i.toRotationMatrix().transpose();
    const Vec3 t = -C_i_b * imu.lever_arm_m;
    text += "imu" + std::to_string(k) + ":\n  T_i_b:\n";
    // 17 significant digits (a double round-trips), and no "-0".
    const auto entry = [](double v) { return FormattedText("%.17g", v == 0.0 ? 0.0 : v); };
    for (int r = 0; r < 3; ++r) {
      text += "    - [" + entry(C_i_b(r, 0)) + ", " + entry(C_i_b(r, 1)) + ", " +
              entry(C_i_b(r, 2)) + ", " + entry(t(r)) + "]\n";
    }
    text += "    - [0, 0, 0, 1]\n";
    text += "  time_offset: " + YamlFloat(imu.time_offset_s) + "  # s\n";
    text += KalibrImuKeys(imu.noise, "  ");
  }
  return text;
}

}  // namespace plumb::exporter

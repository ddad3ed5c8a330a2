// plumb/export/kalibr.h — the session's noise as Kalibr's imu.yaml.
//
// Kalibr's imu.yaml carries the noise model only (ethz-asl/kalibr wiki "IMU Noise Model"):
//   accelerometer_noise_density  N_a, m/s^2/sqrt(Hz)   (white noise, continuous time)
//   accelerometer_random_walk    K_a, m/s^3/sqrt(Hz)   (bias random walk)
//   gyroscope_noise_density      N_g, rad/s/sqrt(Hz)
//   gyroscope_random_walk        K_g, rad/s^2/sqrt(Hz)
//   rostopic, update_rate (Hz)
// It has no place for scale, misalignment, biases or any plumb effect: Kalibr estimates its
// own IMU intrinsics (its scale-misalignment models) in the camera-IMU calibration.
//
// From the session, per axis:
// - N and K are the IEEE terms fitted to the overlapping Allan deviation of the still data
//   (signal/noise_terms.h: every still segment that does not turn, pooled) where the fit
//   resolves them. That needs a still record that shows each term's slope: N (-1/2) nearly
//   always, K (+1/2) only in long still data (several minutes). Axes where a term is not
//   resolved keep the fallback below, and the notes, the report lines and the JSON say which
//   axis came from where.
// - Fallback N, from two measurements, the larger written (an understated noise misleads a
//   filter more than an overstated one):
//   * the per-sample noise sigma (the still-segment scatter plumb whitened with):
//     N_sample = sigma sqrt(dt), Kalibr's own conversion between its continuous density and
//     the discrete per-sample sigma (sigma_d = N / sqrt(dt));
//   * the low-frequency level: the Allan deviation of the longest still segment at 1 s
//     (white noise: ADEV(t) = N / sqrt(t)) when that segment lasts at least 3 s, otherwise
//     sigma sqrt(tau dt) with tau plumb's integrated autocorrelation time (samples): the
//     density near zero frequency of a (possibly low-pass filtered) output.
// - Fallback K: a random walk adds K^2 t / 3 to the Allan variance, so every cluster time t bounds
//   K <= ADEV(t) sqrt(3 / t); the smallest bound over t (up to a third of the longest still
//   segment) is written. It is an estimate only when the Allan deviation rises with slope
//   close to +1/2 at the longest times; otherwise (short still segments, the usual case) it is
//   an upper bound and marked so.
// Kalibr takes one value per sensor: the largest over the three axes.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"
#include "plumb/export/firmware.h"

namespace plumb::exporter {

struct SensorNoise {
  /// N per axis, unit/sqrt(Hz): white_ieee where white_from_ieee, else the larger of
  /// white_sample and white_low.
  Vec3 white = Vec3::Zero();
  Vec3 white_ieee = Vec3::Constant(kNaN);  ///< N of the IEEE fit, NaN where not resolved
  std::array<bool, 3> white_from_ieee{};   ///< the axis's N is the IEEE fit's
  Vec3 white_sample = Vec3::Zero();  ///< sigma sqrt(dt) per axis, unit/sqrt(Hz)
  /// Low-frequency level per axis: ADEV(1 s), or sigma sqrt(tau dt) when not measurable.
  Vec3 white_low = Vec3::Zero();
  bool low_from_allan = false;       ///< white_low is ADEV(1 s) (on every axis)
  /// K per axis, unit/s/sqrt(Hz): walk_ieee where walk_from_ieee, else the fallback (estimate
  /// or upper bound).
  Vec3 walk = Vec3::Zero();
  Vec3 walk_ieee = Vec3::Constant(kNaN);  ///< K of the IEEE fit, NaN where not resolved
  std::array<bool, 3> walk_from_ieee{};   ///< the axis's K is the IEEE fit's
  /// true: every axis's K is resolved (the IEEE fit's, or the fallback's +1/2 slope seen)
  bool walk_resolved = false;
};

struct KalibrImu {
  std::string rostopic = "/imu0";  ///< ROS topic of the IMU messages
  double update_rate_hz = 0;       ///< 1 / median sample interval, Hz
  SensorNoise accel, gyro;
  bool has_gyro = false;
  double longest_still_s = 0;      ///< length of the segment the Allan deviation used, s
  std::vector<Notice> notes;  ///< what the file cannot carry and how K was found (codes: export.h)

  double accelerometer_noise_density() const { return accel.white.maxCoeff(); }
  double accelerometer_random_walk() const { return accel.walk.maxCoeff(); }
  double gyroscope_noise_density() const { return gyro.white.maxCoeff(); }
  double gyroscope_random_walk() const { return gyro.walk.maxCoeff(); }
};

/// Why `topic` is not a ROS topic name ("" when it is): ROS names are letters, digits, '_'
/// and '/' separators, starting with a letter, '/' or '~' ("/imu0", "~imu", "vio/imu"), with
/// no empty part. What reaches the YAML file is checked, so no text can add keys to it.
std::string RosTopicProblem(const std::string& topic);

/// The noise of the session (file comment): the IEEE terms of the still segments `still`
/// where resolved, otherwise the calibration's noise levels checked with the Allan deviation
/// of the longest still segment that is not turning. Throws plumb::Error when `rostopic` is
/// not a ROS topic name (RosTopicProblem), the outputs are not in SI, the series has fewer
/// than two samples or no still segment (Kalibr refuses a random walk of 0).
KalibrImu KalibrNoise(const estimation::Calibration& calibration, const ImuSeries& series,
                      const std::vector<estimation::StillSegmentFit>& still,
                      const std::string& rostopic);

/// Kalibr's imu.yaml text (comments say which values are upper bounds). Every number has a '.'
/// ("5.0e-05"), as Kalibr's reader (PyYAML, YAML 1.1) needs to read it as a float.
std::string KalibrYaml(const KalibrImu& imu);

/// One IMU of a board for Kalibr's IMU set: its noise, and where it sits in the body (IMU 0's
/// accelerometer frame; SPEC 6): R_b_i its frame into the body, its lever arm from IMU 0 (m,
/// body frame) and its time offset (s, added to its stamps).
struct KalibrBoardImu {
  KalibrImu noise;
  Quat R_b_i = Quat::Identity();
  Vec3 lever_arm_m = Vec3::Zero();
  double time_offset_s = 0.0;
};

/// Kalibr's multi-IMU yaml (kalibr_common ImuSetParameters, as kalibr_calibrate_imu_camera
/// writes it for several IMUs): keys imu0, imu1, ... in `imus` order, each with T_i_b (4x4,
/// body to IMU: its rotation C_i_b = R_b_i^T and translation -C_i_b r, as Kalibr's
/// IccImu.getTransformationFromBodyToImu), time_offset (Kalibr adds it to the IMU's stamps, as
/// plumb's) and the noise keys of KalibrYaml; the notes as comments, per IMU.
std::string KalibrImuSetYaml(const std::vector<KalibrBoardImu>& imus);

}  // namespace plumb::exporter

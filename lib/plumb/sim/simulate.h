// plumb/sim/simulate.h — synthetic IMU sessions with a chosen error model and known truth.
//
// For every sample time t_k = t0_s + k / rate_hz (k = 0 .. N-1, covering the schedule's
// duration) the simulator
//   1. takes the body motion from the schedule (attitude R_n_b, rate omega_nb_b, angular
//      acceleration alpha_nb_b, all analytic);
//   2. forms the true inputs of the error model (SPEC section 1), at a site with gravity g_n and
//      Earth rate omega_ie_n (both from plumb::geo::Site; no translation, so a_n = 0):
//        f_b     = R_n_b^T (a_n - g_n) = -R_n_b^T g_n          (still and level: (0, 0, -g))
//        omega_b = R_n_b^T omega_ie_n + omega_nb_b
//        alpha_b = alpha_nb_b - omega_nb_b x (R_n_b^T omega_ie_n)   (d omega_b / dt)
//        dt_s    = t - model.t_ref_s,  dtemp_c = T(t) - model.temp_ref_c
//   3. predicts the outputs with the true model and parameters (plumb::model::Model::Predict);
//   4. adds a bias random walk and white noise, quantises, and stores the sample in float.
//
// Noise: white-noise densities give a per-sample sigma of density * sqrt(rate_hz); the bias
// random walk takes a step of sigma density / sqrt(rate_hz) after every sample, starting from
// zero. One std::mt19937_64 seeded with `seed` draws 12 normals per sample in a fixed order
// (accelerometer white, gyroscope white, accelerometer walk, gyroscope walk) whether or not a
// density is zero, so the same options give the same session bit for bit.
#pragma once


#include <cstddef>
#include <cstdint>
#include <vector>

#include "plumb/core/segment.h"
#include "plumb/core/session.h"
#include "plumb/core/types.h"
#include "plumb/core/typical_mems.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"
#include "plumb/sim/schedule.h"

namespace plumb::sim {

/// Sensor temperature over the session.
struct TemperatureProfile {
  enum class Kind {
    kConstant,  ///< start_c throughout
    kRamp,      ///< linear from start_c at the first sample to end_c at the schedule's end
    kUpDown,    ///< triangle wave: start_c -> end_c -> start_c, once per period_s
  };
  Kind kind = Kind::kConstant;
  double start_c = 25.0;    ///< temperature at the session start, degC, finite
  double end_c = 25.0;      ///< kRamp: at the end; kUpDown: the turning value; degC, finite
  double period_s = 600.0;  ///< kUpDown: length of one up-and-down cycle, s, > 0

  static TemperatureProfile Constant(double temp_c);
  static TemperatureProfile Ramp(double start_c, double end_c);
  static TemperatureProfile UpDown(double start_c, double end_c, double period_s);

  /// Temperature t_s seconds after the session start for a session of duration_s, degC.
  double At(double t_s, double duration_s) const;
  /// Throws plumb::Error if a field is out of range.
  void Validate() const;
};

/// Turns made by hand rather than on a turntable (all zero: a turntable's, the default).
/// During every turn the IMU is also carried by a smooth displacement of hand_translation_m
/// along a direction drawn per turn (zero velocity and acceleration at both ends, the turn's
/// own profile: it adds a_n = L (2 pi / T^2) sin(2 pi u) d_n to the specific force), and
/// shaken: vibration above the Nyquist frequency folds into the accelerometer's samples as a
/// broadband scatter, per sample per axis sigma hand_vibration_accel (m/s^2) times a scale
/// drawn per turn in [0.25, 1] times sin^2(pi u) (strongest mid-turn). A hand's rotation
/// vibration is left out: on the real hand-held sessions the turns' rotation residuals sit
/// at the gyroscope's white noise (estimation/turn_noise.h). These draws come from a second
/// generator (seeded from `seed`), only when an amplitude is set, so sessions without them
/// keep their noise bit for bit.
struct HandHeldTurns {
  double translation_m = 0.0;   ///< displacement over each turn, m, >= 0
  double vibration_accel = 0.0; ///< vibration's per-sample sigma at its peak, m/s^2, >= 0
  bool on() const { return translation_m > 0.0 || vibration_accel > 0.0; }
};

/// Another IMU of the simulated board (SPEC 6, "Several IMUs of one board"). It is sampled on
/// IMU 0's stamps, with the noise levels of SimulationOptions drawn from its own generator, and
/// sees the motion at its own place and in its own frame:
///   f_i     = R_b_i^T (f_b + alpha_b x r + omega_b x (omega_b x r))   (r = lever_arm_m)
///   omega_i = R_b_i^T omega_b,  alpha_i = R_b_i^T alpha_b
/// at the instant t + time_offset_s of its sample stamped t. A hand's translation (HandHeldTurns)
/// moves the whole board, taken at IMU 0's instant; its vibration is drawn per IMU.
struct BoardImuTruth {
  Quat R_b_i = Quat::Identity();    ///< its frame into the body frame (IMU 0's accelerometer's)
  Vec3 lever_arm_m = Vec3::Zero();  ///< where it sits, body frame, m, from IMU 0
  /// Added to its stamps, the true time of its samples, s: its sample stamped t measured the
  /// motion at t + time_offset_s; finite, |offset| <= 1 s.
  double time_offset_s = 0.0;
  /// Its true error model and parameter blocks (empty: the ideal IMU); the model's t_ref_s is
  /// replaced by t0_s, as IMU 0's.
  model::Model model = model::Model::Parse("base");
  model::ParameterBlocks truth;
};

/// Everything the simulator needs besides the schedule.
struct SimulationOptions {
  /// Sample rate, Hz, in (0, 100000].
  double rate_hz = 400.0;
  /// The true error model. Its t_ref_s is replaced by t0_s (the first sample's time: the drift
  /// terms are zero at the session start); its temp_ref_c (degC) is used as given.
  model::Model model = model::Model::Parse("base");
  /// True parameter blocks, one per model term (model.ZeroParameters() layout). Empty = all
  /// zero, the ideal IMU. Use SetParameter / RandomParameters (sim/truth.h) to fill them.
  model::ParameterBlocks truth;
  /// Where the IMU is: gravity g_n and Earth rate omega_ie_n. Site::Unknown() (the default)
  /// has standard gravity and no Earth rate; use Site::At(lat, lon, height, ...) for a real one.
  geo::Site site = geo::Site::Unknown();
  /// White-noise densities: accelerometer m/s^2/sqrt(Hz), gyroscope rad/s/sqrt(Hz); >= 0.
  /// Per-sample sigma = density * sqrt(rate_hz).
  double accel_noise_density = 0.0;
  double gyro_noise_density = 0.0;
  /// Bias random-walk densities: accelerometer m/s^3/sqrt(Hz), gyroscope rad/s^2/sqrt(Hz);
  /// >= 0. The bias moves by a step of sigma density / sqrt(rate_hz) per sample.
  double accel_bias_walk_density = 0.0;
  double gyro_bias_walk_density = 0.0;
  /// Bias instability, the usual inertial-navigation model of it: per axis a first-order
  /// Gauss-Markov process of steady-state sigma accel m/s^2, gyro rad/s (>= 0) and
  /// correlation time bias_instability_time_s (> 0). Its Allan deviation peaks at
  /// 0.618 sigma near 1.89 tau, so IEEE Std 952's B (peak / 0.664) is 0.93 sigma. The
  /// process starts at zero at t0_s, like the walk: the truth's bias is the bias at the start.
  double accel_bias_instability = 0.0;
  double gyro_bias_instability = 0.0;
  double bias_instability_time_s = typical_mems::kInstabilityTime_s;
  /// Quantisation steps of the outputs: accelerometer m/s^2, gyroscope rad/s; >= 0, 0 = none.
  double accel_quantum = 0.0;
  double gyro_quantum = 0.0;
  /// The turns made by hand: translation and vibration (none by default).
  HandHeldTurns hand;
  /// Sensor temperature, degC (fed to the model as dtemp_c = T - model.temp_ref_c).
  TemperatureProfile temperature;
  /// Whether the session's series carries the temperature column.
  bool record_temperature = true;
  /// Time of the first sample, s (any origin, finite).
  double t0_s = 0.0;
  /// Seed of the std::mt19937_64 that draws the noise.
  std::uint64_t seed = 1;
  /// The board's other IMUs, IMU 1, 2, ... (none by default: one IMU).
  std::vector<BoardImuTruth> board;

  /// Noise of a typical consumer MEMS IMU on a small UAV (ICM-20602/42688 class):
  /// accelerometer white 1e-3 m/s^2/sqrt(Hz) (100 ug/sqrt(Hz)), gyroscope 7e-5 rad/s/sqrt(Hz)
  /// (0.004 deg/s/sqrt(Hz)); bias instability (Gauss-Markov sigma) 4e-4 m/s^2 (40 ug) and
  /// 2e-5 rad/s (4 deg/h), correlation time 30 s;
  /// bias walks 1e-4 m/s^3/sqrt(Hz) and 2e-6 rad/s^2/sqrt(Hz); the board warming from 25 to
  /// 35 degC over the session (a ramp; it moves the outputs only through the true model's
  /// temperature effects); no quantisation. Other fields keep their defaults.
  static SimulationOptions TypicalMems();
  /// The same without bias instability, walk or temperature change: white noise only.
  static SimulationOptions WhiteMems();
};

/// Truth of one still step.
struct StillTruth {
  std::size_t step = 0;               ///< index of the step in the schedule
  Quat R_n_b = Quat::Identity();      ///< true attitude, body to NED
  Vec3 f_b = Vec3::Zero();            ///< true specific force, body frame, m/s^2
  Vec3 omega_b = Vec3::Zero();        ///< true angular rate (Earth rate), body frame, rad/s
  /// Mean over the segment of the bias's wander from its value at t0 (random walk plus
  /// instability), m/s^2 and rad/s.
  Vec3 accel_bias_walk = Vec3::Zero();
  Vec3 gyro_bias_walk = Vec3::Zero();
  double mean_temp_c = 0.0;           ///< mean temperature over the segment, degC
};

/// A simulated session and its truth.
struct Simulation {
  /// The native samples (time_s from t0_s, acc, gyr unless the model has no gyroscope, temp_c
  /// if recorded), source "simulated ...", site set when options.site.known; the board's other
  /// IMUs in other_imus (instance k, name "imu<k>"), each with the gyroscope when its model has
  /// one and the temperature when IMU 0 has it. given_segments is
  /// empty (so segmentation is exercised); copy truth_segments into it to skip detection.
  Session session;
  /// The still steps as sample ranges [begin, end) (samples whose time lies in the step),
  /// labelled, with known_R_n_b set to the true attitude. Steps shorter than one sample are
  /// left out.
  std::vector<StillSegment> truth_segments;
  /// True attitude of every entry of truth_segments (same order).
  std::vector<Quat> true_R_n_b;
  /// Further truth of every entry of truth_segments (same order).
  std::vector<StillTruth> still_truth;
  /// The true model as used (t_ref_s = t0_s) and its parameter blocks.
  model::Model model;
  model::ParameterBlocks truth;
  /// The board's other IMUs as simulated (their models' t_ref_s = t0_s, their blocks filled).
  std::vector<BoardImuTruth> board;
  /// The site, schedule and temperature profile used.
  geo::Site site;
  Schedule schedule;
  TemperatureProfile temperature;
  double t0_s = 0.0;       ///< time of the first sample, s
  double rate_hz = 0.0;    ///< sample rate, Hz
  double accel_sigma = 0.0;  ///< per-sample white-noise sigma, m/s^2
  double gyro_sigma = 0.0;   ///< per-sample white-noise sigma, rad/s
};

/// Simulates `schedule` under `options`. Throws plumb::Error if the schedule is empty, an
/// option is out of range (named), the truth blocks do not match the model (the effect and
/// the expected size named), or the session would exceed 200 million samples.
Simulation Simulate(const Schedule& schedule, const SimulationOptions& options);

/// The true inputs of the error model at session time t_s (same origin as the samples),
/// without noise: what Simulate fed to Model::Predict for a sample at t_s (without a hand's
/// translation, SimulationOptions::hand).
model::SensorInput<double> TrueInput(const Simulation& sim, double t_s);

}  // namespace plumb::sim

#include "plumb/sim/simulate.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "plumb/core/error.h"
#include "plumb/core/typical_mems.h"
#include "plumb/core/units.h"

namespace plumb::sim {
namespace {

constexpr double kMaxRateHz = 100000.0;
constexpr double kMaxSamples = 200e6;
/// Tolerance, in samples, when placing step boundaries on the sample grid.
constexpr double kGridTolerance = 1e-6;

void CheckNonNegative(double value, const char* name) {
  if (!std::isfinite(value) || value < 0.0) {
    throw Error(std::string("simulation option ") + name + " = " + Number(value) +
                " must be finite and >= 0");
  }
}

void ValidateOptions(const SimulationOptions& o) {
  if (!std::isfinite(o.rate_hz) || o.rate_hz <= 0.0 || o.rate_hz > kMaxRateHz) {
    throw Error("simulation option rate_hz = " + Number(o.rate_hz) +
                " must be in (0, 100000] Hz");
  }
  CheckNonNegative(o.accel_noise_density, "accel_noise_density (m/s^2/sqrt(Hz))");
  CheckNonNegative(o.gyro_noise_density, "gyro_noise_density (rad/s/sqrt(Hz))");
  CheckNonNegative(o.accel_bias_walk_density, "accel_bias_walk_density (m/s^3/sqrt(Hz))");
  CheckNonNegative(o.gyro_bias_walk_density, "gyro_bias_walk_density (rad/s^2/sqrt(Hz))");
  CheckNonNegative(o.accel_bias_instability, "accel_bias_instability (m/s^2)");
  CheckNonNegative(o.gyro_bias_instability, "gyro_bias_instability (rad/s)");
  if (!(std::isfinite(o.bias_instability_time_s) && o.bias_instability_time_s > 0.0)) {
    throw Error("simulation option bias_instability_time_s = " +
                Number(o.bias_instability_time_s) + " must be finite and > 0 (s)");
  }
  CheckNonNegative(o.hand.translation_m, "hand.translation_m (m)");
  CheckNonNegative(o.hand.vibration_accel, "hand.vibration_accel (m/s^2)");
  CheckNonNegative(o.accel_quantum, "accel_quantum (m/s^2)");
  CheckNonNegative(o.gyro_quantum, "gyro_quantum (rad/s)");
  if (!std::isfinite(o.t0_s)) throw Error("simulation option t0_s must be finite");
  if (!std::isfinite(o.model.temp_ref_c)) throw Error("model temp_ref_c must be finite");
  if (!o.site.g_n.allFinite() || !o.site.omega_ie_n.allFinite()) {
    throw Error("simulation site has non-finite gravity or Earth rate");
  }
  o.temperature.Validate();
  for (std::size_t i = 0; i < o.board.size(); ++i) {
    const BoardImuTruth& b = o.board[i];
    const std::string imu = "board IMU " + std::to_string(i + 1);
    if (!b.lever_arm_m.allFinite()) throw Error("simulation option " + imu + ": lever arm not finite");
    if (!std::isfinite(b.time_offset_s) || std::abs(b.time_offset_s) > 1.0) {
      throw Error("simulation option " + imu + ": time offset " + Number(b.time_offset_s) +
                  " s must be finite and within +-1 s");
    }
    if (!b.R_b_i.coeffs().allFinite() || std::abs(b.R_b_i.norm() - 1.0) > 1e-9) {
      throw Error("simulation option " + imu + ": R_b_i is not a unit quaternion");
    }
    if (!std::isfinite(b.model.temp_ref_c)) throw Error(imu + ": model temp_ref_c must be finite");
  }
}

/// The truth blocks in the model's layout (zeros when empty); throws on a mismatch.
model::ParameterBlocks CheckedTruth(const model::Model& m, const model::ParameterBlocks& truth) {
  if (truth.empty()) return m.ZeroParameters();
  if (truth.size() != static_cast<std::size_t>(m.num_terms())) {
    throw Error("true parameters have " + std::to_string(truth.size()) + " blocks; model '" +
                m.spec() + "' has " + std::to_string(m.num_terms()) + " effects");
  }
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const auto& info = m.terms()[k].effect->info();
    if (truth[k].size() != static_cast<std::size_t>(info.size())) {
      throw Error("true parameters of '" + info.name + "' have " +
                  std::to_string(truth[k].size()) + " values; expected " +
                  std::to_string(info.size()));
    }
    for (double v : truth[k]) {
      if (!std::isfinite(v)) throw Error("true parameters of '" + info.name + "' are not finite");
    }
  }
  return truth;
}

/// Index of the first sample at or after time t_s from the start.
std::size_t FirstSampleAt(double t_s, double rate_hz) {
  return static_cast<std::size_t>(std::max(0.0, std::ceil(t_s * rate_hz - kGridTolerance)));
}

Vec3 Quantise(const Vec3& y, double quantum) {
  if (quantum <= 0.0) return y;
  return (y / quantum).array().round().matrix() * quantum;
}

/// The model inputs for a motion at a site, at time dt_s after t_ref and temperature offset,
/// with the body's acceleration a_n (NED, m/s^2).
model::SensorInput<double> InputFor(const Motion& motion, const geo::Site& site, double dt_s,
                                    double dtemp_c, const Vec3& a_n = Vec3::Zero()) {
  const Mat3 R_b_n = motion.R_n_b.toRotationMatrix().transpose();
  const Vec3 omega_ie_b = R_b_n * site.omega_ie_n;
  model::SensorInput<double> in;
  in.f_b = R_b_n * (a_n - site.g_n);
  in.omega_b = omega_ie_b + motion.omega_nb_b;
  in.alpha_b = motion.alpha_nb_b - motion.omega_nb_b.cross(omega_ie_b);
  in.dt_s = dt_s;
  in.dtemp_c = dtemp_c;
  return in;
}

/// Draws the per-sample noise in a fixed order.
struct NoiseSource {
  std::mt19937_64 rng;
  std::normal_distribution<double> normal{0.0, 1.0};
  Vec3 Draw() {
    const double x = normal(rng);
    const double y = normal(rng);
    const double z = normal(rng);
    return Vec3(x, y, z);
  }
};

using units::kPi;
using units::kTwoPi;

/// One turn's hand: the direction of its displacement (NED, unit) and its vibration's scale.
struct HandTurn {
  Vec3 d_n = Vec3::Zero();
  double vibration_scale = 0.0;
};

/// Draws the hand's motion of each turn, from its own generator.
class Hand {
 public:
  Hand(const HandHeldTurns& hand, std::uint64_t seed) : hand_(hand), noise_{std::mt19937_64(seed)} {}
  bool on() const { return hand_.on(); }
  HandTurn NextTurn() {
    HandTurn turn;
    turn.d_n = noise_.Draw().normalized();
    turn.vibration_scale = std::uniform_real_distribution<double>(0.25, 1.0)(noise_.rng);
    return turn;
  }
  /// The body's acceleration, NED, m/s^2, u = t / T into a turn of T s.
  Vec3 Acceleration(const HandTurn& turn, double u, double T) const {
    return hand_.translation_m * kTwoPi / (T * T) * std::sin(kTwoPi * u) * turn.d_n;
  }
  /// The vibration's per-sample sigma u into the turn, m/s^2.
  double VibrationSigma(const HandTurn& turn, double u) const {
    const double s = std::sin(kPi * u);
    return hand_.vibration_accel * turn.vibration_scale * s * s;
  }
  /// The vibration folded into one accelerometer sample of IMU 0, m/s^2.
  Vec3 Vibration(const HandTurn& turn, double u) { return VibrationSigma(turn, u) * noise_.Draw(); }

 private:
  HandHeldTurns hand_;
  NoiseSource noise_;
};

/// The bias instability of one sensor: per axis a first-order Gauss-Markov process,
/// propagated exactly over one sample, starting at zero.
class Instability {
 public:
  Instability(double sigma, double tau_s, double rate_hz)
      : phi_(std::exp(-1.0 / (rate_hz * tau_s))), step_(sigma * std::sqrt(1.0 - phi_ * phi_)) {}
  bool on() const { return step_ > 0.0; }
  const Vec3& value() const { return state_; }
  void Step(NoiseSource& noise) { state_ = phi_ * state_ + step_ * noise.Draw(); }

 private:
  double phi_ = 0.0, step_ = 0.0;
  Vec3 state_ = Vec3::Zero();
};

/// The noise of one IMU's outputs from its own generator: per sample white noise (accelerometer,
/// then gyroscope), then the bias walks' steps and the instabilities' (only when on), in that
/// order.
class OutputNoise {
 public:
  OutputNoise(const SimulationOptions& o, double accel_sigma, double gyro_sigma, std::uint64_t seed)
      : noise_{std::mt19937_64(seed)},
        accel_sigma_(accel_sigma),
        gyro_sigma_(gyro_sigma),
        accel_walk_step_(o.accel_bias_walk_density / std::sqrt(o.rate_hz)),
        gyro_walk_step_(o.gyro_bias_walk_density / std::sqrt(o.rate_hz)),
        accel_instability_(o.accel_bias_instability, o.bias_instability_time_s, o.rate_hz),
        gyro_instability_(o.gyro_bias_instability, o.bias_instability_time_s, o.rate_hz) {}

  /// The biases' wander at this sample (m/s^2, rad/s).
  struct Wander {
    Vec3 acc, gyr;
  };

  /// Adds this sample's white noise and the wander to `out`, advances the wander by one sample
  /// and returns the wander the sample carried.
  Wander Add(model::SensorOutput<double>& out) {
    const Vec3 accel_white = noise_.Draw();
    const Vec3 gyro_white = noise_.Draw();
    const Wander wander{accel_walk_ + accel_instability_.value(),
                        gyro_walk_ + gyro_instability_.value()};
    // (y + wander) + white, in that order: the sums of sessions simulated before.
    out.acc = out.acc + wander.acc + accel_sigma_ * accel_white;
    out.gyr = out.gyr + wander.gyr + gyro_sigma_ * gyro_white;
    accel_walk_ += accel_walk_step_ * noise_.Draw();
    gyro_walk_ += gyro_walk_step_ * noise_.Draw();
    // Drawn after the walk, and only when on: sessions without instability keep the noise
    // sequence they had before it existed.
    if (accel_instability_.on()) accel_instability_.Step(noise_);
    if (gyro_instability_.on()) gyro_instability_.Step(noise_);
    return wander;
  }

  /// A draw for the vibration of this IMU (a hand's turn).
  Vec3 Draw() { return noise_.Draw(); }

 private:
  NoiseSource noise_;
  double accel_sigma_, gyro_sigma_, accel_walk_step_, gyro_walk_step_;
  Vec3 accel_walk_ = Vec3::Zero(), gyro_walk_ = Vec3::Zero();
  Instability accel_instability_, gyro_instability_;
};

/// The inputs of the IMU at `b`'s place and in its frame, from the body's at that instant
/// (BoardImuTruth).
model::SensorInput<double> MountedInput(const model::SensorInput<double>& body,
                                        const BoardImuTruth& b) {
  const Mat3 R_i_b = b.R_b_i.toRotationMatrix().transpose();
  const Vec3& r = b.lever_arm_m;
  model::SensorInput<double> in = body;
  in.f_b = R_i_b * (body.f_b + body.alpha_b.cross(r) + body.omega_b.cross(body.omega_b.cross(r)));
  in.omega_b = R_i_b * body.omega_b;
  in.alpha_b = R_i_b * body.alpha_b;
  return in;
}

/// One board IMU while it is simulated: its truth, its noise and its samples.
struct BoardImuRun {
  const BoardImuTruth* truth;
  std::vector<const double*> theta;
  OutputNoise noise;
  ImuSeries* series;
};

}  // namespace

TemperatureProfile TemperatureProfile::Constant(double temp_c) {
  TemperatureProfile p;
  p.kind = Kind::kConstant;
  p.start_c = p.end_c = temp_c;
  return p;
}

TemperatureProfile TemperatureProfile::Ramp(double start_c, double end_c) {
  TemperatureProfile p;
  p.kind = Kind::kRamp;
  p.start_c = start_c;
  p.end_c = end_c;
  return p;
}

TemperatureProfile TemperatureProfile::UpDown(double start_c, double end_c, double period_s) {
  TemperatureProfile p;
  p.kind = Kind::kUpDown;
  p.start_c = start_c;
  p.end_c = end_c;
  p.period_s = period_s;
  return p;
}

double TemperatureProfile::At(double t_s, double duration_s) const {
  switch (kind) {
    case Kind::kConstant:
      return start_c;
    case Kind::kRamp:
      return duration_s > 0.0 ? start_c + (end_c - start_c) * std::clamp(t_s / duration_s, 0.0, 1.0)
                              : start_c;
    case Kind::kUpDown: {
      const double phase = std::fmod(std::max(t_s, 0.0), period_s) / period_s;  // [0, 1)
      const double up = phase < 0.5 ? 2.0 * phase : 2.0 * (1.0 - phase);     // 0 -> 1 -> 0
      return start_c + (end_c - start_c) * up;
    }
  }
  return start_c;
}

void TemperatureProfile::Validate() const {
  if (!std::isfinite(start_c) || !std::isfinite(end_c)) {
    throw Error("temperature profile values must be finite degC");
  }
  if (kind == Kind::kUpDown && (!std::isfinite(period_s) || period_s <= 0.0)) {
    throw Error("temperature profile period_s = " + Number(period_s) +
                " must be finite and > 0");
  }
}

SimulationOptions SimulationOptions::TypicalMems() {
  SimulationOptions o = WhiteMems();
  o.accel_bias_walk_density = typical_mems::kAccelWalk;
  o.gyro_bias_walk_density = typical_mems::kGyroWalk;
  o.accel_bias_instability = typical_mems::kAccelInstability;
  o.gyro_bias_instability = typical_mems::kGyroInstability;
  o.bias_instability_time_s = typical_mems::kInstabilityTime_s;
  o.temperature = TemperatureProfile::Ramp(25.0, 35.0);
  return o;
}

SimulationOptions SimulationOptions::WhiteMems() {
  SimulationOptions o;
  o.accel_noise_density = typical_mems::kAccelNoiseDensity;
  o.gyro_noise_density = typical_mems::kGyroNoiseDensity;
  return o;
}

model::SensorInput<double> TrueInput(const Simulation& sim, double t_s) {
  const double t_rel_s = t_s - sim.t0_s;
  return InputFor(sim.schedule.At(t_rel_s), sim.site, t_s - sim.model.t_ref_s,
                  sim.temperature.At(t_rel_s, sim.schedule.duration_s()) - sim.model.temp_ref_c);
}

namespace {

/// The board's other IMUs as simulated: models referred to t0_s, blocks checked, and their
/// series in `session` (IMU 0's columns: the gyroscope when its model has one, the temperature
/// when recorded).
std::vector<BoardImuRun> StartBoard(Simulation& sim, const SimulationOptions& options,
                                    std::size_t n) {
  for (const BoardImuTruth& b : options.board) {
    BoardImuTruth used = b;
    used.model.t_ref_s = options.t0_s;
    used.truth = CheckedTruth(used.model, b.truth);
    sim.board.push_back(std::move(used));
  }
  sim.session.other_imus.resize(sim.board.size());
  std::vector<BoardImuRun> runs;
  for (std::size_t i = 0; i < sim.board.size(); ++i) {
    BoardImu& imu = sim.session.other_imus[i];
    imu.instance = static_cast<int>(i + 1);
    imu.name = "imu" + std::to_string(i + 1);
    imu.series.reserve(n);
    // Each IMU's generator: the main seed mixed with its number (any fixed map would do).
    BoardImuRun run{&sim.board[i], {}, OutputNoise(options, sim.accel_sigma, sim.gyro_sigma,
                                                   options.seed ^ (0xD1B54A32D192ED03ULL * (i + 1))),
                    &imu.series};
    for (const auto& block : sim.board[i].truth) run.theta.push_back(block.data());
    runs.push_back(std::move(run));
  }
  return runs;
}

/// One sample of a board IMU stamped t_s: the motion at t_s + its time offset, a hand's
/// translation a_n (IMU 0's instant) and, in a hand's turn, vibration of `vibration_sigma`.
void BoardSample(BoardImuRun& run, const Simulation& sim, const SimulationOptions& options,
                 double t_s, double temp_c, const Vec3& a_n, double vibration_sigma) {
  const BoardImuTruth& b = *run.truth;
  const double t_rel_s = t_s + b.time_offset_s - options.t0_s;
  const model::SensorInput<double> body =
      InputFor(sim.schedule.At(t_rel_s), sim.site, t_s + b.time_offset_s - b.model.t_ref_s,
               temp_c - b.model.temp_ref_c, a_n);
  model::SensorOutput<double> out = b.model.Predict(run.theta.data(), MountedInput(body, b));
  if (vibration_sigma > 0.0) out.acc += vibration_sigma * run.noise.Draw();
  run.noise.Add(out);
  ImuSeries& series = *run.series;
  series.t_s.push_back(t_s);
  series.acc.push_back(Quantise(out.acc, options.accel_quantum).cast<float>());
  if (b.model.has_gyro()) series.gyr.push_back(Quantise(out.gyr, options.gyro_quantum).cast<float>());
  if (options.record_temperature) series.temp_c.push_back(static_cast<float>(temp_c));
}

}  // namespace

Simulation Simulate(const Schedule& schedule, const SimulationOptions& options) {
  if (schedule.empty()) throw Error("cannot simulate an empty schedule; add still or turn steps");
  ValidateOptions(options);
  const double rate_hz = options.rate_hz;
  const double n_real = std::ceil(schedule.duration_s() * rate_hz - kGridTolerance);
  if (n_real * static_cast<double>(1 + options.board.size()) > kMaxSamples) {
    throw Error("simulation of " + Number(schedule.duration_s()) + " s at " +
                Number(rate_hz) + " Hz of " + std::to_string(1 + options.board.size()) +
                " IMUs exceeds 200 million samples");
  }
  const std::size_t n = static_cast<std::size_t>(std::max(0.0, n_real));

  Simulation sim;
  sim.model = options.model;
  sim.model.t_ref_s = options.t0_s;
  sim.truth = CheckedTruth(sim.model, options.truth);
  sim.site = options.site;
  sim.schedule = schedule;
  sim.temperature = options.temperature;
  sim.t0_s = options.t0_s;
  sim.rate_hz = rate_hz;
  sim.accel_sigma = options.accel_noise_density * std::sqrt(rate_hz);
  sim.gyro_sigma = options.gyro_noise_density * std::sqrt(rate_hz);
  const bool gyro = sim.model.has_gyro();

  Session& session = sim.session;
  session.source = "simulated: model " + sim.model.spec() + ", seed " + std::to_string(options.seed);
  if (sim.site.known) {
    session.site = SiteInput{sim.site.lat_deg, sim.site.lon_deg, sim.site.height_m, "simulation"};
  }
  ImuSeries& series = session.series;
  series.reserve(n);
  if (!gyro) series.gyr.clear();
  if (options.record_temperature) series.temp_c.reserve(n);

  OutputNoise noise(options, sim.accel_sigma, sim.gyro_sigma, options.seed);
  std::vector<BoardImuRun> board = StartBoard(sim, options, n);
  std::vector<const double*> theta;
  for (const auto& block : sim.truth) theta.push_back(block.data());
  // The hand's generator: the main one's seed with its bits mixed (any fixed map would do).
  Hand hand(options.hand, options.seed ^ 0x9E3779B97F4A7C15ULL);

  for (std::size_t i = 0; i < schedule.size(); ++i) {
    const std::size_t begin = std::min(n, FirstSampleAt(schedule.step_start_s(i), rate_hz));
    const std::size_t end = std::min(n, FirstSampleAt(schedule.step_start_s(i + 1), rate_hz));
    StillTruth still;
    still.step = i;
    const bool by_hand = hand.on() && !schedule.is_still(i);
    const HandTurn turn = by_hand ? hand.NextTurn() : HandTurn{};
    const double turn_s = schedule.step_duration_s(i);
    for (std::size_t k = begin; k < end; ++k) {
      const double t_rel_s = static_cast<double>(k) / rate_hz;
      const double t_s = options.t0_s + t_rel_s;
      const double temp_c = sim.temperature.At(t_rel_s, schedule.duration_s());
      const double t_step_s = t_rel_s - schedule.step_start_s(i);
      const Motion motion = schedule.AtStep(i, t_step_s);
      const double u = by_hand ? std::clamp(t_step_s / turn_s, 0.0, 1.0) : 0.0;
      const Vec3 a_n = by_hand ? hand.Acceleration(turn, u, turn_s) : Vec3::Zero();
      const model::SensorInput<double> in = InputFor(motion, sim.site, t_s - sim.model.t_ref_s,
                                                     temp_c - sim.model.temp_ref_c, a_n);
      model::SensorOutput<double> out = sim.model.Predict(theta.data(), in);
      if (by_hand) out.acc += hand.Vibration(turn, u);
      const OutputNoise::Wander wander = noise.Add(out);
      series.t_s.push_back(t_s);
      series.acc.push_back(Quantise(out.acc, options.accel_quantum).cast<float>());
      if (gyro) series.gyr.push_back(Quantise(out.gyr, options.gyro_quantum).cast<float>());
      if (options.record_temperature) series.temp_c.push_back(static_cast<float>(temp_c));
      const double vibration = by_hand ? hand.VibrationSigma(turn, u) : 0.0;
      for (BoardImuRun& run : board) BoardSample(run, sim, options, t_s, temp_c, a_n, vibration);
      if (k == begin) {
        still.R_n_b = motion.R_n_b;
        still.f_b = in.f_b;
        still.omega_b = in.omega_b;
      }
      still.accel_bias_walk += wander.acc;
      still.gyro_bias_walk += wander.gyr;
      still.mean_temp_c += temp_c;
    }
    if (!schedule.is_still(i) || end == begin) continue;
    const double count = static_cast<double>(end - begin);
    still.accel_bias_walk /= count;
    still.gyro_bias_walk /= count;
    still.mean_temp_c /= count;
    StillSegment segment;
    segment.begin = begin;
    segment.end = end;
    const std::string& label = std::get<Still>(schedule.steps()[i]).label;
    segment.label = label.empty() ? "still #" + std::to_string(sim.truth_segments.size() + 1) : label;
    segment.known_R_n_b = still.R_n_b;
    sim.truth_segments.push_back(segment);
    sim.true_R_n_b.push_back(still.R_n_b);
    sim.still_truth.push_back(still);
  }
  return sim;
}

}  // namespace plumb::sim

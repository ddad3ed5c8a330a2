// plumb simulate --out FILE.csv — a synthetic session with a chosen error model and known
// truth (plumb::sim), written as native CSV; optionally the truth as JSON and the true still
// segments as a segments file, for checking a calibration against them.
#include "plumb/sim/simulate.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "fit_options.h"
#include "plumb/core/error.h"
#include "plumb/io/common/atomic_file.h"
#include "plumb/io/text/native_csv.h"
#include "plumb/model/model.h"
#include "plumb/report/json_report.h"
#include "plumb/report/version.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/truth.h"
#include "site_options.h"
#include "validators.h"

namespace plumb::cli {
namespace {

struct SimulateArgs {
  std::string out_path;                ///< --out: native CSV written here
  std::string schedule = "multipose";  ///< multipose | paper-static | paper-benchmark
  int poses = sim::kMultiPosePoses;    ///< multipose: number of still poses, 1..10000
  CLI::Option* poses_option = nullptr;
  double still_s = 0.0;  ///< length of each still hold, s, > 0
  CLI::Option* still_option = nullptr;
  double turn_s = 0.0;  ///< length of each turn, s, > 0
  CLI::Option* turn_option = nullptr;
  double rate_hz = 200.0;          ///< sample rate, Hz
  std::string model = "base";      ///< true error model spec
  std::vector<std::string> truth;  ///< PARAM=VALUE settings of the true parameters
  double random_truth = 0.0;       ///< scale of random true parameters (x typical), >= 0
  sim::SimulationOptions noise = sim::SimulationOptions::TypicalMems();
  std::string temperature = "ramp:25:35";  ///< temperature profile (the board warming up)
  bool no_temperature = false;           ///< leave the temp_c column out
  double temp_ref_c = 25.0;              ///< reference temperature of the true model, degC
  double t0_s = 0.0;                     ///< time of the first sample, s
  SiteArgs site;
  std::uint64_t seed = 1;    ///< seed of the noise, the poses and random truth
  int imus = 1;              ///< --imus: IMUs on the board (RandomBoard places IMU 1..)
  std::string truth_json;    ///< --truth-json FILE
  std::string segments_out;  ///< --segments-out FILE
};

double ParseNumber(const std::string& text, const std::string& what) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || errno != 0 || end != text.c_str() + text.size() || !std::isfinite(v)) {
    throw UsageError(what + ": '" + text + "' is not a finite number");
  }
  return v;
}

/// const:T, ramp:T0:T1, updown:T0:T1:PERIOD_S (degC, s).
sim::TemperatureProfile ParseTemperature(const std::string& spec) {
  std::vector<std::string> parts;
  std::stringstream ss(spec);
  std::string item;
  while (std::getline(ss, item, ':')) parts.push_back(item);
  const auto num = [&](std::size_t i) { return ParseNumber(parts[i], "--temperature " + spec); };
  if (parts.size() == 2 && parts[0] == "const") return sim::TemperatureProfile::Constant(num(1));
  if (parts.size() == 3 && parts[0] == "ramp") return sim::TemperatureProfile::Ramp(num(1), num(2));
  if (parts.size() == 4 && parts[0] == "updown") {
    return sim::TemperatureProfile::UpDown(num(1), num(2), num(3));
  }
  throw UsageError("--temperature must be const:T, ramp:T0:T1 or updown:T0:T1:PERIOD_S (got '" +
                   spec + "')");
}

/// The true parameters of `model` at `truth`, names prefixed with `prefix` ("imu1." for IMU 1).
nlohmann::json TrueParameters(const model::Model& model, const model::ParameterBlocks& truth,
                              const std::string& prefix) {
  const auto names = model.ParameterNames();
  const auto values = model::ReportedValues(model, truth);
  nlohmann::json params = nlohmann::json::array();
  int flat = 0;
  for (const auto& term : model.terms()) {
    const auto& info = term.effect->info();
    for (int i = 0; i < info.size(); ++i, ++flat) {
      params.push_back({{"name", prefix + names[static_cast<std::size_t>(flat)]},
                        {"value", report::Number(values[static_cast<std::size_t>(flat)])},
                        {"unit", info.parameters[static_cast<std::size_t>(i)].unit}});
    }
  }
  return params;
}

/// One IMU of the board as SPEC 6's "imus" entries describe it (IMU 0: the identity).
nlohmann::json BoardImuJson(int instance, const model::Model& model,
                            const model::ParameterBlocks& truth, const Quat& R_b_i,
                            const Vec3& lever_arm_m, double time_offset_s) {
  using nlohmann::json;
  const Mat3 R = R_b_i.toRotationMatrix();
  const Eigen::AngleAxisd v(R_b_i);
  const Vec3 vector = v.angle() * v.axis();
  auto triple = [](const Vec3& x) {
    return json::array({report::Number(x.x()), report::Number(x.y()), report::Number(x.z())});
  };
  json matrix = json::array();
  for (int r = 0; r < 3; ++r) matrix.push_back(triple(R.row(r).transpose()));
  const std::string prefix = instance == 0 ? "" : "imu" + std::to_string(instance) + ".";
  return json{{"instance", instance},
              {"model", model.spec()},
              {"parameters", TrueParameters(model, truth, prefix)},
              {"rotation", {{"matrix", matrix}, {"vector", triple(vector)}}},
              {"lever_arm", {{"value", triple(lever_arm_m)}}},
              {"time_offset", {{"value", report::Number(time_offset_s)}}}};
}

nlohmann::json TruthJson(const sim::Simulation& s, const SimulateArgs& a) {
  using nlohmann::json;
  const json params = TrueParameters(s.model, s.truth, "");
  json segments = json::array();
  for (std::size_t k = 0; k < s.truth_segments.size(); ++k) {
    const auto& seg = s.truth_segments[k];
    const Quat& q = s.true_R_n_b[k];
    segments.push_back({{"label", seg.label},
                        {"begin", seg.begin},
                        {"end", seg.end},
                        {"attitude_quaternion_wxyz",
                         {report::Number(q.w()), report::Number(q.x()), report::Number(q.y()),
                          report::Number(q.z())}}});
  }
  json site{{"lat_deg", s.site.known ? report::Number(s.site.lat_deg) : json(nullptr)},
            {"lon_deg", s.site.known ? report::Number(s.site.lon_deg) : json(nullptr)},
            {"height_m", s.site.known ? report::Number(s.site.height_m) : json(nullptr)},
            {"gravity", report::Number(s.site.gravity())},
            {"source", s.site.known ? s.site.source : std::string("none")}};
  json out{
      {"plumb_version", report::Version()},
      {"model", s.model.spec()},
      {"model_reference", {{"t_ref_s", s.model.t_ref_s}, {"temp_ref_c", s.model.temp_ref_c}}},
      {"parameters", params},
      {"segments", segments},
      {"site", site},
      {"noise",
       {{"accel_sigma", report::Number(s.accel_sigma)},
        {"gyro_sigma", report::Number(s.gyro_sigma)},
        {"accel_noise_density", a.noise.accel_noise_density},
        {"gyro_noise_density", a.noise.gyro_noise_density},
        {"accel_rw_density", a.noise.accel_bias_walk_density},
        {"gyro_rw_density", a.noise.gyro_bias_walk_density},
        {"accel_bias_instability", a.noise.accel_bias_instability},
        {"gyro_bias_instability", a.noise.gyro_bias_instability},
        {"bias_instability_time_s", a.noise.bias_instability_time_s}}},
      {"schedule", a.schedule},
      {"rate_hz", s.rate_hz},
      {"t0_s", s.t0_s},
      {"seed", a.seed}};
  if (!s.board.empty()) {
    json imus = json::array({BoardImuJson(0, s.model, s.truth, Quat::Identity(), Vec3::Zero(), 0.0)});
    for (std::size_t i = 0; i < s.board.size(); ++i) {
      const sim::BoardImuTruth& b = s.board[i];
      imus.push_back(BoardImuJson(static_cast<int>(i + 1), b.model, b.truth, b.R_b_i,
                                  b.lever_arm_m, b.time_offset_s));
    }
    out["imus"] = std::move(imus);
  }
  return out;
}

/// The true still segments as a segments file (CSV, sample indices, half-open).
std::string SegmentsCsv(const std::vector<StillSegment>& segments) {
  std::string out = "start,end,label\n";
  for (const auto& seg : segments) {
    std::string label = seg.label;
    for (char& c : label) c = (c == ',' || c == '\n') ? ';' : c;
    out += std::to_string(seg.begin) + "," + std::to_string(seg.end) + "," + label + "\n";
  }
  return out;
}

class SimulateCommand : public Command {
 public:
  explicit SimulateCommand(CLI::App& parent) {
    app_ = parent.add_subcommand("simulate",
                                 "Simulate a session of an IMU with a chosen error model and "
                                 "write it as native CSV");
    app_->footer("Example (12 poses of a random typical MEMS IMU at a known site, and its truth):\n  plumb simulate --out sim.csv --random-truth 1 --lat 51.64 --lon -1.2 --height 100 --truth-json truth.json");
    SimulateArgs& a = args_;
    app_->add_option("--out", a.out_path, "Native CSV file to write")
        ->required()
        ->type_name("FILE");
    app_->add_option("--schedule", a.schedule,
                     "What the IMU does: multipose (well-spread still poses joined by turns), "
                     "paper-static (one level, x-north hold), paper-benchmark (the seed paper's "
                     "sequence)")
        ->check(CLI::IsMember({"multipose", "paper-static", "paper-benchmark"}))
        ->capture_default_str();
    a.poses_option = app_->add_option("--poses", a.poses, "multipose: number of still poses")
                         ->check(CLI::Range(1, 10000))
                         ->capture_default_str();
    a.still_option = app_->add_option("--still", a.still_s,
                                      "Length of each still hold, s (default: multipose 5, "
                                      "paper-static 60, paper-benchmark 20)")
                         ->check(Positive);
    a.turn_option = app_->add_option("--turn", a.turn_s,
                                     "Length of each turn, s (default: multipose 2, "
                                     "paper-benchmark 3)")
                        ->check(Positive);
    app_->add_option("--rate", a.rate_hz, "Sample rate, Hz")
        ->check(CLI::Range(1e-3, 1e5))
        ->capture_default_str();
    app_->add_option("--model", a.model,
                     "True error model spec, e.g. base+gyro_g_sensitivity (see 'plumb effects')")
        ->capture_default_str();
    app_->add_option("--truth", a.truth,
                     "True parameter PARAM=VALUE in its unit (matrix diagonals near 1), e.g. "
                     "accel.bias.x=0.1 gyro_g_sensitivity.G.xy=1e-4, or of IMU k of a board "
                     "imuK.PARAM=VALUE; repeatable; others are ideal (or random with "
                     "--random-truth)");
    app_->add_option("--imus", a.imus,
                     "IMUs on the board: IMU 1.. of the same model, each rotated by 0.5-2 deg, "
                     "1-5 cm from IMU 0 and 2 ms or less off its stamps (drawn from --seed), "
                     "written as acc1_x.. columns")
        ->check(CLI::Range(1, 16))
        ->capture_default_str();
    app_->add_option("--random-truth", a.random_truth,
                     "Draw every free parameter from N(nominal, (SCALE x typical size)^2) before "
                     "--truth applies; 0 = ideal IMU")
        ->check(NonNegative)
        ->capture_default_str();
    auto* noise = app_->add_option_group("Noise", "Sensor noise (defaults: a typical MEMS IMU)");
    noise
        ->add_option("--accel-noise", a.noise.accel_noise_density,
                     "Accelerometer white-noise density, m/s^2/sqrt(Hz)")
        ->check(NonNegative)
        ->capture_default_str();
    noise
        ->add_option("--gyro-noise", a.noise.gyro_noise_density,
                     "Gyroscope white-noise density, rad/s/sqrt(Hz)")
        ->check(NonNegative)
        ->capture_default_str();
    noise
        ->add_option("--accel-rw", a.noise.accel_bias_walk_density,
                     "Accelerometer bias random-walk density, m/s^3/sqrt(Hz)")
        ->check(NonNegative)
        ->capture_default_str();
    noise
        ->add_option("--gyro-rw", a.noise.gyro_bias_walk_density,
                     "Gyroscope bias random-walk density, rad/s^2/sqrt(Hz)")
        ->check(NonNegative)
        ->capture_default_str();
    noise
        ->add_option("--accel-bi", a.noise.accel_bias_instability,
                     "Accelerometer bias instability: Gauss-Markov sigma, m/s^2")
        ->check(NonNegative)
        ->capture_default_str();
    noise
        ->add_option("--gyro-bi", a.noise.gyro_bias_instability,
                     "Gyroscope bias instability: Gauss-Markov sigma, rad/s")
        ->check(NonNegative)
        ->capture_default_str();
    noise
        ->add_option("--bi-time", a.noise.bias_instability_time_s,
                     "Correlation time of the bias instability, s")
        ->check(Positive)
        ->capture_default_str();
    noise
        ->add_option("--quantisation-acc", a.noise.accel_quantum,
                     "Accelerometer quantisation step, m/s^2 (0 = none)")
        ->check(NonNegative)
        ->capture_default_str();
    noise
        ->add_option("--quantisation-gyr", a.noise.gyro_quantum,
                     "Gyroscope quantisation step, rad/s (0 = none)")
        ->check(NonNegative)
        ->capture_default_str();
    auto* hand = app_->add_option_group(
        "Turns by hand", "Turns made by hand rather than on a turntable (default: none)");
    hand->add_option("--hand-vibration", a.noise.hand.vibration_accel,
                     "Vibration folded into the accelerometer's samples during each turn: "
                     "per-sample sigma at its peak (mid-turn), m/s^2; each turn takes 0.25-1 "
                     "times it (0 = none)")
        ->check(NonNegative)
        ->capture_default_str();
    hand->add_option("--hand-translation", a.noise.hand.translation_m,
                     "Displacement over each turn, m, in a direction drawn per turn, at rest "
                     "at both ends (0 = none)")
        ->check(NonNegative)
        ->capture_default_str();
    app_->add_option("--temperature", a.temperature,
                     "Sensor temperature profile, degC: const:T, ramp:T0:T1 (over the session) "
                     "or updown:T0:T1:PERIOD_S")
        ->capture_default_str();
    app_->add_flag("--no-temperature", a.no_temperature, "Leave the temp_c column out");
    app_->add_option("--temp-ref", a.temp_ref_c,
                     "Reference temperature of the true temperature terms, degC")
        ->check(CLI::Range(-100.0, 200.0))
        ->capture_default_str();
    app_->add_option("--t0", a.t0_s, "Time of the first sample, s")->capture_default_str();
    AddSiteOptions(app_, a.site);
    app_->add_option("--seed", a.seed, "Seed of the noise, the poses and --random-truth")
        ->capture_default_str();
    app_->add_option("--truth-json", a.truth_json,
                     "Write the true parameters, segments, site and noise as JSON to FILE")
        ->type_name("FILE");
    app_->add_option("--segments-out", a.segments_out,
                     "Write the true still segments as a segments file (start,end,label sample "
                     "indices) for 'plumb calibrate --segments'")
        ->type_name("FILE");
  }

  FileRoles Files() const override {
    FileRoles roles;
    roles.output_files.push_back({"--out", args_.out_path});
    roles.output_files.push_back({"--truth-json", args_.truth_json});
    roles.output_files.push_back({"--segments-out", args_.segments_out});
    return roles;
  }

  int Run() override {
    const SimulateArgs& a = args_;
    const sim::Schedule schedule = MakeSchedule();
    sim::SimulationOptions options = a.noise;
    options.rate_hz = a.rate_hz;
    options.model = ParseModelOption("--model", a.model);
    options.model.temp_ref_c = a.temp_ref_c;
    options.truth = a.random_truth > 0
                        ? sim::RandomParameters(options.model, a.random_truth, a.seed)
                        : options.model.ZeroParameters();
    options.board = sim::RandomBoard(a.imus, options.model, a.random_truth, a.seed);
    for (const auto& setting : a.truth) SetTruth(setting, options);
    options.temperature = ParseTemperature(a.temperature);
    options.record_temperature = !a.no_temperature;
    options.t0_s = a.t0_s;
    options.seed = a.seed;
    options.site = ResolveSite(a.site, std::nullopt, std::nullopt);

    const sim::Simulation sim = sim::Simulate(schedule, options);
    io::WriteNativeCsv(a.out_path, sim.session);
    std::cout << "wrote " << a.out_path << ": " << sim.session.series.size() << " samples, "
              << sim.session.series.duration_s() << " s at " << sim.rate_hz << " Hz, "
              << sim.truth_segments.size() << " still holds; model " << sim.model.spec()
              << "; noise per sample " << sim.accel_sigma << " m/s^2, " << sim.gyro_sigma
              << " rad/s; site " << (sim.site.known ? "given" : "none (no Earth rate)");
    if (!sim.board.empty()) std::cout << "; " << sim.board.size() + 1 << " IMUs on one board";
    std::cout << "\n";
    if (!a.truth_json.empty()) {
      report::WriteJson(a.truth_json, TruthJson(sim, a));
      std::cout << "wrote " << a.truth_json << "\n";
    }
    if (!a.segments_out.empty()) {
      io::WriteFileAtomic(a.segments_out, SegmentsCsv(sim.truth_segments));
      std::cout << "wrote " << a.segments_out << "\n";
    }
    return 0;
  }

 private:
  /// One --truth PARAM=VALUE or imuK.PARAM=VALUE into `options` (sim::SetTruth).
  static void SetTruth(const std::string& setting, sim::SimulationOptions& options) {
    const auto eq = setting.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw UsageError("--truth must be PARAM=VALUE (got '" + setting + "')");
    }
    const double value = ParseNumber(setting.substr(eq + 1), "--truth " + setting);
    try {
      sim::SetTruth(options, setting.substr(0, eq), value);
    } catch (const Error& e) {
      throw UsageError("--truth " + setting + ": " + e.what());
    }
  }

  /// The schedule the flags name (sim::NamedSchedule: its defaults for what is not given).
  sim::Schedule MakeSchedule() const {
    const SimulateArgs& a = args_;
    sim::ScheduleRequest r;
    r.kind = a.schedule;
    if (a.poses_option->count() > 0) r.poses = a.poses;
    if (a.still_option->count() > 0) r.still_s = a.still_s;
    if (a.turn_option->count() > 0) r.turn_s = a.turn_s;
    r.seed = a.seed;
    try {
      return sim::NamedSchedule(r, {"--schedule", "--poses", "--turn"});
    } catch (const Error& e) {
      throw UsageError(e.what());
    }
  }

  SimulateArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeSimulateCommand(CLI::App& parent) {
  return std::make_unique<SimulateCommand>(parent);
}

}  // namespace plumb::cli

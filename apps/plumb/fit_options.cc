// See fit_options.h.
#include "fit_options.h"
#include "commands.h"
#include "jobs.h"
#include "progress.h"

#include <cstdio>
#include <iostream>
#include <optional>

#include "plumb/core/datasheet_level.h"
#include "plumb/core/error.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/gates.h"
#include "plumb/estimation/wander_levels.h"
#include "plumb/signal/noise_terms.h"
#include "segment_options.h"
#include "validators.h"

namespace plumb::cli {

void AddModelOption(CLI::App* app, FitArgs& a, bool board) {
  app->add_option("--model", a.model,
                  "Error model spec: base, paper, or base+EFFECT[:OPTION]+... "
                  "(see 'plumb effects')")
      ->capture_default_str();
  if (board) AddImuModelOption(app, a);
}

void AddImuModelOption(CLI::App* app, FitArgs& a) {
  app->add_option("--imu-model", a.imu_models,
                  "With --imus: board IMU K's own error model (K as its parameters are "
                  "named, imuK.accel.bias.x), e.g. 2=base+gyro_g_sensitivity; repeatable; the "
                  "others take --model")
      ->type_name("K=SPEC")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

namespace {

/// A wander level as a datasheet states it (ParseDatasheetLevel), rewritten to the
/// SI number; CLI11 puts the option's name before the parser's message.
CLI::Validator DatasheetLevel(WanderLevel level) {
  return CLI::Validator(
      [level](std::string& text) -> std::string {
        double v = 0;
        try {
          v = ParseDatasheetLevel(text, level);
        } catch (const Error& e) {
          return e.what();
        }
        char number[40];
        std::snprintf(number, sizeof number, "%.17g", v);
        text = number;
        return {};
      },
      "LEVEL[UNIT]");
}

/// The bias wander (estimation/noise_model.h): by default the bias wanders (a random walk and
/// a Gauss-Markov instability) at the levels given, else from the still data or typical
/// (estimation/wander_levels.h).
void AddWanderOptions(CLI::App* app, FitArgs& a) {
  const auto level = [&](const char* name, std::optional<double>& target, const std::string& text,
                         WanderLevel units) {
    return app->add_option(name, target, text)->transform(DatasheetLevel(units));
  };
  const std::string units =
      " (sensor units for unscaled samples), or with a datasheet's unit; 0 = none. Default: "
      "from the still data's Allan deviation, else the typical MEMS ";
  CLI::Option* wander[] = {
      level("--accel-rw", a.options.accel_walk_density,
            "Accelerometer bias random walk, m/s^3/sqrt(Hz) or ug/sqrt(s), ug/sqrt(h)" + units +
                "1e-4 (or --estimate-rw)",
            WanderLevel::kAccelWalk),
      level("--gyro-rw", a.options.gyro_walk_density,
            "Gyroscope bias random walk (rate random walk), rad/s^2/sqrt(Hz) or deg/h/sqrt(h), "
            "deg/s/sqrt(s)" + units + "2e-6 (or --estimate-rw)",
            WanderLevel::kGyroWalk),
      app->add_flag("--estimate-rw", a.options.estimate_walk,
                    "Estimate the bias wander levels not given (walk and instability) from the "
                    "session: variance components over the wander factors, marginalised over "
                    "the estimate's own scatter; 6 or more still poses. The differences between "
                    "poses it reads as wander also carry any effect the model misses: check "
                    "with 'plumb diagnose' first"),
      level("--accel-bi", a.options.accel_instability,
            "Accelerometer bias instability as a Gauss-Markov process: its sigma, m/s^2 or ug, "
            "mg" + units + "4e-4",
            WanderLevel::kAccelInstability),
      level("--gyro-bi", a.options.gyro_instability,
            "Gyroscope bias instability as a Gauss-Markov process: its sigma, rad/s or deg/h, "
            "deg/s" + units + "2e-5",
            WanderLevel::kGyroInstability),
      app->add_option("--bi-time", a.options.instability_time_s, "Correlation time of the bias instability, s")
          ->check(CLI::Range(1e-3, 1e9))
          ->capture_default_str(),
      app->add_option("--noise-from", a.noise_from,
                      "A still recording of the same sensor (read with the same input options), "
                      "e.g. several minutes on the bench: its Allan deviation informs the bias "
                      "wander levels not given, beside the session's own still data")
          ->type_name("FILE")};
  auto* constant = app->add_flag(
      "--constant-bias", a.options.constant_bias,
      "One constant bias over the session: no random walk, no instability (the sigma is then "
      "honest only for white noise; for comparisons with peers that assume it)");
  for (auto* o : wander) constant->excludes(o);
}

}  // namespace

void AddFitOptions(CLI::App* app, FitArgs& a) {
  app->add_flag_callback(
      "--white-turns", [&a] { a.options.turn_vibration = false; },
      "Weight the turns' velocity residuals (used by time_offset and accel_size_effect) by the "
      "white noise alone, not by the vibration measured in each turn: to see what the "
      "vibration does (on turns made by hand it understates their sigma)");
  app->add_flag("--strict", a.strict,
                "Fail (exit 1) when the data cannot determine every parameter of the model, "
                "instead of reporting the unobservable directions, and (exit 3, nothing "
                "written) when the fit fails a gate: not converged, segments of one pose, "
                "samples out of range, a unit or rate the data contradict, a saturated axis");
  a.heading = app->add_option("--heading", a.heading_deg,
                              "Heading of the first still pose's x axis from north, degrees "
                              "(0 = x north); otherwise the heading is an arbitrary gauge")
                ->check(CLI::Range(-360.0, 360.0));
  auto* level = app->add_flag("--level-north", a.level_north,
                              "The first still pose is level with x north (the paper's pose): "
                              "its attitude is known and held");
  level->excludes(a.heading);
  app->add_option("--temp-ref", a.temp_ref_c,
                  "Reference temperature of the temperature terms, degC")
      ->check(CLI::Range(-100.0, 200.0))
      ->capture_default_str();
  app->add_option("--max-iterations", a.options.max_iterations,
                  "Iteration limit of each solve; a fit that reaches it has not converged "
                  "(the gate not_converged)")
      ->check(Positive)
      ->capture_default_str();
  AddWanderOptions(app, a);
}

namespace {

/// The noise of the still recording `path` (--noise-from), read like the session.
signal::StillNoise StillNoiseFrom(const std::string& path, const InputArgs& input,
                                  double instability_time_s) {
  InputArgs other = input;
  other.inputs = {path};
  other.acc_file.clear();
  other.gyr_file.clear();
  const Session still = ReadInputs(other);
  const segmentation::SegmentationResult seg = FindSegments(still.series, SegmentArgs{});
  try {
    return signal::AnalyseStillNoise(still.series, seg.segments,
                                     estimation::WanderNoiseOptions(instability_time_s),
                                     ParallelJobs(0));
  } catch (const InsufficientDataError& e) {
    throw InsufficientDataError("--noise-from " + path + ": " + e.what());
  }
}

}  // namespace

model::Model ParseModelOption(const std::string& option, const std::string& spec) {
  try {
    return model::Model::Parse(spec);
  } catch (const Error& e) {
    throw UsageError(option + ": " + e.what());
  }
}

FitSetup PrepareFit(Session& session, const segmentation::SegmentationResult& segmentation,
                    const SiteArgs& site_args, const FitArgs& fit, const InputArgs& input) {
  pipeline::FitRequest request;
  request.model = ParseModelOption("--model", fit.model);
  for (const std::string& given : fit.imu_models) {
    const std::size_t eq = given.find('=');
    int instance = -1;
    try {
      std::size_t used = 0;
      instance = eq == std::string::npos ? -1 : std::stoi(given.substr(0, eq), &used);
      if (used != eq) instance = -1;
    } catch (const std::exception&) {
      instance = -1;
    }
    if (instance < 0) {
      throw UsageError("--imu-model " + given + ": give K=SPEC, K the board IMU's number as its "
                       "parameters are named (imuK.), e.g. 2=base+gyro_g_sensitivity");
    }
    if (!request.imu_models
             .emplace(instance, ParseModelOption("--imu-model " + given.substr(0, eq),
                                                 given.substr(eq + 1)))
             .second) {
      throw UsageError("--imu-model: IMU " + std::to_string(instance) + " given twice");
    }
  }
  request.temp_ref_c = fit.temp_ref_c;
  request.level_north = fit.level_north;
  request.site = site_args.given_site();
  request.gravity_m_s2 = site_args.fixed_gravity();
  estimation::CalibrationOptions& o = request.options;
  o = fit.options;
  if (fit.heading != nullptr && fit.heading->count() > 0) o.first_heading_deg = fit.heading_deg;
  if (fit.strict) o.on_insufficient = estimation::InsufficientData::kError;
  if (!fit.noise_from.empty()) {
    o.other_still_noise.push_back(StillNoiseFrom(fit.noise_from, input, o.instability_time_s));
  }
  FitSetup out = pipeline::PrepareFit(session, segmentation, std::move(request));
  session.warnings = out.input_warnings;
  return out;
}

void PrintSession(const Session& session) {
  const ImuSeries& series = session.series;
  std::cout << session.source << ": " << series.size() << " samples, " << series.duration_s()
            << " s" << (series.has_gyro() ? "" : ", no gyroscope")
            << (series.has_temperature() ? ", with temperature" : "") << "\n";
  PrintWarnings(session.warnings);
}

void PrintWarnings(const std::vector<Notice>& warnings) {
  for (const Notice& w : warnings) std::cerr << "warning: " << w.message << "\n";
}

estimation::CalibrationResult CalibrateWithProgress(const Session& session, const FitSetup& fit) {
  Progress::Of().Stage("fitting " + fit.model.spec() + " to " + std::to_string(fit.segments.size()) +
                       " still segments");
  return pipeline::CalibrateSession(session, fit);
}

int StrictGateExit(const estimation::FitReport& fit, const std::string& source, bool strict) {
  if (!strict || fit.gates.empty()) return 0;
  std::cerr << "plumb: error: " << GateFailure(fit, source)
            << " under --strict (see 'gate failed' above); nothing written\n";
  return kExitGateFailed;
}

void AddFitInputFiles(const InputArgs& input, const std::string& segments_path,
                      const FitArgs& fit, FileRoles& roles) {
  AddInputFiles(input, roles);
  if (!segments_path.empty()) roles.inputs.push_back({"--segments", segments_path});
  if (!fit.noise_from.empty()) roles.inputs.push_back({"--noise-from", fit.noise_from});
}

}  // namespace plumb::cli

// See fit_options.h.
#include "fit_options.h"
#include "commands.h"
#include "progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/gates.h"
#include "plumb/estimation/wander_levels.h"
#include "plumb/signal/noise_terms.h"
#include "segment_options.h"
#include "validators.h"

namespace plumb::cli {

void AddModelOption(CLI::App* app, FitArgs& a) {
  app->add_option("--model", a.model,
                  "Error model spec: base, paper, or base+EFFECT[:OPTION]+... "
                  "(see 'plumb effects')")
      ->capture_default_str();
}

namespace {

/// A wander level as a datasheet states it: a finite number >= 0 with an optional unit from
/// `units` (name, SI per unit), e.g. "4 deg/h" or "40ug"; rewritten to the SI number. Without
/// a unit: SI (sensor units for unscaled samples).
CLI::Validator DatasheetLevel(std::vector<std::pair<std::string, double>> units) {
  std::string names;
  for (const auto& u : units) names += (names.empty() ? "" : ", ") + u.first;
  return CLI::Validator(
      [units, names](std::string& text) -> std::string {
        std::size_t end = 0;
        double v = 0;
        try {
          v = std::stod(text, &end);
        } catch (const std::exception&) {
          return "must be a number >= 0 with an optional unit (" + names + "), got '" + text + "'";
        }
        std::string unit = text.substr(end);
        unit.erase(std::remove(unit.begin(), unit.end(), ' '), unit.end());
        double scale = 1.0;
        if (!unit.empty()) {
          const auto it = std::find_if(units.begin(), units.end(),
                                       [&](const auto& u) { return u.first == unit; });
          if (it == units.end()) {
            return "unit '" + unit + "' not known here; use one of " + names + " (got '" + text + "')";
          }
          scale = it->second;
        }
        if (!std::isfinite(v) || v < 0) return "must be a finite number >= 0 (got '" + text + "')";
        char number[40];
        std::snprintf(number, sizeof number, "%.17g", v * scale);
        text = number;
        return {};
      },
      "LEVEL[UNIT]");
}

/// The units of datasheets and of 'plumb allan''s datasheet column, SI per unit.
const double kDegPerHour = 1.0 / units::kDegPerHourPerRadPerS;
const std::vector<std::pair<std::string, double>> kAccelInstabilityUnits{
    {"m/s^2", 1.0}, {"ug", units::kMicroG}, {"mg", units::kMilliG}};
const std::vector<std::pair<std::string, double>> kGyroInstabilityUnits{
    {"rad/s", 1.0}, {"deg/s", units::kRadPerDeg}, {"deg/h", kDegPerHour}};
const std::vector<std::pair<std::string, double>> kAccelWalkUnits{
    {"m/s^3/sqrt(Hz)", 1.0}, {"m/s^2/sqrt(s)", 1.0}, {"ug/sqrt(s)", units::kMicroG},
    {"ug/sqrt(h)", units::kMicroG / units::kSqrtSecondsPerSqrtHour}};
const std::vector<std::pair<std::string, double>> kGyroWalkUnits{
    {"rad/s^2/sqrt(Hz)", 1.0}, {"rad/s/sqrt(s)", 1.0}, {"deg/s/sqrt(s)", units::kRadPerDeg},
    {"deg/h/sqrt(h)", kDegPerHour / units::kSqrtSecondsPerSqrtHour}};

/// The bias wander (estimation/noise_model.h): by default the bias wanders (a random walk and
/// a Gauss-Markov instability) at the levels given, else from the still data or typical
/// (estimation/wander_levels.h).
void AddWanderOptions(CLI::App* app, FitArgs& a) {
  const auto level = [&](const char* name, std::optional<double>& target, const std::string& text,
                         const std::vector<std::pair<std::string, double>>& units) {
    return app->add_option(name, target, text)->transform(DatasheetLevel(units));
  };
  const std::string units =
      " (sensor units for unscaled samples), or with a datasheet's unit; 0 = none. Default: "
      "from the still data's Allan deviation, else the typical MEMS ";
  CLI::Option* wander[] = {
      level("--accel-rw", a.accel_walk_density,
            "Accelerometer bias random walk, m/s^3/sqrt(Hz) or ug/sqrt(s), ug/sqrt(h)" + units +
                "1e-4 (or --estimate-rw)",
            kAccelWalkUnits),
      level("--gyro-rw", a.gyro_walk_density,
            "Gyroscope bias random walk (rate random walk), rad/s^2/sqrt(Hz) or deg/h/sqrt(h), "
            "deg/s/sqrt(s)" + units + "2e-6 (or --estimate-rw)",
            kGyroWalkUnits),
      app->add_flag("--estimate-rw", a.estimate_walk,
                    "Estimate the bias random walks not given from the session (variance "
                    "components over the walk factors; 6 or more still poses). The differences "
                    "between poses it reads as a walk also carry any effect the model misses: "
                    "check with 'plumb diagnose' first"),
      level("--accel-bi", a.accel_instability,
            "Accelerometer bias instability as a Gauss-Markov process: its sigma, m/s^2 or ug, "
            "mg" + units + "4e-4",
            kAccelInstabilityUnits),
      level("--gyro-bi", a.gyro_instability,
            "Gyroscope bias instability as a Gauss-Markov process: its sigma, rad/s or deg/h, "
            "deg/s" + units + "2e-5",
            kGyroInstabilityUnits),
      app->add_option("--bi-time", a.instability_time_s, "Correlation time of the bias instability, s")
          ->check(CLI::Range(1e-3, 1e9))
          ->capture_default_str(),
      app->add_option("--noise-from", a.noise_from,
                      "A still recording of the same sensor (read with the same input options), "
                      "e.g. several minutes on the bench: its Allan deviation informs the bias "
                      "wander levels not given, beside the session's own still data")
          ->type_name("FILE")};
  auto* constant = app->add_flag(
      "--constant-bias", a.constant_bias,
      "One constant bias over the session: no random walk, no instability (the sigma is then "
      "honest only for white noise; for comparisons with peers that assume it)");
  for (auto* o : wander) constant->excludes(o);
}

}  // namespace

void AddFitOptions(CLI::App* app, FitArgs& a) {
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
  app->add_option("--max-iterations", a.max_iterations,
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
                                     estimation::WanderNoiseOptions(instability_time_s));
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
  FitSetup out;
  out.segments = segmentation.segments;
  if (fit.level_north && !out.segments.empty()) {
    out.segments.front().known_R_n_b = Quat::Identity();
  }
  const std::optional<double> gravity = site_args.fixed_gravity();
  out.site = ResolveSite(site_args, session.site, gravity);
  if (gravity && out.site.known) {
    session.warnings.push_back("gravity fixed at " + std::to_string(*gravity) +
                               " m/s^2 by --gravity instead of WGS84 normal gravity");
  }
  out.model = ParseModelOption("--model", fit.model);
  out.model.t_ref_s = session.series.t_s.front();
  out.model.temp_ref_c = fit.temp_ref_c;
  if (fit.heading != nullptr && fit.heading->count() > 0) {
    out.options.first_heading_deg = fit.heading_deg;
  }
  if (fit.strict) out.options.on_insufficient = estimation::InsufficientData::kError;
  out.options.max_iterations = fit.max_iterations;
  out.options.accel_walk_density = fit.accel_walk_density;
  out.options.gyro_walk_density = fit.gyro_walk_density;
  out.options.estimate_walk = fit.estimate_walk;
  out.options.accel_instability = fit.accel_instability;
  out.options.gyro_instability = fit.gyro_instability;
  out.options.instability_time_s = fit.instability_time_s;
  out.options.constant_bias = fit.constant_bias;
  if (!fit.noise_from.empty()) {
    out.options.other_still_noise.push_back(
        StillNoiseFrom(fit.noise_from, input, fit.instability_time_s));
  }
  return out;
}

void PrintSession(const Session& session) {
  const ImuSeries& series = session.series;
  std::cout << session.source << ": " << series.size() << " samples, " << series.duration_s()
            << " s" << (series.has_gyro() ? "" : ", no gyroscope")
            << (series.has_temperature() ? ", with temperature" : "") << "\n";
  PrintWarnings(session.warnings);
}

void PrintWarnings(const std::vector<std::string>& warnings) {
  for (const auto& w : warnings) std::cerr << "warning: " << w << "\n";
}

estimation::CalibrationResult CalibrateSession(const Session& session, const FitSetup& fit) {
  Progress::Of().Stage("fitting " + fit.model.spec() + " to " + std::to_string(fit.segments.size()) +
                       " still segments");
  try {
    return estimation::Calibrate(session.series, fit.segments, fit.model, fit.site, fit.options);
  } catch (const Error& e) {
    const std::vector<estimation::Gate> gates =
        estimation::CheckSamples(session.series, fit.segments);
    if (gates.empty()) throw;
    std::string text = e.what();
    for (const auto& g : gates) text += "\ngate failed: " + g.name + ": " + session.source + ": " + g.message;
    throw Error(text);
  }
}

std::string GateFailure(const estimation::FitReport& fit, const std::string& source) {
  std::string names;
  for (const auto& g : fit.gates) names += (names.empty() ? "" : ", ") + g.name;
  const std::size_t n = fit.gates.size();
  return "the fit of " + source + " failed " +
         (n == 1 ? std::string("a gate") : std::to_string(n) + " gates") + " (" + names + ")";
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

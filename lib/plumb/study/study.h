// plumb/study/study.h — a sensitivity study of the calibration procedure (`plumb sweep`): a
// base design simulated with known truth, factors that change it, and Monte Carlo runs of the
// generalized fit at every point of a design over the factors.
//
// The study file (JSON; docs/reference/cli.md#plumb-sweep, examples/studies/):
//
//   { "name": "poses",                    what the study is called
//     "seed": 1,                          the study seed (every run's seed derives from it)
//     "runs": 20,                         Monte Carlo runs per point, >= 1
//     "design": "grid",                   "grid" | "one_at_a_time" | {"latin_hypercube": N}
//     "base": { "schedule": "multipose",  "multipose" | "paper_static" | "paper_benchmark" |
//                                         "session" (with "template": a calibration document)
//               "poses": 12, "still_s": 5, "turn_s": 2, "rate_hz": 100,
//               "sensor": "typical",      "typical" (white, instability, walk, warming) | "white"
//               "random_truth": 1,        scale of the random true parameters (sim/truth.h)
//               "lat_deg": 51.64, "lon_deg": -1.2, "height_m": 100 },
//     "simulate": "base",                 the model simulated (default: the fitted one)
//     "fit": { "method": "generalized", "model": "base", "constant_bias": false,
//              "wander_levels": "from_data" },   or "given": the simulated sensor's levels
//                                         are given to the fit (a datasheet, other still data)
//     "factors": [ {"name": "poses", "levels": [6, 9, 12]},
//                  {"name": "still_s", "range": [2, 30]},      (a range: latin hypercube only)
//                  {"name": "fit_lat_error_deg", "levels": [0], "sigma": 1} ] }
//                                         sigma: an uncertain factor, drawn in every run
//                                         (Factor::sigma; not for poses)
//
// Factors (FactorNames()): poses, still_s, turn_s, rate_hz, accel_noise, gyro_noise, accel_rw,
// gyro_rw, accel_bi, gyro_bi, bi_time_s, temperature_rise_c, lat_deg, height_m (the site,
// simulated and fitted), fit_lat_error_deg (the site the fit is given is off by this much in
// latitude), fit_gravity_m_s2 (the fit uses this gravity instead of WGS84's at the site; 0:
// WGS84), level_error_deg and heading_error_deg (paper_static only: the true hold's tilt
// about body y and its heading from north, while the fit assumes level, x north), and
// truth.PARAMETER (a true parameter of the simulated model in its unit, e.g.
// truth.gyro_g_sensitivity.G.xy). Each sets the field of the base of that name.
//
// Values are SI numbers. The bias wander levels (accel_rw, gyro_rw, accel_bi, gyro_bi: the base's
// keys, and those factors' levels, range and sigma) may also be given as a datasheet states
// them, as the front ends' bias wander options take them: "4 deg/h",
// "40 ug", "0.5 deg/h/sqrt(h)" (core/datasheet_level.h); ParseStudy turns them into SI, and a
// unit the level does not take is an InputError naming the file and the key.
#pragma once

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace plumb::study {

/// A factor and its levels (grid, one at a time) or range (latin hypercube).
struct Factor {
  std::string name;
  std::vector<double> levels;  ///< the values, in the factor's unit
  double low = 0.0, high = 0.0;  ///< the range; used when levels is empty
  /// > 0: the factor is uncertain: every run draws its value from N(level, sigma^2) (a
  /// stream of its own, FactorSeed), and the results give the first-order spread its
  /// analytic sensitivity predicts (summary.h). 0: every run takes the level.
  double sigma = 0.0;
};

/// The base of every point; each factor overrides its field.
struct Base {
  std::string schedule = "multipose";  ///< multipose | paper_static | paper_benchmark | session
  double poses = 12, still_s = 5, turn_s = 2, rate_hz = 100;
  std::string sensor = "typical";  ///< typical | white
  double random_truth = 1.0;
  double lat_deg = 51.64, lon_deg = -1.2, height_m = 100.0;
  /// Noise levels (as `plumb simulate`'s flags); NaN: the sensor's (typical or white).
  static constexpr double kSensor = std::numeric_limits<double>::quiet_NaN();
  double accel_noise = kSensor, gyro_noise = kSensor, accel_rw = kSensor, gyro_rw = kSensor;
  double accel_bi = kSensor, gyro_bi = kSensor;
  double bi_time_s = 30.0, temperature_rise_c = 10.0;
  /// Turns made by hand (sim::HandHeldTurns): vibration folded into the accelerometer's
  /// samples, per-sample sigma at its peak, m/s^2, and the displacement over each turn, m.
  double hand_vibration = 0.0, hand_translation_m = 0.0;
  double fit_lat_error_deg = 0.0, fit_gravity_m_s2 = 0.0;
  /// paper_static only: the true hold is tilted about body y by level_error_deg and turned
  /// from north by heading_error_deg, while the fit assumes level, x north.
  double level_error_deg = 0.0, heading_error_deg = 0.0;
  /// schedule "session": the path of a calibration document (SPEC section 6) whose still
  /// segments (their fitted attitudes, lengths and the gaps between them) are the poses and
  /// timing (TemplateSchedule).
  std::string template_path;
  /// truth.PARAMETER factors and the base's "truth" object: name -> value.
  std::vector<std::pair<std::string, double>> truth;
};

enum class DesignKind { kGrid, kOneAtATime, kLatinHypercube };

struct Study {
  std::string name;
  std::uint64_t seed = 1;
  int runs = 10;
  DesignKind design = DesignKind::kGrid;
  int lhs_points = 0;  ///< latin hypercube: points
  Base base;
  std::string simulate_model;  ///< the simulated model spec ("" = the fitted one)
  std::string fit_model = "base";
  /// "generalized" (the backend, with sigma), "paper_static" (the seed paper's closed forms,
  /// section 5, on the paper_static schedule: no sigma, so no NEES) or "paper_static_backend"
  /// (the same procedure on the backend, the paper's constants held: with sigma;
  /// paper/backend.h), or "paper_benchmark" (the paper's section 4 closed forms on the
  /// paper_benchmark schedule: values only).
  std::string fit_method = "generalized";
  bool constant_bias = false;
  /// The generalized fit is given the simulated sensor's bias walk and instability levels
  /// (as CalibrationOptions' walk densities and instabilities from a datasheet), instead of taking
  /// them from the still data or the typical sensor (estimation/wander_levels.h).
  bool wander_levels_given = false;
  std::vector<Factor> factors;
  nlohmann::json source;  ///< the study file as read (kept in every output)
  /// schedule "session": the calibrate document at base.template_path, loaded by the caller
  /// (the library reads no files); see TemplateSchedule.
  nlohmann::json template_document;
};

/// The factor names a study may use besides truth.PARAMETER.
const std::vector<std::string>& FactorNames();

/// The unit of factor `name`'s values (FactorNames): "s", "Hz", "m/s^2/sqrt(Hz)", "deg", ...;
/// "poses" for poses; "" for truth.PARAMETER (its unit is the parameter's, which the model
/// gives) and an unknown name.
std::string FactorUnit(const std::string& name);

/// The name a factor's value stands for when it is not a quantity: "WGS84" for
/// fit_gravity_m_s2 = 0 (the fit uses WGS84's gravity at the site); "" otherwise. A factor
/// with such a value is a category, not a scale: drawn and listed by its levels' names.
std::string FactorLevelName(const std::string& name, double value);

/// Reads a study from its JSON (file comment), the wander levels given with a unit in SI.
/// Throws plumb::InputError naming `path` and the key for anything out of place (an unknown
/// factor, a range in a grid, runs < 1, a unit a level does not take, ...).
Study ParseStudy(const nlohmann::json& document, const std::string& path);

/// One point of the design: the value of every factor, in Study::factors order.
struct Point {
  int index = 0;
  std::vector<double> values;
};

/// The points of the design: the full grid (last factor fastest), one factor at a time (the
/// base, then each factor's levels with the others at the base; a level equal to the base's is
/// not repeated), or a latin hypercube of lhs_points over the ranges (seeded by the study
/// seed; a factor with levels picks among them).
std::vector<Point> DesignPoints(const Study& study);

/// The base with a point's values applied. Throws plumb::Error for an unknown factor.
Base Apply(const Study& study, const Point& point);

/// The seed of run `run` of point `point`: from the study seed by std::seed_seq, so that any
/// subset of runs reproduces bit for bit.
std::uint64_t RunSeed(std::uint64_t study_seed, int point, int run);

/// The seed of the uncertain factors' draws of run `run` of point `point` (Factor::sigma):
/// another stream than RunSeed's, so the simulated noise is the same with or without them.
std::uint64_t FactorSeed(std::uint64_t study_seed, int point, int run);

/// The point a run sees: `point` with every uncertain factor (Factor::sigma > 0) drawn from
/// N(its value, sigma^2) with FactorSeed.
Point DrawUncertainFactors(const Study& study, const Point& point, int run);

}  // namespace plumb::study

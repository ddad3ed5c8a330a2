// plumb/study/study.cc — see study.h.
#include "plumb/study/study.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>

#include "plumb/core/datasheet_level.h"
#include "plumb/core/error.h"
#include "plumb/core/option_name.h"

namespace plumb::study {
namespace {

using nlohmann::json;

/// The base's field of a factor name, or nullptr.
double* Field(Base& b, const std::string& name) {
  struct Entry {
    const char* name;
    double Base::*field;
  };
  static const Entry kFields[] = {
      {"poses", &Base::poses},
      {"still_s", &Base::still_s},
      {"turn_s", &Base::turn_s},
      {"rate_hz", &Base::rate_hz},
      {"accel_noise", &Base::accel_noise},
      {"gyro_noise", &Base::gyro_noise},
      {"accel_rw", &Base::accel_rw},
      {"gyro_rw", &Base::gyro_rw},
      {"accel_bi", &Base::accel_bi},
      {"gyro_bi", &Base::gyro_bi},
      {"bi_time_s", &Base::bi_time_s},
      {"temperature_rise_c", &Base::temperature_rise_c},
      {"hand_vibration", &Base::hand_vibration},
      {"hand_translation_m", &Base::hand_translation_m},
      {"lat_deg", &Base::lat_deg},
      {"height_m", &Base::height_m},
      {"fit_lat_error_deg", &Base::fit_lat_error_deg},
      {"fit_gravity_m_s2", &Base::fit_gravity_m_s2},
      {"level_error_deg", &Base::level_error_deg},
      {"heading_error_deg", &Base::heading_error_deg},
  };
  for (const Entry& e : kFields) {
    if (name == e.name) return &(b.*e.field);
  }
  return nullptr;
}

bool IsTruth(const std::string& name) { return name.rfind("truth.", 0) == 0; }

double Number(const json& v, const std::string& path, const std::string& where) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    throw InputError(path, "key '" + where + "'", "expected a finite number");
  }
  return v.get<double>();
}

/// The bias wander level a base key or factor of this name is (accel_rw, gyro_rw, accel_bi,
/// gyro_bi), or none.
std::optional<WanderLevel> LevelOf(const std::string& name) {
  if (name == "accel_rw") return WanderLevel::kAccelWalk;
  if (name == "gyro_rw") return WanderLevel::kGyroWalk;
  if (name == "accel_bi") return WanderLevel::kAccelInstability;
  if (name == "gyro_bi") return WanderLevel::kGyroInstability;
  return std::nullopt;
}

/// A value of the base field or factor `name` at `where`: a finite number (SI) or, for a bias
/// wander level, also a datasheet's text such as "4 deg/h" or "40 ug", read by the parser of
/// the front ends' bias instability option (core/datasheet_level.h), in SI.
double Value(const json& v, const std::string& name, const std::string& path,
             const std::string& where) {
  const std::optional<WanderLevel> level = LevelOf(name);
  if (!level || v.is_number()) return Number(v, path, where);
  if (!v.is_string()) {
    std::string units;
    for (const auto& u : DatasheetUnits(*level)) units += (units.empty() ? "" : ", ") + u.first;
    throw InputError(path, "key '" + where + "'",
                     "expected a finite number or a text with a unit (" + units + ")");
  }
  try {
    return ParseDatasheetLevel(v.get<std::string>(), *level);
  } catch (const Error& e) {
    throw InputError(path, "key '" + where + "'", e.what());
  }
}

void ReadBase(const json& b, const std::string& path, Base& base) {
  if (!b.is_object()) throw InputError(path, "key 'base'", "expected an object");
  for (const auto& [key, value] : b.items()) {
    const std::string where = "base." + key;
    if (key == "schedule" || key == "sensor" || key == "template") {
      if (!value.is_string()) throw InputError(path, "key '" + where + "'", "expected a name");
      (key == "schedule" ? base.schedule : key == "sensor" ? base.sensor : base.template_path) =
          value.get<std::string>();
    } else if (key == "random_truth") {
      base.random_truth = Number(value, path, where);
    } else if (key == "lon_deg") {
      base.lon_deg = Number(value, path, where);
    } else if (key == "truth") {
      if (!value.is_object()) throw InputError(path, "key 'base.truth'", "expected an object");
      for (const auto& [name, v] : value.items()) {
        base.truth.emplace_back(name, Number(v, path, "base.truth." + name));
      }
    } else if (double* field = Field(base, key)) {
      *field = Value(value, key, path, where);
    } else {
      throw InputError(path, "key '" + where + "'", "not a field of the base");
    }
  }
  const std::vector<std::string> schedules = {"multipose", "paper_static", "paper_benchmark",
                                              "session"};
  if (std::find(schedules.begin(), schedules.end(), base.schedule) == schedules.end()) {
    throw InputError(path, "key 'base.schedule'",
                     "expected multipose, paper_static, paper_benchmark or session");
  }
  if ((base.schedule == "session") != !base.template_path.empty()) {
    throw InputError(path, "key 'base.template'",
                     "the session schedule takes a template (a " +
                         OptionText(Option::kCalibrationJson) + " file), and only it",
                     {Option::kCalibrationJson});
  }
  if (base.sensor != "typical" && base.sensor != "white") {
    throw InputError(path, "key 'base.sensor'", "expected typical or white");
  }
}

Factor ReadFactor(const json& f, const std::string& path, std::size_t i, DesignKind design) {
  const std::string where = "factors[" + std::to_string(i) + "]";
  if (!f.is_object() || !f.contains("name") || !f.at("name").is_string()) {
    throw InputError(path, "key '" + where + "'", "expected {\"name\": ..., \"levels\": [...]}");
  }
  Factor out;
  out.name = f.at("name").get<std::string>();
  Base probe;
  if (!IsTruth(out.name) && Field(probe, out.name) == nullptr) {
    std::string names;
    for (const auto& n : FactorNames()) names += (names.empty() ? "" : ", ") + n;
    throw InputError(path, "key '" + where + ".name'",
                     "unknown factor '" + out.name + "'; known: " + names + ", truth.PARAMETER");
  }
  if (f.contains("levels")) {
    const json& levels = f.at("levels");
    if (!levels.is_array() || levels.empty()) {
      throw InputError(path, "key '" + where + ".levels'", "expected a non-empty list of numbers");
    }
    for (std::size_t j = 0; j < levels.size(); ++j) {
      out.levels.push_back(
          Value(levels[j], out.name, path, where + ".levels[" + std::to_string(j) + "]"));
    }
  } else if (f.contains("range")) {
    const json& range = f.at("range");
    if (design != DesignKind::kLatinHypercube) {
      throw InputError(path, "key '" + where + ".range'",
                       "a range needs the latin_hypercube design; give levels for a grid or one "
                       "factor at a time");
    }
    if (!range.is_array() || range.size() != 2) {
      throw InputError(path, "key '" + where + ".range'", "expected [low, high]");
    }
    out.low = Value(range[0], out.name, path, where + ".range[0]");
    out.high = Value(range[1], out.name, path, where + ".range[1]");
    if (!(out.low < out.high)) throw InputError(path, "key '" + where + ".range'", "expected low < high");
  } else {
    throw InputError(path, "key '" + where + "'", "expected levels or a range");
  }
  if (f.contains("sigma")) {
    out.sigma = Value(f.at("sigma"), out.name, path, where + ".sigma");
    if (!(out.sigma >= 0.0)) throw InputError(path, "key '" + where + ".sigma'", "expected >= 0");
    if (out.name == "poses" && out.sigma > 0.0) {
      throw InputError(path, "key '" + where + ".sigma'", "poses is a count: it cannot be drawn");
    }
    const auto non_positive = [&] {
      return std::any_of(out.levels.begin(), out.levels.end(), [](double v) { return v <= 0.0; }) ||
             (out.levels.empty() && out.low <= 0.0);
    };
    if (out.name == "fit_gravity_m_s2" && out.sigma > 0.0 && non_positive()) {
      throw InputError(path, "key '" + where + ".sigma'",
                       "fit_gravity_m_s2 0 means WGS84's: an uncertain gravity needs levels > 0");
    }
  }
  return out;
}

void ReadDesign(const json& d, const std::string& path, Study& s) {
  if (d.is_string() && d.get<std::string>() == "grid") {
    s.design = DesignKind::kGrid;
  } else if (d.is_string() && d.get<std::string>() == "one_at_a_time") {
    s.design = DesignKind::kOneAtATime;
  } else if (d.is_object() && d.contains("latin_hypercube") && d.at("latin_hypercube").is_number_integer() &&
             d.at("latin_hypercube").get<int>() >= 1) {
    s.design = DesignKind::kLatinHypercube;
    s.lhs_points = d.at("latin_hypercube").get<int>();
  } else {
    throw InputError(path, "key 'design'",
                     "expected \"grid\", \"one_at_a_time\" or {\"latin_hypercube\": POINTS}");
  }
}

}  // namespace

const std::vector<std::string>& FactorNames() {
  static const std::vector<std::string> kNames = {
      "poses",   "still_s",  "turn_s",   "rate_hz",   "accel_noise", "gyro_noise",
      "accel_rw", "gyro_rw", "accel_bi", "gyro_bi",   "bi_time_s",   "temperature_rise_c",
      "lat_deg", "height_m", "fit_lat_error_deg", "fit_gravity_m_s2", "level_error_deg",
      "heading_error_deg", "hand_vibration", "hand_translation_m"};
  return kNames;
}

std::string FactorUnit(const std::string& name) {
  static const std::vector<std::pair<std::string, std::string>> kUnits = {
      {"poses", "poses"}, {"still_s", "s"}, {"turn_s", "s"}, {"rate_hz", "Hz"},
      {"accel_noise", "m/s^2/sqrt(Hz)"}, {"gyro_noise", "rad/s/sqrt(Hz)"},
      {"accel_rw", "m/s^3/sqrt(Hz)"}, {"gyro_rw", "rad/s^2/sqrt(Hz)"}, {"accel_bi", "m/s^2"},
      {"gyro_bi", "rad/s"}, {"bi_time_s", "s"}, {"temperature_rise_c", "degC"},
      {"lat_deg", "deg"}, {"height_m", "m"}, {"fit_lat_error_deg", "deg"},
      {"fit_gravity_m_s2", "m/s^2"}, {"level_error_deg", "deg"}, {"heading_error_deg", "deg"},
      {"hand_vibration", "m/s^2"}, {"hand_translation_m", "m"}};
  for (const auto& [factor, unit] : kUnits) {
    if (factor == name) return unit;
  }
  return "";
}

std::string FactorLevelName(const std::string& name, double value) {
  return name == "fit_gravity_m_s2" && value == 0.0 ? "WGS84" : "";
}

Study ParseStudy(const json& doc, const std::string& path) {
  if (!doc.is_object()) throw InputError(path, "", "expected a study object");
  Study s;
  s.source = doc;
  for (const auto& [key, value] : doc.items()) {
    if (key == "name") {
      if (!value.is_string()) throw InputError(path, "key 'name'", "expected text");
      s.name = value.get<std::string>();
    } else if (key == "seed") {
      if (!value.is_number_integer() || (value.is_number_integer() && !value.is_number_unsigned() &&
                                          value.get<long long>() < 0)) {
        throw InputError(path, "key 'seed'", "expected an integer >= 0");
      }
      s.seed = value.get<std::uint64_t>();
    } else if (key == "runs") {
      if (!value.is_number_integer() || value.get<long>() < 1 || value.get<long>() > 1000000) {
        throw InputError(path, "key 'runs'", "expected an integer in [1, 1000000]");
      }
      s.runs = value.get<int>();
    } else if (key == "design") {
      ReadDesign(value, path, s);
    } else if (key == "base") {
      ReadBase(value, path, s.base);
    } else if (key == "simulate") {
      if (!value.is_string()) throw InputError(path, "key 'simulate'", "expected a model spec");
      s.simulate_model = value.get<std::string>();
    } else if (key == "fit") {
      if (!value.is_object()) throw InputError(path, "key 'fit'", "expected an object");
      for (const auto& [k, v] : value.items()) {
        if (k == "model" && v.is_string()) {
          s.fit_model = v.get<std::string>();
        } else if (k == "method" && v.is_string() &&
                   (v.get<std::string>() == "generalized" || v.get<std::string>() == "paper_static" ||
                    v.get<std::string>() == "paper_static_backend" ||
                    v.get<std::string>() == "paper_benchmark")) {
          s.fit_method = v.get<std::string>();
        } else if (k == "constant_bias" && v.is_boolean()) {
          s.constant_bias = v.get<bool>();
        } else if (k == "wander_levels" && v.is_string() &&
                   (v.get<std::string>() == "from_data" || v.get<std::string>() == "given")) {
          s.wander_levels_given = v.get<std::string>() == "given";
        } else {
          throw InputError(path, "key 'fit." + k + "'",
                           "expected method (generalized, paper_static, paper_static_backend "
                           "or paper_benchmark), model (text), constant_bias (true/false) or "
                           "wander_levels (from_data or given)");
        }
      }
    } else if (key != "factors") {
      throw InputError(path, "key '" + key + "'", "not a key of a study");
    }
  }
  if (doc.contains("factors")) {
    const json& factors = doc.at("factors");
    if (!factors.is_array()) throw InputError(path, "key 'factors'", "expected a list");
    for (std::size_t i = 0; i < factors.size(); ++i) {
      s.factors.push_back(ReadFactor(factors[i], path, i, s.design));
      const std::string& name = s.factors.back().name;
      if ((name == "level_error_deg" || name == "heading_error_deg") &&
          s.base.schedule != "paper_static") {
        throw InputError(path, "key 'factors[" + std::to_string(i) + "].name'",
                         name + " applies to the paper_static schedule (one level, x-north hold)");
      }
    }
  }
  const std::string needs = s.fit_method == "paper_benchmark" ? "paper_benchmark" : "paper_static";
  if (s.fit_method != "generalized" && s.base.schedule != needs) {
    throw InputError(path, "key 'fit.method'", s.fit_method + " needs the " + needs + " schedule");
  }
  return s;
}

std::vector<Point> DesignPoints(const Study& study) {
  std::vector<Point> out;
  const std::size_t k = study.factors.size();
  Base base = study.base;
  std::vector<double> at_base(k, 0.0);
  // The base's value of each factor (one at a time holds the others there).
  for (std::size_t f = 0; f < k; ++f) {
    const std::string& name = study.factors[f].name;
    if (IsTruth(name)) {
      at_base[f] = 0.0;
      for (const auto& [n, v] : base.truth) {
        if ("truth." + n == name) at_base[f] = v;
      }
    } else {
      at_base[f] = *Field(base, name);
    }
  }
  if (study.design == DesignKind::kGrid) {
    std::vector<std::size_t> index(k, 0);
    while (true) {
      Point p{static_cast<int>(out.size()), {}};
      for (std::size_t f = 0; f < k; ++f) p.values.push_back(study.factors[f].levels[index[f]]);
      out.push_back(p);
      std::size_t f = k;
      while (f > 0 && ++index[f - 1] == study.factors[f - 1].levels.size()) index[--f] = 0;
      if (f == 0) break;
    }
  } else if (study.design == DesignKind::kOneAtATime) {
    out.push_back(Point{0, at_base});
    for (std::size_t f = 0; f < k; ++f) {
      for (double level : study.factors[f].levels) {
        if (level == at_base[f]) continue;
        Point p{static_cast<int>(out.size()), at_base};
        p.values[f] = level;
        out.push_back(p);
      }
    }
  } else {
    // Latin hypercube: each factor's range cut into lhs_points strata, one draw in each, the
    // strata permuted independently per factor (McKay, Beckman and Conover 1979).
    std::mt19937_64 rng(RunSeed(study.seed, -1, -1));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const auto n = static_cast<std::size_t>(study.lhs_points);
    out.assign(n, Point{});
    for (std::size_t i = 0; i < n; ++i) out[i].index = static_cast<int>(i);
    for (std::size_t f = 0; f < k; ++f) {
      std::vector<std::size_t> strata(n);
      for (std::size_t i = 0; i < n; ++i) strata[i] = i;
      std::shuffle(strata.begin(), strata.end(), rng);
      const Factor& fac = study.factors[f];
      for (std::size_t i = 0; i < n; ++i) {
        const double x = (static_cast<double>(strata[i]) + u(rng)) / static_cast<double>(n);
        if (fac.levels.empty()) {
          out[i].values.push_back(fac.low + x * (fac.high - fac.low));
        } else {
          const auto j = std::min(fac.levels.size() - 1,
                                  static_cast<std::size_t>(x * static_cast<double>(fac.levels.size())));
          out[i].values.push_back(fac.levels[j]);
        }
      }
    }
  }
  return out;
}

Base Apply(const Study& study, const Point& point) {
  Base b = study.base;
  for (std::size_t f = 0; f < point.values.size() && f < study.factors.size(); ++f) {
    const std::string& name = study.factors[f].name;
    if (IsTruth(name)) {
      const std::string param = name.substr(6);
      auto it = std::find_if(b.truth.begin(), b.truth.end(),
                             [&](const auto& t) { return t.first == param; });
      if (it == b.truth.end()) {
        b.truth.emplace_back(param, point.values[f]);
      } else {
        it->second = point.values[f];
      }
    } else if (double* field = Field(b, name)) {
      *field = point.values[f];
    } else {
      throw Error("study: unknown factor '" + name + "'");
    }
  }
  return b;
}

namespace {

std::uint64_t TaggedSeed(std::uint64_t study_seed, int point, int run, std::uint32_t tag) {
  std::seed_seq seq{static_cast<std::uint32_t>(study_seed), static_cast<std::uint32_t>(study_seed >> 32),
                    static_cast<std::uint32_t>(point), static_cast<std::uint32_t>(run), tag};
  std::array<std::uint32_t, 2> out{};
  seq.generate(out.begin(), out.end());
  return (static_cast<std::uint64_t>(out[0]) << 32) | out[1];
}

}  // namespace

std::uint64_t RunSeed(std::uint64_t study_seed, int point, int run) {
  return TaggedSeed(study_seed, point, run, 0x706c756dU);  // "plum"
}

std::uint64_t FactorSeed(std::uint64_t study_seed, int point, int run) {
  return TaggedSeed(study_seed, point, run, 0x66616374U);  // "fact"
}

Point DrawUncertainFactors(const Study& study, const Point& point, int run) {
  Point drawn = point;
  std::mt19937_64 rng(FactorSeed(study.seed, point.index, run));
  std::normal_distribution<double> normal(0.0, 1.0);
  for (std::size_t f = 0; f < study.factors.size() && f < drawn.values.size(); ++f) {
    if (study.factors[f].sigma > 0.0) drawn.values[f] += study.factors[f].sigma * normal(rng);
  }
  return drawn;
}

}  // namespace plumb::study

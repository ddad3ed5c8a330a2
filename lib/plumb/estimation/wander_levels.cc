#include "plumb/estimation/wander_levels.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/core/typical_mems.h"

namespace plumb::estimation {
namespace {

/// Smallest level kept, as a fraction of the typical one.
constexpr double kFloor = 1e-3;
/// A record whose fitted Allan deviation reaches this fraction of the session's span covers
/// it: its fitted levels, resolved or not, reproduce the wander over the session.
constexpr double kCovers = 1.0;

/// One wander process of one sensor, as this stage fills it.
struct Slot {
  signal::Sensor sensor;
  bool walk;                          ///< random walk (else the instability)
  const std::optional<double>* given;
  Vec3* level;
  std::array<LevelSource, 3>* from;
  Vec3* bound;
  double typical;                     ///< in the sensor's units
};

/// What the still data say about one process on one axis.
struct AxisLevel {
  double level;
  LevelSource from;
  double bound;  ///< the smallest bound, +inf without still data
};

AxisLevel LevelOf(const Slot& slot, int axis, const std::vector<const signal::StillNoise*>& measured,
                  double instability_time_s, double span_s) {
  const auto kind = slot.walk ? signal::NoiseTermKind::kRandomWalk
                              : signal::NoiseTermKind::kBiasInstability;
  double bound = std::numeric_limits<double>::infinity();
  double resolved = 0.0, resolved_from_s = -1.0, covering = 0.0, covering_from_s = -1.0;
  for (const signal::StillNoise* m : measured) {
    const signal::AxisNoise* a = m->Find(slot.sensor, axis);
    if (a == nullptr) continue;
    // The terms with the estimator's instability, a Gauss-Markov process: as analysed
    // (MeasureStillNoise), or fitted again.
    signal::NoiseFit fit;
    if (m->options.terms.gauss_markov_time_s == instability_time_s) {
      fit = a->fit;
    } else {
      signal::NoiseTermsOptions options = m->options.terms;
      options.gauss_markov_time_s = instability_time_s;
      try {
        fit = signal::FitNoiseTerms(a->adev, options);
      } catch (const InsufficientDataError&) {
        continue;  // too few points: this record says nothing
      }
    }
    const signal::NoiseTerm& term = fit.term(kind);
    if (std::isfinite(term.upper_bound)) bound = std::min(bound, term.upper_bound);
    if (fit.misfit) continue;
    if (term.resolved && m->still_s > resolved_from_s) {
      resolved_from_s = m->still_s;
      resolved = term.fitted;
    }
    if (a->adev.tau_s[fit.last] >= kCovers * span_s && m->still_s > covering_from_s) {
      covering_from_s = m->still_s;
      covering = term.fitted;
    }
  }
  AxisLevel out{slot.typical, LevelSource::kTypical, bound};
  if (covering_from_s >= 0.0) {
    out = {covering, LevelSource::kMeasured, bound};
  } else if (resolved_from_s >= 0.0) {
    out = {std::min(resolved, bound), LevelSource::kMeasured, bound};
  } else if (bound < slot.typical) {
    out = {bound, LevelSource::kBounded, bound};
  }
  out.level = std::max(out.level, kFloor * slot.typical);
  return out;
}

/// "accel walk 0.0001 m/s^3/sqrt(Hz) typical (bound 0.0019..0.0021)"; per axis when the
/// axes differ in level or source.
std::string Describe(const std::string& what, const std::string& unit,
                     const std::array<AxisLevel, 3>& axes) {
  auto source = [](LevelSource from) {
    return from == LevelSource::kMeasured ? "measured"
           : from == LevelSource::kBounded ? "the data's bound"
                                           : "typical";
  };
  auto number = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.2g", v);
    return std::string(b);
  };
  const bool same = axes[0].from == axes[1].from && axes[1].from == axes[2].from &&
                    axes[0].level == axes[1].level && axes[1].level == axes[2].level;
  if (same) {
    std::string out = what + " " + number(axes[0].level) + " " + unit + " " + source(axes[0].from);
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    for (const AxisLevel& a : axes) {
      lo = std::min(lo, a.bound);
      hi = std::max(hi, a.bound);
    }
    if (axes[0].from == LevelSource::kTypical && std::isfinite(hi)) {
      out += " (bound " + number(lo) + (hi > lo ? ".." + number(hi) : "") + " " + unit + ")";
    }
    return out;
  }
  std::string out = what + " " + unit + ":";
  const char* names[3] = {" x ", ", y ", ", z "};
  for (std::size_t i = 0; i < 3; ++i) {
    out += names[i] + number(axes[i].level) + " " + source(axes[i].from);
    if (axes[i].from == LevelSource::kTypical && std::isfinite(axes[i].bound)) {
      out += " (bound " + number(axes[i].bound) + " " + unit + ")";
    }
  }
  return out;
}

std::string WalkUnit(const std::string& unit) {
  if (unit == "m/s^2") return "m/s^3/sqrt(Hz)";
  if (unit == "rad/s") return "rad/s^2/sqrt(Hz)";
  return unit + "/s/sqrt(Hz)";
}

/// Sets the quantisation that the longest still data resolve, per sensor and axis, in `n`;
/// returns ", quantisation ..." for the note ("" when none is resolved).
std::string Quantisation(const std::vector<const signal::StillNoise*>& measured, bool has_gyro,
                         NoiseModel& n) {
  std::string note;
  for (const signal::Sensor sensor : {signal::Sensor::kAccel, signal::Sensor::kGyro}) {
    if (sensor == signal::Sensor::kGyro && !has_gyro) continue;
    Vec3& Q = sensor == signal::Sensor::kAccel ? n.quantisation_acc : n.quantisation_gyr;
    for (int axis = 0; axis < 3; ++axis) {
      double from_s = -1.0;
      for (const signal::StillNoise* m : measured) {
        const signal::AxisNoise* a = m->Find(sensor, axis);
        if (a == nullptr || a->fit.misfit || m->still_s <= from_s) continue;
        const signal::NoiseTerm& q = a->fit.term(signal::NoiseTermKind::kQuantisation);
        if (!q.resolved) continue;
        from_s = m->still_s;
        Q[axis] = q.fitted;
      }
    }
    if (Q.isZero()) continue;
    char text[160];
    std::snprintf(text, sizeof text, ", %s quantisation x %.2g, y %.2g, z %.2g (measured where "
                  "not 0) sensor units x s", sensor == signal::Sensor::kAccel ? "accel" : "gyro",
                  Q[0], Q[1], Q[2]);
    note += text;
  }
  return note;
}

}  // namespace

WanderLevels AssignWanderLevels(const NoiseModel& noise,
                                const std::vector<const signal::StillNoise*>& measured,
                                const StartingValues& start, bool has_gyro, double span_s,
                                const CalibrationOptions& options, int still_poses) {
  WanderLevels out{noise, {}, {}};
  NoiseModel& n = out.noise;
  WanderBounds& b = out.bounds;
  const double acc_scale = start.accel.scale, gyr_scale = 1.0 / start.gyro_rad_per_unit;
  const std::array<Slot, 4> slots{{
      {signal::Sensor::kAccel, false, &options.accel_instability, &n.instability_acc,
       &n.from.instability_acc, &b.instability_acc, typical_mems::kAccelInstability * acc_scale},
      {signal::Sensor::kAccel, true, &options.accel_walk_density, &n.walk_acc, &n.from.walk_acc,
       &b.walk_acc, typical_mems::kAccelWalk * acc_scale},
      {signal::Sensor::kGyro, false, &options.gyro_instability, &n.instability_gyr,
       &n.from.instability_gyr, &b.instability_gyr, typical_mems::kGyroInstability * gyr_scale},
      {signal::Sensor::kGyro, true, &options.gyro_walk_density, &n.walk_gyr, &n.from.walk_gyr,
       &b.walk_gyr, typical_mems::kGyroWalk * gyr_scale},
  }};
  std::string acc_unit = "sensor units", gyr_unit = "sensor units";
  double still_s = 0.0;
  for (const signal::StillNoise* m : measured) {
    acc_unit = m->acc_unit;
    gyr_unit = m->gyr_unit;
    still_s += m->still_s;
  }
  std::string note;
  for (const Slot& slot : slots) {
    if (slot.given->has_value()) continue;
    if (slot.sensor == signal::Sensor::kGyro && !has_gyro) continue;
    std::array<AxisLevel, 3> axes{};
    for (int i = 0; i < 3; ++i) {
      const AxisLevel a = LevelOf(slot, i, measured, n.instability_time_s, span_s);
      axes[static_cast<std::size_t>(i)] = a;
      (*slot.level)[i] = a.level;
      (*slot.from)[static_cast<std::size_t>(i)] = a.from;
      (*slot.bound)[i] = a.bound;
    }
    const bool acc = slot.sensor == signal::Sensor::kAccel;
    const std::string unit = slot.walk ? WalkUnit(acc ? acc_unit : gyr_unit) : (acc ? acc_unit : gyr_unit);
    const std::string what = std::string(acc ? "accel" : "gyro") + (slot.walk ? " walk" : " instability");
    note += (note.empty() ? "" : ", ") + Describe(what, unit, axes);
  }
  note += Quantisation(measured, has_gyro, n);
  if (note.empty()) return out;
  // The session's holds can estimate what the still data leave to the typical sensor.
  const bool estimable = !options.estimate_walk && still_poses >= options.walk_min_poses &&
                         note.find(" typical") != std::string::npos;
  char head[160], tail[160];
  std::snprintf(head, sizeof head, "bias wander levels (Allan deviation of %.0f s of still data): ",
                still_s);
  const std::string lead = measured.empty() ? "bias wander levels (no still data long enough for "
                                              "an Allan deviation): "
                                            : head;
  std::snprintf(tail, sizeof tail, "; instability: Gauss-Markov sigma, correlation time %.3g "
                "s; override with ", n.instability_time_s);
  std::vector<Option> pointed = {Option::kAccelWalk, Option::kGyroWalk,
                                 Option::kAccelInstability, Option::kGyroInstability,
                                 Option::kNoiseFrom};
  if (estimable) pointed.push_back(Option::kEstimateWalk);
  out.notes.push_back(Notice{
      "wander_levels",
      lead + note + tail + OptionText(Option::kAccelWalk) + "/" + OptionText(Option::kGyroWalk) +
          "/" + OptionText(Option::kAccelInstability) + "/" +
          OptionText(Option::kGyroInstability) + " (a datasheet's values)" +
          (estimable ? "," : " or") + " " + OptionText(Option::kNoiseFrom) +
          " a long still recording" +
          (estimable ? " or " + OptionText(Option::kEstimateWalk) +
                           " (from the session's holds, once diagnose finds no missing effect)"
                     : std::string()),
      std::move(pointed)});
  return out;
}

signal::StillNoiseOptions WanderNoiseOptions(double instability_time_s) {
  signal::StillNoiseOptions options;
  options.terms.gauss_markov_time_s = instability_time_s;
  // Half the density of 'plumb allan': the fit's tests count points per decade, and the
  // Allan deviation of an hour at 1 kHz costs half as much (one pass over the samples per
  // cluster size).
  options.allan.points_per_decade = 5;
  return options;
}

std::optional<signal::StillNoise> MeasureStillNoise(const ImuSeries& series, const StillSet& set,
                                                    double instability_time_s,
                                                    std::vector<Notice>& notes,
                                                    const JobRunner& run_jobs) {
  try {
    return signal::AnalyseStillNoise(series, set.AtRestSegments(),
                                      WanderNoiseOptions(instability_time_s), run_jobs);
  } catch (const InsufficientDataError& e) {
    AddNotice(notes, "allan_too_short",
              std::string("the still data are too short for an Allan deviation (") + e.what() +
                  ")");
  }
  return std::nullopt;
}

}  // namespace plumb::estimation

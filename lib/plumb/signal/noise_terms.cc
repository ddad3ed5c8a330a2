#include "plumb/signal/noise_terms.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/signal/chi_square.h"

namespace plumb::signal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// The fit has settled when no coefficient moves by more than this fraction of the largest.
constexpr double kSettled = 1e-9;
/// The shortest segment the still noise is measured on, samples (clusters of 1..4).
constexpr std::size_t kMinSegmentSamples = 8;

NoiseTermKind Kind(int k) { return static_cast<NoiseTermKind>(k); }

void CheckOptions(const NoiseTermsOptions& o) {
  const bool ok = o.tau_min_s >= 0.0 && std::isfinite(o.tau_min_s) && o.tau_max_s >= 0.0 &&
                  std::isfinite(o.tau_max_s) && o.min_edf >= 1.0 && std::isfinite(o.min_edf) &&
                  o.min_points >= 1 && o.term_confidence > 0.5 && o.term_confidence < 1.0 &&
                  o.max_iterations >= 1 && o.misfit_chi2_per_point > 0.0 &&
                  o.gauss_markov_time_s >= 0.0 && std::isfinite(o.gauss_markov_time_s);
  if (!ok) {
    throw Error("noise terms: options out of range (tau_min_s, tau_max_s >= 0, min_edf >= 1, "
                "min_points >= 1, term_confidence in (0.5, 1), max_iterations >= 1, "
                "misfit_chi2_per_point > 0, gauss_markov_time_s >= 0)");
  }
}

/// The points fitted: in [tau_min, tau_max] with a white-FM EDF of at least min_edf.
std::vector<std::size_t> FittedPoints(const AllanDeviation& a, const NoiseTermsOptions& o) {
  std::vector<std::size_t> points;
  for (std::size_t j = 0; j < a.tau_s.size(); ++j) {
    if (a.tau_s[j] < o.tau_min_s * (1.0 - 1e-12)) continue;
    if (o.tau_max_s > 0.0 && a.tau_s[j] > o.tau_max_s * (1.0 + 1e-12)) continue;
    if (!(a.adev[j] > 0.0)) continue;  // a constant record says nothing
    const double edf =
        PooledAllanEdf(a.record_sizes, a.cluster_size[j], PowerLawNoise::kWhiteFrequency);
    if (edf < o.min_edf) continue;
    points.push_back(j);
  }
  return points;
}

using Coefficients = std::array<double, kNoiseTermCount>;

/// The shape of term k: NoiseTermShape, but a Gauss-Markov process of correlation time gm
/// for the instability when gm > 0 (NoiseTermsOptions::gauss_markov_time_s).
double TermShape(int k, double tau, double gm) {
  if (gm > 0.0 && Kind(k) == NoiseTermKind::kBiasInstability) return GaussMarkovAvarShape(tau, gm);
  return NoiseTermShape(Kind(k), tau);
}

struct WeightedProblem {
  std::vector<double> tau, target, weight;  // per fitted point
  double gm = 0.0;                          // the instability's shape (TermShape)
};

double Model(const Coefficients& c, double tau, double gm) {
  double sum = 0.0;
  for (int k = 0; k < kNoiseTermCount; ++k) sum += c[k] * TermShape(k, tau, gm);
  return sum;
}

double LinearCost(const WeightedProblem& p, const Coefficients& c) {
  double cost = 0.0;
  for (std::size_t j = 0; j < p.tau.size(); ++j) {
    const double r = p.target[j] - Model(c, p.tau[j], p.gm);
    cost += p.weight[j] * r * r;
  }
  return cost;
}

/// Non-negative weighted least squares of `target` by enumerating the subsets of the enabled
/// terms (each solved by column-pivoted QR on unit-norm columns; the cheapest one with no
/// negative coefficient wins).
Coefficients SolveNonNegative(const WeightedProblem& p,
                              const std::array<bool, kNoiseTermCount>& enabled) {
  const auto rows = static_cast<Eigen::Index>(p.tau.size());
  Coefficients best{};
  double best_cost = LinearCost(p, best);  // all zero
  for (int subset = 1; subset < (1 << kNoiseTermCount); ++subset) {
    std::vector<int> cols;
    for (int k = 0; k < kNoiseTermCount; ++k) {
      if ((subset >> k) & 1) cols.push_back(k);
    }
    const bool allowed = std::all_of(cols.begin(), cols.end(), [&](int k) { return enabled[k]; });
    if (!allowed || static_cast<Eigen::Index>(cols.size()) > rows) continue;
    Eigen::MatrixXd design(rows, static_cast<Eigen::Index>(cols.size()));
    Eigen::VectorXd y(rows);
    for (Eigen::Index j = 0; j < rows; ++j) {
      const double s = std::sqrt(p.weight[j]);
      y[j] = s * p.target[j];
      for (std::size_t i = 0; i < cols.size(); ++i) {
        design(j, static_cast<Eigen::Index>(i)) = s * TermShape(cols[i], p.tau[j], p.gm);
      }
    }
    const Eigen::VectorXd norms = design.colwise().norm();
    if ((norms.array() <= 0.0).any()) continue;
    const Eigen::MatrixXd scaled = design * norms.cwiseInverse().asDiagonal();
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(scaled);
    if (qr.rank() < scaled.cols()) continue;
    const Eigen::VectorXd z = qr.solve(y);
    Coefficients c{};
    bool feasible = true;
    for (std::size_t i = 0; i < cols.size(); ++i) {
      c[cols[i]] = z[static_cast<Eigen::Index>(i)] / norms[static_cast<Eigen::Index>(i)];
      feasible = feasible && c[cols[i]] >= 0.0 && std::isfinite(c[cols[i]]);
    }
    if (!feasible) continue;
    const double cost = LinearCost(p, c);
    if (cost < best_cost) {
      best_cost = cost;
      best = c;
    }
  }
  return best;
}

/// The term with the largest AVAR at tau (the white noise when every coefficient is 0).
int Dominant(const Coefficients& c, double tau, double gm) {
  int best = static_cast<int>(NoiseTermKind::kWhite);
  double largest = 0.0;
  for (int k = 0; k < kNoiseTermCount; ++k) {
    const double v = c[k] * TermShape(k, tau, gm);
    if (v > largest) {
      largest = v;
      best = k;
    }
  }
  return best;
}

/// The fit: coefficients, and the noise type and EDF at each fitted point.
struct FitState {
  Coefficients c{};
  std::vector<PowerLawNoise> noise;  // per fitted point
  std::vector<double> edf;           // per fitted point
  double chi2 = 0.0;
  int iterations = 0;
};

/// sum_j edf_j / 2 (ln AVAR_j - ln model_j)^2; infinite where the model is not positive.
double LogCost(const std::vector<double>& tau, const std::vector<double>& avar,
               const std::vector<double>& edf, const Coefficients& c, double gm) {
  double cost = 0.0;
  for (std::size_t j = 0; j < tau.size(); ++j) {
    const double m = Model(c, tau[j], gm);
    if (!(m > 0.0)) return std::numeric_limits<double>::infinity();
    const double r = std::log(avar[j] / m);
    cost += 0.5 * edf[j] * r * r;
  }
  return cost;
}

/// Gauss-Newton on the log cost with the non-negative linear step of the header: each pass
/// fits model_j (1 + ln(AVAR_j / model_j)) with weights edf_j / (2 model_j^2) (the first pass,
/// model = AVAR, is the relative-error fit), halves the step while the log cost rises, and
/// updates the noise types and EDF from the dominant terms.
FitState FitInLogs(const AllanDeviation& a, const std::vector<std::size_t>& points,
                   const std::array<bool, kNoiseTermCount>& enabled, int max_iterations,
                   double gm) {
  FitState s;
  s.noise.assign(points.size(), PowerLawNoise::kWhiteFrequency);
  s.edf.assign(points.size(), 0.0);
  WeightedProblem p;
  p.gm = gm;
  std::vector<double> avar;
  for (std::size_t j : points) {
    p.tau.push_back(a.tau_s[j]);
    avar.push_back(a.adev[j] * a.adev[j]);
  }
  std::vector<double> model = avar;
  p.target.assign(points.size(), 0.0);
  p.weight.assign(points.size(), 0.0);
  const auto update_edf = [&] {
    for (std::size_t i = 0; i < points.size(); ++i) {
      s.edf[i] = PooledAllanEdf(a.record_sizes, a.cluster_size[points[i]], s.noise[i]);
    }
  };
  for (int it = 1; it <= max_iterations; ++it) {
    update_edf();
    for (std::size_t i = 0; i < points.size(); ++i) {
      p.weight[i] = 0.5 * s.edf[i] / (model[i] * model[i]);
      p.target[i] = model[i] * (1.0 + std::log(avar[i] / model[i]));
    }
    Coefficients c = SolveNonNegative(p, enabled);
    if (it > 1) {  // step control: never a higher log cost than the last solution's
      const Coefficients from = s.c;
      const double before = LogCost(p.tau, avar, s.edf, from, gm);
      double step = 1.0;
      Coefficients trial = c;
      while (LogCost(p.tau, avar, s.edf, trial, gm) > before && step > 1.0 / 64) {
        step *= 0.5;
        for (int k = 0; k < kNoiseTermCount; ++k) trial[k] = from[k] + step * (c[k] - from[k]);
      }
      c = LogCost(p.tau, avar, s.edf, trial, gm) <= before ? trial : from;
    }
    s.iterations = it;
    bool same = it > 1;
    double largest = 0.0;
    for (int k = 0; k < kNoiseTermCount; ++k) largest = std::max(largest, c[k]);
    for (int k = 0; k < kNoiseTermCount; ++k) {
      same = same && std::abs(c[k] - s.c[k]) <= kSettled * largest;
    }
    s.c = c;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double m = Model(c, p.tau[i], gm);
      model[i] = m > 0.0 ? m : avar[i];
      const PowerLawNoise noise = NoiseTermNoise(Kind(Dominant(c, p.tau[i], gm)));
      same = same && noise == s.noise[i];
      s.noise[i] = noise;
    }
    if (same) break;
  }
  update_edf();
  s.chi2 = LogCost(p.tau, avar, s.edf, s.c, gm);
  return s;
}

std::array<bool, kNoiseTermCount> Enabled(const NoiseTermsOptions& o) {
  return {o.quantisation, true, true, true, o.rate_ramp};
}

/// Resolved test and upper bound of term k (see the header).
NoiseTerm Judge(int k, const AllanDeviation& a, const std::vector<std::size_t>& points,
                const FitState& s, const NoiseTermsOptions& o) {
  NoiseTerm t;
  t.kind = Kind(k);
  t.in_model = k == static_cast<int>(NoiseTermKind::kQuantisation) ? o.quantisation
               : k == static_cast<int>(NoiseTermKind::kRamp)       ? o.rate_ramp
                                                                    : true;
  t.fitted = std::sqrt(s.c[k]);
  t.upper_bound = kNaN;
  // Bonferroni over the fitted points: each point's one-sided limit leaves out (1 - c) / P.
  t.chi2_rise = kNaN;
  const double tail = (1.0 - o.term_confidence) / static_cast<double>(points.size());
  double bound = std::numeric_limits<double>::infinity();
  std::size_t run_begin = 0, run_length = 0, best_begin = 0, best_length = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double tau = a.tau_s[points[i]];
    const double avar = a.adev[points[i]] * a.adev[points[i]];
    const double upper = avar * s.edf[i] / ChiSquareQuantileExact(tail, s.edf[i]);
    const double b = upper / TermShape(k, tau, o.gauss_markov_time_s);
    if (b < bound) {
      bound = b;
      t.bound_tau_s = tau;
    }
    const bool dominant = s.c[k] > 0.0 && Dominant(s.c, tau, o.gauss_markov_time_s) == k;
    run_length = dominant ? run_length + 1 : 0;
    if (run_length == 1) run_begin = i;
    if (run_length > best_length) {
      best_length = run_length;
      best_begin = run_begin;
    }
  }
  t.upper_bound = std::sqrt(bound);
  if (best_length >= static_cast<std::size_t>(o.min_points)) {
    // The best fit without the term, and how much worse it is, counting a decade of points
    // as one observation.
    std::array<bool, kNoiseTermCount> without = Enabled(o);
    without[k] = false;
    const Coefficients c =
        FitInLogs(a, points, without, o.max_iterations, o.gauss_markov_time_s).c;
    std::vector<double> tau, avar;
    for (std::size_t j : points) {
      tau.push_back(a.tau_s[j]);
      avar.push_back(a.adev[j] * a.adev[j]);
    }
    const double decades = std::log10(tau.back() / tau.front());
    const double per_decade =
        decades > 0.0 ? std::max(1.0, static_cast<double>(points.size() - 1) / decades) : 1.0;
    t.chi2_rise = (LogCost(tau, avar, s.edf, c, o.gauss_markov_time_s) - s.chi2) / per_decade;
    t.resolved = t.chi2_rise > ChiSquareQuantileExact(o.term_confidence, 1.0);
  }
  if (t.resolved) {
    t.tau_min_s = a.tau_s[points[best_begin]];
    t.tau_max_s = a.tau_s[points[best_begin + best_length - 1]];
  } else {
    t.tau_min_s = t.tau_max_s = t.bound_tau_s;
  }
  return t;
}

}  // namespace

const char* NoiseTermSymbol(NoiseTermKind kind) {
  switch (kind) {
    case NoiseTermKind::kQuantisation: return "Q";
    case NoiseTermKind::kWhite: return "N";
    case NoiseTermKind::kBiasInstability: return "B";
    case NoiseTermKind::kRandomWalk: return "K";
    case NoiseTermKind::kRamp: return "R";
  }
  return "?";
}

double NoiseTermShape(NoiseTermKind kind, double tau_s) {
  switch (kind) {
    case NoiseTermKind::kQuantisation: return 3.0 / (tau_s * tau_s);
    case NoiseTermKind::kWhite: return 1.0 / tau_s;
    case NoiseTermKind::kBiasInstability: return 2.0 * std::log(2.0) / units::kPi;
    case NoiseTermKind::kRandomWalk: return tau_s / 3.0;
    case NoiseTermKind::kRamp: return 0.5 * tau_s * tau_s;
  }
  return kNaN;
}

PowerLawNoise NoiseTermNoise(NoiseTermKind kind) {
  switch (kind) {
    case NoiseTermKind::kQuantisation: return PowerLawNoise::kWhitePhase;
    case NoiseTermKind::kWhite: return PowerLawNoise::kWhiteFrequency;
    case NoiseTermKind::kBiasInstability: return PowerLawNoise::kFlickerFrequency;
    case NoiseTermKind::kRandomWalk:
    case NoiseTermKind::kRamp: return PowerLawNoise::kRandomWalkFrequency;
  }
  return PowerLawNoise::kWhiteFrequency;
}

double GaussMarkovAvarShape(double tau_s, double tau_c_s) {
  const double x = tau_s / tau_c_s;
  // Below x = 1e-3 the bracket cancels to rounding: its series, 2 x / 3 - x^2 / 2.
  if (x < 1e-3) return x * (2.0 / 3.0 - 0.5 * x);
  return (2.0 - (3.0 - 4.0 * std::exp(-x) + std::exp(-2.0 * x)) / x) / x;
}

double NoiseFit::Avar(double tau_s) const {
  double sum = 0.0;
  for (int k = 0; k < kNoiseTermCount; ++k) {
    const NoiseTerm& t = terms[static_cast<std::size_t>(k)];
    sum += t.fitted * t.fitted * TermShape(k, tau_s, gauss_markov_time_s);
  }
  return sum;
}

NoiseFit FitNoiseTerms(const AllanDeviation& a, const NoiseTermsOptions& o) {
  CheckOptions(o);
  const std::vector<std::size_t> points = FittedPoints(a, o);
  if (points.size() < 2) {
    throw InsufficientDataError(
        "noise terms: " + std::to_string(points.size()) +
        " Allan deviation point(s) in the fitted range; record a longer still period");
  }
  const FitState s = FitInLogs(a, points, Enabled(o), o.max_iterations, o.gauss_markov_time_s);
  NoiseFit fit;
  fit.gauss_markov_time_s = o.gauss_markov_time_s;
  for (int k = 0; k < kNoiseTermCount; ++k) fit.terms[k] = Judge(k, a, points, s, o);
  fit.first = points.front();
  fit.last = points.back();
  fit.chi2 = s.chi2;
  int nonzero = 0;
  for (double c : s.c) nonzero += c > 0.0 ? 1 : 0;
  fit.dof = static_cast<int>(points.size()) - nonzero;
  fit.iterations = s.iterations;
  // A curve the terms cannot describe resolves nothing: only the bounds stand.
  fit.misfit = fit.chi2 > o.misfit_chi2_per_point * static_cast<double>(points.size());
  if (fit.misfit) {
    for (NoiseTerm& t : fit.terms) {
      t.resolved = false;
      t.tau_min_s = t.tau_max_s = t.bound_tau_s;
    }
  }
  // Noise type per point of the whole curve: the fit's inside, the nearest fitted point's out.
  fit.noise.assign(a.tau_s.size(), PowerLawNoise::kWhiteFrequency);
  std::size_t i = 0;
  for (std::size_t j = 0; j < a.tau_s.size(); ++j) {
    while (i + 1 < points.size() && points[i] < j) ++i;
    std::size_t nearest = i;
    if (i > 0 && points[i] > j && j - points[i - 1] < points[i] - j) nearest = i - 1;
    fit.noise[j] = s.noise[nearest];
  }
  return fit;
}

const AxisNoise* StillNoise::Find(Sensor sensor, int axis) const {
  for (const AxisNoise& a : axes) {
    if (a.sensor == sensor && a.axis == axis) return &a;
  }
  return nullptr;
}

StillNoise AnalyseStillNoise(const ImuSeries& series, const std::vector<StillSegment>& segments,
                             const StillNoiseOptions& options, const JobRunner& run_jobs) {
  StillNoise out;
  out.options = options;
  out.dt_s = series.median_dt_s();
  if (!(out.dt_s > 0.0)) throw Error("still noise: the series has no sample interval");
  out.acc_unit = series.acc_unit;
  out.gyr_unit = series.gyr_unit;
  std::size_t longest = 0;
  for (const StillSegment& s : segments) {
    if (s.end > series.size() || s.end < s.begin) {
      throw Error("still noise: segment '" + s.label + "' is outside the series");
    }
    if (s.spinning()) {
      out.notes.push_back("segment '" + s.label + "' turns at a stated rate: left out");
      continue;
    }
    if (s.count() < 2) {
      out.notes.push_back("segment '" + s.label + "' has fewer than 2 samples: left out");
      continue;
    }
    out.segments.push_back(s);
    out.samples += s.count();
    longest = std::max(longest, s.count());
  }
  if (longest < kMinSegmentSamples) {
    throw InsufficientDataError(
        "still noise: the longest still segment has " + std::to_string(longest) +
        " samples; the Allan deviation needs at least " + std::to_string(kMinSegmentSamples) +
        " (record a still period of several minutes for the noise terms)");
  }
  out.still_s = static_cast<double>(out.samples) * out.dt_s;
  out.longest_s = static_cast<double>(longest) * out.dt_s;
  // One job per axis of each sensor, each writing its own entry; the first error in axis
  // order is the one thrown.
  const int sensors = series.has_gyro() ? 2 : 1;
  out.axes.resize(static_cast<std::size_t>(3 * sensors));
  std::vector<std::exception_ptr> errors(out.axes.size());
  RunJobs(run_jobs, static_cast<int>(out.axes.size()), [&](int job) {
    const auto k = static_cast<std::size_t>(job);
    try {
      AxisNoise& a = out.axes[k];
      a.sensor = job < 3 ? Sensor::kAccel : Sensor::kGyro;
      a.axis = job % 3;
      std::vector<AxisView> records;
      for (const StillSegment& s : out.segments) {
        records.push_back(ViewAxis(series, a.sensor, a.axis, s.begin, s.end));
      }
      a.adev = PooledAllanPoints(records, out.dt_s, options.allan);  // intervals below
      a.fit = FitNoiseTerms(a.adev, options.terms);
      SetAllanIntervals(a.adev, a.fit.noise, options.allan.confidence);
    } catch (...) {
      errors[k] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return out;
}

}  // namespace plumb::signal

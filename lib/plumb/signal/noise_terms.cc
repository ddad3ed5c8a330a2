#include "plumb/signal/noise_terms.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <utility>
#include <vector>

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

/// The fitted points and what every pass of the fit and every term's refit reads of them,
/// computed once per FitNoiseTerms: each point's tau, AVAR and term shapes (TermShape), and its
/// pooled EDF for each noise type, computed when first asked for.
class FitData {
 public:
  FitData(const AllanDeviation& a, std::vector<std::size_t> points, double gm)
      : a_(a), points_(std::move(points)), gm_(gm) {
    for (std::size_t j : points_) {
      tau_.push_back(a.tau_s[j]);
      avar_.push_back(a.adev[j] * a.adev[j]);
      Coefficients shape{};
      for (int k = 0; k < kNoiseTermCount; ++k) shape[k] = TermShape(k, a.tau_s[j], gm);
      shape_.push_back(shape);
    }
    edf_.assign(points_.size() * kNoiseTypes, kUnset);
  }

  std::size_t size() const { return points_.size(); }
  const std::vector<std::size_t>& points() const { return points_; }
  const std::vector<double>& tau() const { return tau_; }
  const std::vector<double>& avar() const { return avar_; }
  const Coefficients& shape(std::size_t i) const { return shape_[i]; }
  double gm() const { return gm_; }

  /// PooledAllanEdf of point i for `noise`.
  double Edf(std::size_t i, PowerLawNoise noise) {
    double& edf = edf_[i * kNoiseTypes + static_cast<std::size_t>(noise)];
    if (edf == kUnset) edf = PooledAllanEdf(a_.record_sizes, a_.cluster_size[points_[i]], noise);
    return edf;
  }

 private:
  static constexpr std::size_t kNoiseTypes = 5;  // PowerLawNoise's values
  static constexpr double kUnset = -1.0;         // an EDF is at least 1
  const AllanDeviation& a_;
  std::vector<std::size_t> points_;
  double gm_;
  std::vector<double> tau_, avar_;
  std::vector<Coefficients> shape_;
  std::vector<double> edf_;
};

struct WeightedProblem {
  std::vector<double> target, weight;  // per fitted point
};

/// The model's AVAR at a point, from its term shapes.
double Model(const Coefficients& c, const Coefficients& shape) {
  double sum = 0.0;
  for (int k = 0; k < kNoiseTermCount; ++k) sum += c[k] * shape[k];
  return sum;
}

double LinearCost(const FitData& d, const WeightedProblem& p, const Coefficients& c) {
  double cost = 0.0;
  for (std::size_t j = 0; j < d.size(); ++j) {
    const double r = p.target[j] - Model(c, d.shape(j));
    cost += p.weight[j] * r * r;
  }
  return cost;
}

/// Non-negative weighted least squares of `target` by enumerating the subsets of the enabled
/// terms (each solved by column-pivoted QR on unit-norm columns; the cheapest one with no
/// negative coefficient wins).
Coefficients SolveNonNegative(const FitData& d, const WeightedProblem& p,
                              const std::array<bool, kNoiseTermCount>& enabled) {
  const auto rows = static_cast<Eigen::Index>(d.size());
  Coefficients best{};
  double best_cost = LinearCost(d, p, best);  // all zero
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
      const auto point = static_cast<std::size_t>(j);
      const double s = std::sqrt(p.weight[point]);
      y[j] = s * p.target[point];
      for (std::size_t i = 0; i < cols.size(); ++i) {
        design(j, static_cast<Eigen::Index>(i)) = s * d.shape(point)[cols[i]];
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
    const double cost = LinearCost(d, p, c);
    if (cost < best_cost) {
      best_cost = cost;
      best = c;
    }
  }
  return best;
}

/// The term with the largest AVAR at a point of term shapes `shape` (the white noise when
/// every coefficient is 0).
int Dominant(const Coefficients& c, const Coefficients& shape) {
  int best = static_cast<int>(NoiseTermKind::kWhite);
  double largest = 0.0;
  for (int k = 0; k < kNoiseTermCount; ++k) {
    const double v = c[k] * shape[k];
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
double LogCost(const FitData& d, const std::vector<double>& edf, const Coefficients& c) {
  double cost = 0.0;
  for (std::size_t j = 0; j < d.size(); ++j) {
    const double m = Model(c, d.shape(j));
    if (!(m > 0.0)) return std::numeric_limits<double>::infinity();
    const double r = std::log(d.avar()[j] / m);
    cost += 0.5 * edf[j] * r * r;
  }
  return cost;
}

/// Gauss-Newton on the log cost with the non-negative linear step of the header: each pass
/// fits model_j (1 + ln(AVAR_j / model_j)) with weights edf_j / (2 model_j^2) (the first pass,
/// model = AVAR, is the relative-error fit), halves the step while the log cost rises, and
/// updates the noise types and EDF from the dominant terms.
FitState FitInLogs(FitData& d, const std::array<bool, kNoiseTermCount>& enabled,
                   int max_iterations) {
  const std::size_t points = d.size();
  const std::vector<double>& avar = d.avar();
  FitState s;
  s.noise.assign(points, PowerLawNoise::kWhiteFrequency);
  s.edf.assign(points, 0.0);
  WeightedProblem p;
  std::vector<double> model = avar;
  p.target.assign(points, 0.0);
  p.weight.assign(points, 0.0);
  const auto update_edf = [&] {
    for (std::size_t i = 0; i < points; ++i) s.edf[i] = d.Edf(i, s.noise[i]);
  };
  for (int it = 1; it <= max_iterations; ++it) {
    update_edf();
    for (std::size_t i = 0; i < points; ++i) {
      p.weight[i] = 0.5 * s.edf[i] / (model[i] * model[i]);
      p.target[i] = model[i] * (1.0 + std::log(avar[i] / model[i]));
    }
    Coefficients c = SolveNonNegative(d, p, enabled);
    if (it > 1) {  // step control: never a higher log cost than the last solution's
      const Coefficients from = s.c;
      const double before = LogCost(d, s.edf, from);
      double step = 1.0;
      Coefficients trial = c;
      while (LogCost(d, s.edf, trial) > before && step > 1.0 / 64) {
        step *= 0.5;
        for (int k = 0; k < kNoiseTermCount; ++k) trial[k] = from[k] + step * (c[k] - from[k]);
      }
      c = LogCost(d, s.edf, trial) <= before ? trial : from;
    }
    s.iterations = it;
    bool same = it > 1;
    double largest = 0.0;
    for (int k = 0; k < kNoiseTermCount; ++k) largest = std::max(largest, c[k]);
    for (int k = 0; k < kNoiseTermCount; ++k) {
      same = same && std::abs(c[k] - s.c[k]) <= kSettled * largest;
    }
    s.c = c;
    for (std::size_t i = 0; i < points; ++i) {
      const double m = Model(c, d.shape(i));
      model[i] = m > 0.0 ? m : avar[i];
      const PowerLawNoise noise = NoiseTermNoise(Kind(Dominant(c, d.shape(i))));
      same = same && noise == s.noise[i];
      s.noise[i] = noise;
    }
    if (same) break;
  }
  update_edf();
  s.chi2 = LogCost(d, s.edf, s.c);
  return s;
}

std::array<bool, kNoiseTermCount> Enabled(const NoiseTermsOptions& o) {
  return {o.quantisation, true, true, true, o.rate_ramp};
}

/// What Judge reads of the fit for every term: each fitted point's one-sided upper limit of
/// AVAR (Bonferroni over the points: each leaves out (1 - c) / P), and the chi^2 rise that
/// resolves a term.
struct Limits {
  std::vector<double> upper_avar;  // per fitted point
  double resolving_rise = 0.0;
};

Limits MakeLimits(const FitData& d, const FitState& s, const NoiseTermsOptions& o) {
  Limits limits;
  const double tail = (1.0 - o.term_confidence) / static_cast<double>(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    limits.upper_avar.push_back(d.avar()[i] * s.edf[i] / ChiSquareQuantileExact(tail, s.edf[i]));
  }
  limits.resolving_rise = ChiSquareQuantileExact(o.term_confidence, 1.0);
  return limits;
}

/// Resolved test and upper bound of term k (see the header).
NoiseTerm Judge(int k, FitData& d, const FitState& s, const Limits& limits,
                const NoiseTermsOptions& o) {
  const std::size_t points = d.size();
  NoiseTerm t;
  t.kind = Kind(k);
  t.in_model = k == static_cast<int>(NoiseTermKind::kQuantisation) ? o.quantisation
               : k == static_cast<int>(NoiseTermKind::kRamp)       ? o.rate_ramp
                                                                    : true;
  t.fitted = std::sqrt(s.c[k]);
  t.upper_bound = kNaN;
  t.chi2_rise = kNaN;
  double bound = std::numeric_limits<double>::infinity();
  std::size_t run_begin = 0, run_length = 0, best_begin = 0, best_length = 0;
  for (std::size_t i = 0; i < points; ++i) {
    const double tau = d.tau()[i];
    const double b = limits.upper_avar[i] / d.shape(i)[k];
    if (b < bound) {
      bound = b;
      t.bound_tau_s = tau;
    }
    const bool dominant = s.c[k] > 0.0 && Dominant(s.c, d.shape(i)) == k;
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
    const Coefficients c = FitInLogs(d, without, o.max_iterations).c;
    const double decades = std::log10(d.tau().back() / d.tau().front());
    const double per_decade =
        decades > 0.0 ? std::max(1.0, static_cast<double>(points - 1) / decades) : 1.0;
    t.chi2_rise = (LogCost(d, s.edf, c) - s.chi2) / per_decade;
    t.resolved = t.chi2_rise > limits.resolving_rise;
  }
  if (t.resolved) {
    t.tau_min_s = d.tau()[best_begin];
    t.tau_max_s = d.tau()[best_begin + best_length - 1];
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
  FitData data(a, points, o.gauss_markov_time_s);
  const FitState s = FitInLogs(data, Enabled(o), o.max_iterations);
  const Limits limits = MakeLimits(data, s, o);
  NoiseFit fit;
  fit.gauss_markov_time_s = o.gauss_markov_time_s;
  for (int k = 0; k < kNoiseTermCount; ++k) fit.terms[k] = Judge(k, data, s, limits, o);
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

// plumb/signal/noise_terms.h — the IEEE Std 952 / 1293 noise terms of a sensor axis, fitted to
// its overlapping Allan deviation (allan.h), and the noise of a session's still data.
//
// The terms and their Allan variance (IEEE Std 952-1997 annex C; El-Sheimy et al. 2008), for
// samples in unit u (m/s^2 or rad/s):
//   Q  quantisation                 AVAR = 3 Q^2 / tau^2         Q in u s        slope -1
//   N  angle / velocity random walk AVAR = N^2 / tau             N in u/sqrt(Hz) slope -1/2
//      (white noise density; the per-sample sigma is N / sqrt(dt))
//   B  bias instability             AVAR = (2 ln 2 / pi) B^2     B in u          slope 0
//      (flicker noise of two-sided density B^2 / (2 pi f); the floor ADEV = 0.664 B)
//   K  rate / acceleration random walk AVAR = K^2 tau / 3        K in u/sqrt(s)  slope +1/2
//      (= u/s/sqrt(Hz); the bias moves by K sqrt(dt) per sample)
//   R  rate ramp                    AVAR = R^2 tau^2 / 2         R in u/s        slope +1
// Slopes are of ADEV against tau on log-log axes. The terms are independent, so their Allan
// variances add.
//
// The method: weighted least squares with non-negative coefficients (the least-squares fit
// of IEEE Std 952 annex C). The model is linear in c = (Q^2, N^2, B^2, K^2, R^2):
// AVAR(tau) = sum_k c_k f_k(tau). The estimate AVAR_j at each fitted point is a chi-square
// variable with edf_j degrees of freedom (allan.h's table, for the noise type of the term that
// dominates the model there), so ln AVAR_j has variance about 2 / edf_j and the cost is
//   chi2 = sum_j (edf_j / 2) (ln AVAR_j - ln model_j)^2,
// minimised over c >= 0 by Gauss-Newton: each pass solves the linearised problem -- fit
// model_j (1 + ln(AVAR_j / model_j)) with weights edf_j / (2 model_j^2) -- exactly under
// c >= 0 (every subset of the terms solved by column-pivoted QR on scaled columns, the
// cheapest with no negative coefficient kept), halves the step while the log cost rises, and
// updates the noise types and EDF, until the coefficients and the types settle (at most
// max_iterations passes; the first pass, from the measured AVAR, is the relative-error fit).
// Logs, because a relative-error cost is bounded below the data (-1) and not above it, and
// would let a misfitting model float over a curve that is not made of these terms. Why this
// and not slope lines at -1, -1/2, 0, +1/2: a slope line reads one term where it alone shapes
// the curve, and says nothing where two terms overlap (a short still record, the usual case:
// the white and random-walk lines cross before the flat part shows); the sum of all terms
// fitted to every point uses the whole curve, weighs each point by what it knows (its EDF),
// and gives the same answer as the slope lines where those apply. Neighbouring points share
// data, so chi2 is a goodness-of-fit number, not a chi-square test.
//
// Resolved or upper bound. A term is resolved when (a) it is the largest term of the fitted
// model at min_points or more consecutive fitted points, and (b) leaving it out makes the fit
// worse beyond chance: the best fit without it (same method) raises chi2 by more than the
// chi-square(1) quantile at term_confidence, after dividing the rise by the fitted points per
// decade of tau. The division is the points' correlation: overlapping estimates at
// neighbouring taus share their data (about one per octave is independent for white noise,
// Schlossberger and Howe 2019, fewer where a random walk dominates), and counting a decade as
// one observation kept every absent term unresolved in simulated white, flicker, random-walk
// and quantisation records (30 each) while the present ones were resolved. Its value is then
// sqrt(c_k) and its tau range that run of points. Otherwise the data only bounds it: a term's
// AVAR never exceeds the total, so at every fitted point c_k <= AVAR_j edf_j / chi2_a(edf_j) /
// f_k(tau_j) with a = (1 - term_confidence) / P over the P fitted points (Bonferroni: the
// smallest of P per-point limits still holds at term_confidence); the smallest of these,
// square-rooted, is the upper bound, read at one tau. The bound is computed for every term,
// resolved or not.
//
// A misfit (chi2 above misfit_chi2_per_point per fitted point: the curve is not made of these
// terms) resolves no term; the upper bounds, which need no model, stand.
//
// Several still segments: AnalyseStillNoise pools them per axis (allan.h: each segment gives
// the clusters that fit inside it; none across its ends), fits the terms, and sets the
// intervals of the Allan deviation for the noise type the fit found at each tau.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/jobs.h"
#include "plumb/core/segment.h"
#include "plumb/signal/allan.h"
#include "plumb/signal/axis_view.h"

namespace plumb::signal {

/// The terms, in the order of their slopes.
enum class NoiseTermKind { kQuantisation, kWhite, kBiasInstability, kRandomWalk, kRamp };
inline constexpr int kNoiseTermCount = 5;

/// "Q", "N", "B", "K", "R".
const char* NoiseTermSymbol(NoiseTermKind kind);
/// AVAR of the term with a unit coefficient at tau_s > 0: 3 / tau^2, 1 / tau, 2 ln2 / pi,
/// tau / 3, tau^2 / 2 (s^-2, s^-1, 1, s, s^2).
double NoiseTermShape(NoiseTermKind kind, double tau_s);
/// The power-law noise whose EDF is used where the term dominates (rate ramp: random-walk FM,
/// the fewest EDF of the table; a ramp is not a noise).
PowerLawNoise NoiseTermNoise(NoiseTermKind kind);

struct NoiseTermsOptions {
  /// Shortest cluster time fitted, s, >= 0; 0: from the first point. Raise it to skip the
  /// short taus of a low-pass filtered output (ADEV below the white line there).
  double tau_min_s = 0.0;
  /// Longest cluster time fitted, s, >= 0; 0: no limit but min_edf.
  double tau_max_s = 0.0;
  /// Points whose white-FM EDF is below this are not fitted (the last ones: about a third of
  /// the longest record and beyond for 2), >= 1.
  double min_edf = 2.0;
  bool quantisation = true;  ///< the model has Q (otherwise only its bound is reported)
  /// The model has R (otherwise only its bound is reported). Off by default: at the longest
  /// taus, where a still record has few degrees of freedom, a ramp (slope +1) and a random
  /// walk (+1/2) trade places, and K, which Kalibr and filters need, comes out unresolved
  /// more often (simulated white + flicker + random walk, four hours: K resolved in 30 of 30
  /// records without R, 25 of 30 with it; one random walk of 30 was called a ramp).
  bool rate_ramp = false;
  /// Consecutive fitted points at which a term must be the largest to be resolved, >= 1.
  int min_points = 3;
  /// Confidence of the resolved test and of the upper bounds, in (0.5, 1).
  double term_confidence = 0.95;
  /// Gauss-Newton passes, >= 1.
  int max_iterations = 20;
  /// A fit whose chi2 exceeds this many per fitted point is a misfit: the curve is not made of
  /// these terms (motion or vibration in the "still" data, a low-pass filter at the short
  /// taus: raise tau_min_s, temperature steps), and no term is called resolved; > 0. Fits of
  /// simulated still records (white, flicker, random walk, quantisation, their sums; 180
  /// records) stayed below 3.3 per point, of tomisuarez2's 449 s still record below 1.
  double misfit_chi2_per_point = 10.0;
  /// > 0: the instability term is a first-order Gauss-Markov process of this correlation
  /// time, s (GaussMarkovAvarShape; its level the process's sigma) instead of IEEE's flicker
  /// floor B: the process the estimator's bias wander has (estimation/wander_levels.h), whose
  /// sigma the flicker floor does not give where a random walk hides the floor.
  double gauss_markov_time_s = 0.0;
};

struct NoiseTerm {
  NoiseTermKind kind = NoiseTermKind::kWhite;
  bool in_model = false;  ///< the fit had the term (Q and R can be left out)
  double fitted = 0.0;    ///< the fit's coefficient sqrt(c_k), >= 0, unit of the term
  bool resolved = false;  ///< see the header
  /// Resolved: the run of fitted points where the term dominates, s; otherwise the tau of the
  /// upper bound (both ends equal).
  double tau_min_s = 0.0, tau_max_s = 0.0;
  /// The rise of chi2 without the term, per decade of points (the resolved test); NaN when
  /// the term does not dominate min_points points.
  double chi2_rise = 0.0;
  double upper_bound = 0.0;  ///< the smallest per-point bound, unit of the term
  double bound_tau_s = 0.0;  ///< where it was read, s
  /// What is reported: the fitted value when resolved, else the upper bound.
  double value() const { return resolved ? fitted : upper_bound; }
};

struct NoiseFit {
  std::array<NoiseTerm, kNoiseTermCount> terms;  ///< indexed by NoiseTermKind
  std::size_t first = 0;  ///< first fitted point (index into the AllanDeviation)
  std::size_t last = 0;   ///< last fitted point, inclusive
  /// Per point of the AllanDeviation: the noise type of the term that dominates the model
  /// there (outside the fitted range, that of the nearest fitted point).
  std::vector<PowerLawNoise> noise;
  double chi2 = 0.0;    ///< the log cost at the solution (see the header)
  int dof = 0;          ///< fitted points minus nonzero coefficients
  int iterations = 0;   ///< passes made
  bool misfit = false;  ///< chi2 above misfit_chi2_per_point per point: nothing resolved
  /// The options' gauss_markov_time_s: > 0, the instability term was a Gauss-Markov process.
  double gauss_markov_time_s = 0.0;
  std::size_t points() const { return last + 1 - first; }
  const NoiseTerm& term(NoiseTermKind kind) const { return terms[static_cast<int>(kind)]; }
  /// The fitted model's Allan variance at tau_s > 0, unit^2.
  double Avar(double tau_s) const;
};

/// Fits the terms to `adev` (its record_sizes set the EDF). Throws plumb::Error for options out
/// of range, InsufficientDataError when fewer than 2 points lie in the fitted range.
NoiseFit FitNoiseTerms(const AllanDeviation& adev, const NoiseTermsOptions& options = {});

/// The Allan variance of a first-order Gauss-Markov process of unit steady-state sigma and
/// correlation time tau_c_s > 0 at cluster time tau_s > 0 (x = tau / tau_c):
///   AVAR = (1 / x) [2 - (1 / x) (3 - 4 e^-x + e^-2x)]
/// (Gelb; El-Sheimy et al. 2008). About 2 x / 3 for x << 1 (a random walk with
/// K^2 = 2 / tau_c), largest, 0.6174^2, at x = 1.89, and 2 / x for x >> 1 (white noise).
double GaussMarkovAvarShape(double tau_s, double tau_c_s);

struct StillNoiseOptions {
  /// Cluster sizes or density and the confidence of the intervals; its `noise` is replaced per
  /// point by the fit's.
  AllanOptions allan;
  NoiseTermsOptions terms;
};

/// One axis of one sensor.
struct AxisNoise {
  Sensor sensor = Sensor::kAccel;
  int axis = 0;         ///< 0 x, 1 y, 2 z
  AllanDeviation adev;  ///< pooled over the segments, intervals for the fitted noise types
  NoiseFit fit;
};

struct StillNoise {
  std::vector<StillSegment> segments;  ///< the segments pooled (not turning, 2 samples or more)
  std::size_t samples = 0;             ///< samples pooled per axis
  double dt_s = 0.0;                   ///< sample interval (median of the series), s
  double still_s = 0.0;                ///< samples * dt_s, s
  double longest_s = 0.0;              ///< the longest segment, s
  std::string acc_unit, gyr_unit;      ///< units of the samples
  std::vector<AxisNoise> axes;  ///< accelerometer x, y, z, then gyroscope x, y, z when present
  std::vector<std::string> notes;  ///< segments left out and why
  StillNoiseOptions options;       ///< as analysed
  /// The axis, or nullptr when the session has no such sensor.
  const AxisNoise* Find(Sensor sensor, int axis) const;
};

/// The noise of the still data of `series`: the segments `segments` pooled per axis, the
/// Allan deviation with intervals and the fitted terms. Segments that turn at a stated rate or
/// have fewer than 2 samples are left out (noted). Throws InsufficientDataError when the
/// longest remaining segment has fewer than 8 samples, plumb::Error for a series without a
/// sample interval or options out of range. The axes are analysed at once through `run_jobs`
/// when it is given (core/jobs.h); the result is the same either way.
StillNoise AnalyseStillNoise(const ImuSeries& series, const std::vector<StillSegment>& segments,
                             const StillNoiseOptions& options = {},
                             const JobRunner& run_jobs = {});

}  // namespace plumb::signal

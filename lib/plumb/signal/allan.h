// plumb/signal/allan.h — overlapping Allan deviation of a uniformly sampled series, of one
// record or pooled over several (the still segments of a session), with confidence intervals.
//
// For samples x_i (i = 0..n-1) at interval dt, the integral theta_k = dt sum_{i<k} x_i
// (k = 0..n) and a cluster of m samples (tau = m dt):
//   AVAR(tau) = sum_{k=0}^{n-2m} (theta_{k+2m} - 2 theta_{k+m} + theta_k)^2
//               / (2 tau^2 (n + 1 - 2m)),
// the fully overlapping estimator (IEEE Std 952, annex C; NIST SP 1065 eq. 14). White noise
// of standard deviation sigma gives ADEV = sigma / sqrt(m); a random walk whose steps have
// standard deviation q gives ADEV = q sqrt(m / 3). The cost is O(n) per cluster size. The
// integral is formed in double after subtracting the first sample (AVAR ignores a constant
// offset).
//
// Several records (pooled). At cluster size m every record of n_k >= 2m samples contributes
// its own n_k + 1 - 2m second differences, none across a record's ends (a gap or a turn
// between still segments is never differenced); AVAR is the sum of all their squares over
// 2 tau^2 times their count. A constant offset per record (another pose's gravity or Earth
// rate) drops out. Records shorter than 2m give nothing at that m.
//
// Confidence intervals (NIST SP 1065 section 5.3, "chi-squared confidence intervals"): an
// AVAR estimate s^2 with `edf` equivalent degrees of freedom has edf s^2 / AVAR ~ chi^2(edf),
// so the two-sided interval at confidence c is
//   ADEV in [ s sqrt(edf / chi2_{(1+c)/2}(edf)),  s sqrt(edf / chi2_{(1-c)/2}(edf)) ]
// with the exact chi-square quantile (Boost.Math, chi_square.h). The EDF of the overlapping
// estimator is the simple approximation of Howe, Allan and Barnes (1981) tabulated in NIST SP
// 1065 Table 5 (Stein 1985), for N = n + 1 phase points (integral samples) and the noise type
// that dominates at that tau:
//   white PM    (quantisation)     (N+1)(N-2m) / (2(N-m))
//   flicker PM                     exp( sqrt( ln((N-1)/(2m)) ln((2m+1)(N-1)/4) ) )
//   white FM    (white rate noise) (3(N-1)/(2m) - 2(N-2)/N) 4m^2 / (4m^2+5)
//   flicker FM  (bias instability) 2(N-2)^2 / (2.3N-4.9) for m = 1; 5N^2 / (4m(N+3m)) else
//   random walk FM (rate walk)     (N-2) / (m (N-3)^2) ((N-1)^2 - 3m(N-1) + 4m^2)
// floored at 1 (one second difference at m = n/2, where the formulas give about 1). Pooled
// records: each record's estimate is a chi-square variable scaled by its share w_k =
// terms_k / terms of the second differences, so the pool's EDF is Satterthwaite's
// 1 / sum_k (w_k^2 / edf_k) (one record: its own EDF; K equal records: K times it).
// (The flicker-FM entry at m = 1 has (N-2)^2, as in Stein's table; a transcription without the
// square, found in some libraries, gives an EDF below 1.) Greenhall and Riley's EDF algorithm
// (2003), which Stable32 uses, is not implemented. The intervals' coverage is checked by
// simulation (tests/signal/allan_test.cc: white noise and random walk, one-sigma intervals
// hold the truth 68 % of the time within the binomial spread). The default interval is one
// sigma (c = 0.6827) for the white-FM EDF; callers that know the dominant noise per tau (the
// noise-term fit, noise_terms.h) set it with SetAllanIntervals.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "plumb/signal/axis_view.h"

namespace plumb::signal {

/// The power-law noise type an EDF assumes, with the IMU term that produces it (IEEE Std 952
/// annex C) and the log-log slope of ADEV against tau.
enum class PowerLawNoise {
  kWhitePhase,          ///< white PM, alpha = +2: quantisation; slope -1
  kFlickerPhase,        ///< flicker PM, alpha = +1; slope about -1
  kWhiteFrequency,      ///< white FM, alpha = 0: angle / velocity random walk; slope -1/2
  kFlickerFrequency,    ///< flicker FM, alpha = -1: bias instability; slope 0
  kRandomWalkFrequency  ///< random-walk FM, alpha = -2: rate random walk; slope +1/2
};

/// Short name: "white PM", "flicker PM", "white FM", "flicker FM", "random-walk FM".
const char* PowerLawNoiseName(PowerLawNoise noise);

/// One sigma of the normal distribution as a two-sided probability, erf(1 / sqrt 2).
inline constexpr double kOneSigmaConfidence = 0.68268949213708585;

struct AllanOptions {
  /// Cluster sizes m, samples, each in [1, n / 2] (n: the longest record); sorted and
  /// deduplicated. Empty: log-spaced, m = round(10^(j / points_per_decade)) for j = 0, 1, ...
  /// while m <= n / 2.
  std::vector<std::size_t> cluster_sizes;
  /// Density of the automatic log spacing, points per decade of tau, [1, 100].
  int points_per_decade = 10;
  /// Two-sided confidence of the intervals adev_lower..adev_upper, in (0, 1).
  double confidence = kOneSigmaConfidence;
  /// The noise type the intervals' EDF assumes at every tau (SetAllanIntervals changes it
  /// per point).
  PowerLawNoise noise = PowerLawNoise::kWhiteFrequency;
};

struct AllanDeviation {
  std::vector<std::size_t> cluster_size;  ///< m, samples
  std::vector<double> tau_s;              ///< cluster time m dt, s
  std::vector<double> adev;               ///< overlapping Allan deviation, units of x
  std::vector<std::size_t> terms;         ///< second differences averaged, sum of n_k + 1 - 2m
  std::vector<double> edf;                ///< equivalent degrees of freedom of AVAR, >= 1
  std::vector<PowerLawNoise> noise;       ///< the noise type each point's EDF assumes
  std::vector<double> adev_lower;         ///< lower end of the interval, units of x
  std::vector<double> adev_upper;         ///< upper end of the interval, units of x
  double confidence = 0.0;                ///< two-sided confidence of the intervals
  std::vector<std::size_t> record_sizes;  ///< samples of each record pooled, in input order
  double dt_s = 0.0;                      ///< sample interval, s
};

/// EDF of the overlapping AVAR at cluster size m of one record of n samples (the table above,
/// N = n + 1), floored at 1. Throws plumb::Error unless 1 <= m <= n / 2.
double OverlappingAllanEdf(std::size_t n, std::size_t m, PowerLawNoise noise);

/// EDF of the pooled AVAR at cluster size m (Satterthwaite over the records with n_k >= 2m).
/// Throws plumb::Error when no record has 2m samples.
double PooledAllanEdf(const std::vector<std::size_t>& record_sizes, std::size_t m,
                      PowerLawNoise noise);

/// Two-sided chi-square interval {lower, upper} of a deviation `adev` whose variance has
/// `edf` degrees of freedom, at `confidence` in (0, 1). Throws plumb::Error for edf <= 0 or a
/// confidence out of range.
std::pair<double, double> AllanInterval(double adev, double edf, double confidence);

/// Overlapping Allan deviation of `x` sampled every `dt_s` seconds, with intervals. Throws
/// plumb::Error if dt_s is not positive and finite, x has fewer than 2 samples, a given
/// cluster size is 0 or above n / 2, points_per_decade or confidence is out of range.
AllanDeviation OverlappingAllanDeviation(const AxisView& x, double dt_s,
                                         const AllanOptions& options = {});

/// The pooled overlapping Allan deviation of several records of the same quantity sampled
/// every `dt_s` seconds (above). Records of fewer than 2 samples are ignored; cluster sizes go
/// up to half the longest record. Throws plumb::Error as above, and when no record has 2
/// samples.
AllanDeviation PooledAllanDeviation(const std::vector<AxisView>& records, double dt_s,
                                    const AllanOptions& options = {});

/// PooledAllanDeviation without the intervals (edf, noise, adev_lower, adev_upper empty and
/// confidence 0), for a caller that sets them with SetAllanIntervals once it knows each
/// point's noise type (AnalyseStillNoise). Throws as PooledAllanDeviation does.
AllanDeviation PooledAllanPoints(const std::vector<AxisView>& records, double dt_s,
                                 const AllanOptions& options = {});

/// Recomputes edf, noise and the intervals of `adev` for the noise type of each point
/// (`noise`, one per point) at `confidence`. Throws plumb::Error when the sizes differ or the
/// confidence is not in (0, 1).
void SetAllanIntervals(AllanDeviation& adev, const std::vector<PowerLawNoise>& noise,
                       double confidence);

}  // namespace plumb::signal

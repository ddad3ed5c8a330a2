#include "plumb/signal/noise_terms.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "noise.h"
#include "plumb/core/error.h"

namespace plumb::signal {
namespace {

constexpr double kDt = 0.1;  // 10 Hz: long records at little cost

/// The IEEE terms' true levels of a simulated axis (0: absent).
struct Levels {
  double q = 0.0;  // quantisation, u s
  double n = 0.0;  // white noise density, u / sqrt(Hz)
  double b = 0.0;  // bias instability, u
  double k = 0.0;  // random walk, u / sqrt(s)
};

/// `samples` samples every kDt of white noise N, flicker B (noise.h: Gauss-Markov octaves from
/// kDt / 2 to 1e5 s), a bias random walk K (steps K sqrt(dt)) and quantisation Q (the
/// difference of a white angle error e of sigma Q, over dt: AVAR = 3 Q^2 / tau^2 exactly).
std::vector<float> Simulate(std::uint64_t seed, std::size_t samples, const Levels& l) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> e(0.0, 1.0);
  const std::vector<double> flicker =
      l.b > 0 ? testing::FlickerNoise(seed + 1, samples, kDt, l.b, kDt / 2, 1e5)
              : std::vector<double>(samples, 0.0);
  std::vector<float> x(samples);
  double bias = 0.0, angle_error = l.q * e(rng);
  for (std::size_t i = 0; i < samples; ++i) {
    const double next_error = l.q * e(rng);
    bias += l.k * std::sqrt(kDt) * e(rng);
    x[i] = static_cast<float>(l.n / std::sqrt(kDt) * e(rng) + flicker[i] + bias +
                              (next_error - angle_error) / kDt);
    angle_error = next_error;
  }
  return x;
}

/// The true Allan deviation of `l` at tau.
double TrueAdev(const Levels& l, double tau) {
  return std::sqrt(l.q * l.q * NoiseTermShape(NoiseTermKind::kQuantisation, tau) +
                   l.n * l.n * NoiseTermShape(NoiseTermKind::kWhite, tau) +
                   l.b * l.b * NoiseTermShape(NoiseTermKind::kBiasInstability, tau) +
                   l.k * l.k * NoiseTermShape(NoiseTermKind::kRandomWalk, tau));
}

struct Analysed {
  AllanDeviation adev;
  NoiseFit fit;
};

Analysed Analyse(const std::vector<float>& x, const NoiseTermsOptions& options = {},
                 double confidence = 0.95) {
  Analysed a;
  a.adev = OverlappingAllanDeviation(ViewContiguous(x.data(), x.size()), kDt);
  a.fit = FitNoiseTerms(a.adev, options);
  SetAllanIntervals(a.adev, a.fit.noise, confidence);
  return a;
}

/// Fraction of the fitted points from tau_from_s on whose interval holds the true curve.
double FractionInside(const Analysed& a, const Levels& l, double tau_from_s) {
  int inside = 0, count = 0;
  for (std::size_t j = a.fit.first; j <= a.fit.last; ++j) {
    if (a.adev.tau_s[j] < tau_from_s) continue;
    const double truth = TrueAdev(l, a.adev.tau_s[j]);
    inside += a.adev.adev_lower[j] <= truth && truth <= a.adev.adev_upper[j] ? 1 : 0;
    ++count;
  }
  return count > 0 ? static_cast<double>(inside) / count : 0.0;
}

const NoiseTerm& Term(const Analysed& a, NoiseTermKind kind) { return a.fit.term(kind); }

// ---- (b) one noise at a time: the curve within its intervals, the level recovered ------------

TEST(NoiseTerms, WhiteNoiseGivesNAndBoundsTheRest) {
  const Levels l{0.0, 1e-3, 0.0, 0.0};
  const Analysed a = Analyse(Simulate(1, 36000, l));  // one hour
  // 95 % intervals (for the white-FM EDF the fit found): most points hold the truth (they are
  // correlated, so the fraction scatters more than a binomial one: 0.6 to 1 over seeds).
  EXPECT_GE(FractionInside(a, l, 0.0), 0.6);
  const NoiseTerm& n = Term(a, NoiseTermKind::kWhite);
  EXPECT_TRUE(n.resolved);
  EXPECT_NEAR(n.value() / l.n, 1.0, 0.02);
  EXPECT_DOUBLE_EQ(n.tau_min_s, kDt);
  EXPECT_GT(n.tau_max_s, 100.0);
  for (NoiseTermKind absent : {NoiseTermKind::kQuantisation, NoiseTermKind::kBiasInstability,
                               NoiseTermKind::kRandomWalk, NoiseTermKind::kRamp}) {
    const NoiseTerm& t = Term(a, absent);
    EXPECT_FALSE(t.resolved) << NoiseTermSymbol(absent);
    EXPECT_GT(t.upper_bound, 0.0) << NoiseTermSymbol(absent);
    EXPECT_EQ(t.value(), t.upper_bound);
    EXPECT_EQ(t.tau_min_s, t.bound_tau_s);
  }
  EXPECT_FALSE(Term(a, NoiseTermKind::kRamp).in_model);  // R only when asked
  EXPECT_TRUE(Term(a, NoiseTermKind::kQuantisation).in_model);
  // B's bound is read where the white curve is lowest, the longest taus, and lies within a
  // factor 5 of what that curve would give as a floor there.
  const NoiseTerm& b = Term(a, NoiseTermKind::kBiasInstability);
  EXPECT_GT(b.bound_tau_s, 100.0);
  EXPECT_LT(b.upper_bound, 5.0 * TrueAdev(l, b.bound_tau_s) /
                               std::sqrt(NoiseTermShape(NoiseTermKind::kBiasInstability, 1.0)));
}

TEST(NoiseTerms, RandomWalkGivesK) {
  const Levels l{0.0, 0.0, 0.0, 8e-5};
  const Analysed a = Analyse(Simulate(2, 36000, l));
  // A random walk's Allan deviations at all taus move together: the fraction scatters widely.
  EXPECT_GE(FractionInside(a, l, 1.0), 0.5);
  const NoiseTerm& k = Term(a, NoiseTermKind::kRandomWalk);
  EXPECT_TRUE(k.resolved);
  EXPECT_NEAR(k.value() / l.k, 1.0, 0.1);
  EXPECT_FALSE(Term(a, NoiseTermKind::kWhite).resolved);
}

TEST(NoiseTerms, FlickerGivesB) {
  const Levels l{0.0, 0.0, 1e-3, 0.0};
  NoiseTermsOptions options;
  options.tau_min_s = 1.0;  // the simulated 1/f band starts at dt / 2: flat from 10 samples on
  const Analysed a = Analyse(Simulate(3, 36000, l), options);
  EXPECT_GE(FractionInside(a, l, 1.0), 0.6);
  // The flat floor: ADEV = sqrt(2 ln 2 / pi) B = 0.664 B.
  EXPECT_NEAR(TrueAdev(l, 10.0) / l.b, 0.6643, 1e-4);
  const NoiseTerm& b = Term(a, NoiseTermKind::kBiasInstability);
  EXPECT_TRUE(b.resolved);
  EXPECT_NEAR(b.value() / l.b, 1.0, 0.08);
  EXPECT_GE(b.tau_min_s, 1.0);
}

TEST(NoiseTerms, QuantisationGivesQ) {
  const Levels l{2e-4, 1e-4, 0.0, 0.0};  // Q dominates below tau = 3 Q^2 / N^2 = 12 s
  const Analysed a = Analyse(Simulate(4, 36000, l));
  EXPECT_GE(FractionInside(a, l, 0.0), 0.6);
  const NoiseTerm& q = Term(a, NoiseTermKind::kQuantisation);
  EXPECT_TRUE(q.resolved);
  EXPECT_NEAR(q.value() / l.q, 1.0, 0.02);
  EXPECT_DOUBLE_EQ(q.tau_min_s, kDt);
  EXPECT_TRUE(Term(a, NoiseTermKind::kWhite).resolved);
  EXPECT_NEAR(Term(a, NoiseTermKind::kWhite).value() / l.n, 1.0, 0.1);
}

// ---- (c) the sum: N, B and K each read where it dominates -------------------------------------

TEST(NoiseTerms, FitRecoversNBAndKFromTheirSum) {
  // Crossings: N^2 / tau = 0.44 B^2 at 2.3 s, 0.44 B^2 = K^2 tau / 3 at 206 s; four hours.
  const Levels l{0.0, 1e-3, 1e-3, 8e-5};
  const Analysed a = Analyse(Simulate(5, 144000, l));
  EXPECT_GE(FractionInside(a, l, 1.0), 0.6);
  const NoiseTerm& n = Term(a, NoiseTermKind::kWhite);
  const NoiseTerm& b = Term(a, NoiseTermKind::kBiasInstability);
  const NoiseTerm& k = Term(a, NoiseTermKind::kRandomWalk);
  ASSERT_TRUE(n.resolved);
  ASSERT_TRUE(b.resolved);
  ASSERT_TRUE(k.resolved);
  // The spread over seeds: N a few per cent, B under 10 %, K about 20 % (one sigma): K is read
  // from the longest taus, where four hours give few degrees of freedom.
  EXPECT_NEAR(n.value() / l.n, 1.0, 0.05);
  EXPECT_NEAR(b.value() / l.b, 1.0, 0.15);
  EXPECT_NEAR(k.value() / l.k, 1.0, 0.5);
  // Each from its own stretch of taus, in the order of the slopes.
  EXPECT_LT(n.tau_max_s, b.tau_min_s);
  EXPECT_LT(b.tau_max_s, k.tau_min_s);
  EXPECT_GT(k.tau_max_s, 1000.0);
  EXPECT_FALSE(Term(a, NoiseTermKind::kQuantisation).resolved);
  // The model passes through the data: a reasonable cost per point.
  EXPECT_LT(a.fit.chi2 / a.fit.points(), 3.0);
  EXPECT_NEAR(std::sqrt(a.fit.Avar(10.0)) / TrueAdev(l, 10.0), 1.0, 0.05);
}

TEST(NoiseTerms, RateRampWhenAsked) {
  // A bias ramp of R = 1e-5 u/s on white noise: AVAR = R^2 tau^2 / 2.
  const Levels l{0.0, 1e-3, 0.0, 0.0};
  std::vector<float> x = Simulate(6, 36000, l);
  const double r = 1e-5;
  for (std::size_t i = 0; i < x.size(); ++i) x[i] += static_cast<float>(r * kDt * i);
  NoiseTermsOptions options;
  options.rate_ramp = true;
  const Analysed a = Analyse(x, options);
  const NoiseTerm& ramp = Term(a, NoiseTermKind::kRamp);
  EXPECT_TRUE(ramp.in_model);
  EXPECT_TRUE(ramp.resolved);
  EXPECT_NEAR(ramp.value() / r, 1.0, 0.1);
}

// ---- Options, data and the session's still segments -------------------------------------------

TEST(NoiseTerms, GaussMarkovShapeHasItsLimits) {
  // Short taus: a random walk of K^2 = 2 / tau_c (AVAR 2 x / 3); the peak 0.6174^2 near
  // x = 1.89 (0.6174 sigma); long taus: white noise 2 / x.
  EXPECT_NEAR(GaussMarkovAvarShape(1e-4, 1.0) / (2e-4 / 3.0), 1.0, 1e-3);
  EXPECT_NEAR(GaussMarkovAvarShape(1e-2, 1.0) / (2e-2 / 3.0), 1.0, 1e-2);
  double peak = 0.0, at = 0.0;
  for (double x = 0.5; x < 5.0; x += 1e-3) {
    if (GaussMarkovAvarShape(x, 1.0) > peak) {
      peak = GaussMarkovAvarShape(x, 1.0);
      at = x;
    }
  }
  EXPECT_NEAR(std::sqrt(peak), 0.6174, 1e-4);
  EXPECT_NEAR(at, 1.89, 0.01);
  EXPECT_NEAR(GaussMarkovAvarShape(1e4, 1.0) / 2e-4, 1.0, 1e-3);
  // Continuous across the series' threshold x = 1e-3.
  EXPECT_NEAR(GaussMarkovAvarShape(0.999e-3, 1.0) / 0.999e-3,
              GaussMarkovAvarShape(1.001e-3, 1.0) / 1.001e-3, 1e-6);
}

TEST(NoiseTerms, AGaussMarkovInstabilityGivesItsSigma) {
  // White noise with a Gauss-Markov bias of sigma 2e-3 and correlation time 20 s, 10 hours at
  // 10 Hz; fitted with the instability as that process (gauss_markov_time_s, the estimator's
  // own, estimation/wander_levels.h): its sigma resolved within 20 %. The flicker floor's B,
  // fitted to the same curve, is not that sigma.
  constexpr double kSigma = 2e-3, kTime = 20.0;
  std::mt19937_64 rng(31);
  std::normal_distribution<double> e(0.0, 1.0);
  const double phi = std::exp(-kDt / kTime);
  std::vector<float> x(360000);
  double b = 0.0;
  for (float& v : x) {
    b = phi * b + kSigma * std::sqrt(1.0 - phi * phi) * e(rng);
    v = static_cast<float>(b + 1e-3 / std::sqrt(kDt) * e(rng));
  }
  NoiseTermsOptions gm;
  gm.gauss_markov_time_s = kTime;
  const Analysed a = Analyse(x, gm);
  const NoiseTerm& s = Term(a, NoiseTermKind::kBiasInstability);
  EXPECT_TRUE(s.resolved);
  EXPECT_NEAR(s.fitted / kSigma, 1.0, 0.2);
  EXPECT_FALSE(Term(a, NoiseTermKind::kRandomWalk).resolved);
  EXPECT_DOUBLE_EQ(a.fit.gauss_markov_time_s, kTime);
  EXPECT_NEAR(a.fit.Avar(40.0) / (kSigma * kSigma * GaussMarkovAvarShape(40.0, kTime) +
                                  1e-6 / 40.0), 1.0, 0.25);
}

TEST(NoiseTerms, RejectsBadOptionsAndTooFewPoints) {
  const std::vector<float> x = Simulate(7, 1000, Levels{0.0, 1e-3, 0.0, 0.0});
  const AllanDeviation ad = OverlappingAllanDeviation(ViewContiguous(x.data(), x.size()), kDt);
  NoiseTermsOptions bad;
  bad.term_confidence = 0.4;
  EXPECT_THROW(FitNoiseTerms(ad, bad), Error);
  bad = NoiseTermsOptions{};
  bad.min_points = 0;
  EXPECT_THROW(FitNoiseTerms(ad, bad), Error);
  NoiseTermsOptions narrow;
  narrow.tau_min_s = 5.0;
  narrow.tau_max_s = 5.5;
  EXPECT_THROW(FitNoiseTerms(ad, narrow), InsufficientDataError);
}

ImuSeries StillSeries(std::size_t samples) {
  ImuSeries s;
  std::mt19937_64 rng(8);
  std::normal_distribution<float> e(0.0F, 1.0F);
  for (std::size_t i = 0; i < samples; ++i) {
    s.t_s.push_back(100.0 + kDt * i);
    s.acc.push_back(Vec3f(0.01F * e(rng), 0.01F * e(rng), -9.8F + 0.01F * e(rng)));
    s.gyr.push_back(Vec3f(0.001F * e(rng), 0.001F * e(rng), 0.001F * e(rng)));
  }
  return s;
}

TEST(StillNoise, PoolsTheStillSegmentsPerAxis) {
  const ImuSeries series = StillSeries(20000);
  StillSegment a, b, turning, tiny;
  a.begin = 0, a.end = 8000, a.label = "a";
  b.begin = 9000, b.end = 12000, b.label = "b";
  turning.begin = 13000, turning.end = 16000, turning.label = "turntable";
  turning.known_omega_eb_b = Vec3(0.0, 0.0, 1.0);
  tiny.begin = 17000, tiny.end = 17001, tiny.label = "tiny";
  const StillNoise noise = AnalyseStillNoise(series, {a, b, turning, tiny});
  ASSERT_EQ(noise.segments.size(), 2U);
  EXPECT_EQ(noise.samples, 11000U);
  EXPECT_NEAR(noise.dt_s, kDt, 1e-9);
  EXPECT_NEAR(noise.still_s, 1100.0, 1e-6);
  EXPECT_NEAR(noise.longest_s, 800.0, 1e-6);
  EXPECT_EQ(noise.notes.size(), 2U);  // the turning and the one-sample segments
  ASSERT_EQ(noise.axes.size(), 6U);
  const AxisNoise* gz = noise.Find(Sensor::kGyro, 2);
  ASSERT_NE(gz, nullptr);
  EXPECT_EQ(gz->adev.record_sizes, (std::vector<std::size_t>{8000, 3000}));
  EXPECT_EQ(gz->adev.cluster_size.back(), 3981U);  // 10^3.6, the last point <= 4000
  EXPECT_NEAR(gz->fit.term(NoiseTermKind::kWhite).value() / (0.001 * std::sqrt(kDt)), 1.0, 0.05);
  const AxisNoise* az = noise.Find(Sensor::kAccel, 2);
  ASSERT_NE(az, nullptr);
  EXPECT_NEAR(az->fit.term(NoiseTermKind::kWhite).value() / (0.01 * std::sqrt(kDt)), 1.0, 0.05);
  // The intervals are those of the fitted noise types, at the default one sigma.
  EXPECT_EQ(az->adev.noise, az->fit.noise);
  EXPECT_DOUBLE_EQ(az->adev.confidence, kOneSigmaConfidence);
}

TEST(StillNoise, TooLittleStillDataIsSaid) {
  const ImuSeries series = StillSeries(100);
  StillSegment s;
  s.begin = 0, s.end = 5, s.label = "short";
  EXPECT_THROW(AnalyseStillNoise(series, {s}), InsufficientDataError);
  EXPECT_THROW(AnalyseStillNoise(series, {}), InsufficientDataError);
}

}  // namespace
}  // namespace plumb::signal

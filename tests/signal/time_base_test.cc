// signal/time_base.h: the stamps read for what they are, on stamps made with a known truth
// (deterministic patterns, no random numbers): a sensor clock off its nominal rate keeps its
// rate; a host's arrival clock (the sawtooth of ChanghyeonKim93's sessions: stamps drifting
// late by 0.2 ms a sample, then one short interval) is named and its uniform clock recovers
// the true sample times; dropped samples are counted and kept as gaps, with or without jitter.
#include "plumb/signal/time_base.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace plumb::signal {
namespace {

constexpr double kT = 0.01;          // 100 Hz
constexpr double kStart = 1.5356e9;  // unix time, as host stamps are
/// How close the uniform clock comes to the true sample times (less the constant latency):
/// 0.5 % of an interval (the line's slope through a truncated sawtooth, and the 0.24 us
/// resolution of a double at unix times).
constexpr double kClockTolerance = 5e-5;

/// True sample times a + T n for the indices `n`.
std::vector<double> Times(const std::vector<std::int64_t>& n, double interval) {
  std::vector<double> t;
  for (std::int64_t k : n) t.push_back(kStart + interval * static_cast<double>(k));
  return t;
}

std::vector<std::int64_t> Indices(std::int64_t count, const std::vector<std::int64_t>& dropped) {
  std::vector<std::int64_t> n;
  for (std::int64_t k = 0; k < count; ++k) {
    bool gone = false;
    for (std::int64_t d : dropped) gone = gone || d == k;
    if (!gone) n.push_back(k);
  }
  return n;
}

/// A host's arrival stamps: late by 0.2 ms more each sample, back in one step every 25 samples
/// (the pattern of a reader that polls a little slower than the sensor), plus a 0.3 ms ripple.
std::vector<double> HostStamps(const std::vector<double>& truth) {
  std::vector<double> t = truth;
  for (std::size_t k = 0; k < t.size(); ++k) {
    t[k] += 2e-4 * static_cast<double>(k % 25) + 3e-4 * std::sin(0.7 * static_cast<double>(k));
  }
  return t;
}

TEST(TimeBase, ASensorClockOffItsNominalRateKeepsThatRate) {
  const double interval = kT / 1.001;  // 100.1 Hz: 0.1 % fast
  const std::vector<double> t = Times(Indices(5000, {}), interval);
  const TimeBase b = AnalyseTimeBase(t);
  EXPECT_EQ(b.kind, ClockKind::kUniform);
  EXPECT_NEAR(b.rate_hz(), 100.1, 1e-6);
  EXPECT_EQ(b.dropped, 0u);
  EXPECT_LT(b.jitter_rms_s, 1e-6);
}

TEST(TimeBase, AHostArrivalClockIsNamedAndItsUniformClockIsTheSampleClock) {
  const std::vector<double> truth = Times(Indices(6000, {}), kT);
  std::vector<double> t = HostStamps(truth);
  const TimeBase b = AnalyseTimeBase(t);
  EXPECT_EQ(b.kind, ClockKind::kHostArrival);
  EXPECT_EQ(b.dropped, 0u);
  EXPECT_NEAR(b.rate_hz(), 100.0, 1e-3);
  EXPECT_GT(b.jitter_rms_s, 1e-3);
  EXPECT_GT(b.short_intervals, 200u);  // one in 25
  ApplyUniformClock(b, t);
  // The same sample clock up to the host's mean latency (a constant: the stamps' own origin).
  const double latency = t.front() - truth.front();
  for (std::size_t k = 0; k < t.size(); ++k) EXPECT_NEAR(t[k] - truth[k], latency, kClockTolerance) << k;
}

TEST(TimeBase, DroppedSamplesAreCountedAndKeptAsGapsWithAndWithoutJitter) {
  // Three samples dropped at two places: one at 1000, two at 3000-3001.
  const std::vector<std::int64_t> n = Indices(6000, {1000, 3000, 3001});
  const std::vector<double> truth = Times(n, kT);
  for (const bool host : {false, true}) {
    std::vector<double> t = host ? HostStamps(truth) : truth;
    const TimeBase b = AnalyseTimeBase(t);
    EXPECT_EQ(b.kind, host ? ClockKind::kHostArrival : ClockKind::kUniform);
    EXPECT_EQ(b.dropped, 3u) << host;
    EXPECT_EQ(b.drop_places, 2u) << host;
    EXPECT_NEAR(b.first_drop_s, t[1000], 1e-9);
    ApplyUniformClock(b, t);
    const double latency = t.front() - truth.front();
    for (std::size_t k = 0; k < t.size(); k += 97) EXPECT_NEAR(t[k] - truth[k], latency, kClockTolerance);
  }
}

TEST(TimeBase, TooFewStampsAreNotJudgedAndLeftAlone) {
  std::vector<double> t = Times(Indices(kMinTimeBaseSamples - 1, {}), kT);
  const std::vector<double> before = t;
  const TimeBase b = AnalyseTimeBase(t);
  EXPECT_EQ(b.kind, ClockKind::kTooShort);
  ApplyUniformClock(b, t);
  EXPECT_EQ(t, before);
}

}  // namespace
}  // namespace plumb::signal

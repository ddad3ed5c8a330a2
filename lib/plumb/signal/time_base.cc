// plumb/signal/time_base.cc — see time_base.h.
#include "plumb/signal/time_base.h"

#include <algorithm>
#include <cmath>

namespace plumb::signal {
namespace {

/// Least-squares line t = a + T n (t relative to the first stamp).
struct Line {
  double a = 0.0, T = 0.0;
  double At(std::int64_t n) const { return a + T * static_cast<double>(n); }
};

Line FitLine(const std::vector<std::int64_t>& n, const std::vector<double>& t) {
  const double count = static_cast<double>(n.size());
  double mean_n = 0.0, mean_t = 0.0;
  for (std::size_t k = 0; k < n.size(); ++k) {
    mean_n += static_cast<double>(n[k]);
    mean_t += t[k];
  }
  mean_n /= count;
  mean_t /= count;
  double snn = 0.0, snt = 0.0;
  for (std::size_t k = 0; k < n.size(); ++k) {
    const double dn = static_cast<double>(n[k]) - mean_n;
    snn += dn * dn;
    snt += dn * (t[k] - mean_t);
  }
  Line line;
  line.T = snt / snn;
  line.a = mean_t - line.T * mean_n;
  return line;
}

double Median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// The stamps' level (median residual) from `begin` to `end` (clamped to the series).
double Level(const std::vector<double>& r, std::size_t begin, std::size_t end) {
  end = std::min(end, r.size());
  return Median(std::vector<double>(r.begin() + static_cast<std::ptrdiff_t>(begin),
                                    r.begin() + static_cast<std::ptrdiff_t>(end)));
}

/// Places dropped samples where a long interval is followed by a level shift of the residuals
/// against `line`; returns how many places changed.
std::size_t PlaceDrops(const std::vector<double>& t, const Line& line,
                       std::vector<std::int64_t>& n) {
  std::vector<double> r(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) r[k] = t[k] - line.At(n[k]);
  std::vector<std::int64_t> add(t.size(), 0);
  std::size_t changed = 0;
  for (std::size_t k = 1; k < t.size(); ++k) {
    if (t[k] - t[k - 1] <= 1.5 * line.T) continue;
    const std::size_t before = k >= kLevelWindow ? k - kLevelWindow : 0;
    const double shift = Level(r, k, k + kLevelWindow) - Level(r, before, k);
    const auto steps = static_cast<std::int64_t>(std::lround(shift / line.T));
    // A drop already placed leaves no shift; never take back more than the gap holds.
    const std::int64_t room = n[k] - n[k - 1] - 1;
    const std::int64_t step = std::max(steps, -room);
    if (step != 0) {
      add[k] = step;
      ++changed;
    }
  }
  std::int64_t carried = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    carried += add[k];
    n[k] += carried;
  }
  return changed;
}

}  // namespace

TimeBase AnalyseTimeBase(const std::vector<double>& t_s) {
  TimeBase out;
  out.samples = t_s.size();
  if (t_s.size() < kMinTimeBaseSamples) return out;
  // Relative to the first stamp: unix times would lose the jitter in the line's rounding.
  const double t0 = t_s.front();
  std::vector<double> t(t_s.size());
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = t_s[k] - t0;
  // First indices: each interval in steps of the median interval (a sensor clock's T; a
  // host's bunching is within half a step of one), at least one.
  std::vector<double> dt(t.size() - 1);
  for (std::size_t k = 1; k < t.size(); ++k) dt[k - 1] = t[k] - t[k - 1];
  out.median_interval_s = Median(dt);
  out.index.resize(t.size());
  out.index[0] = 0;
  for (std::size_t k = 1; k < t.size(); ++k) {
    const auto steps = static_cast<std::int64_t>(std::lround(dt[k - 1] / out.median_interval_s));
    out.index[k] = out.index[k - 1] + std::max<std::int64_t>(1, steps);
  }
  Line line = FitLine(out.index, t);
  for (int pass = 0; pass < 3; ++pass) {
    if (PlaceDrops(t, line, out.index) == 0) break;
    line = FitLine(out.index, t);
  }
  out.offset_s = t0 + line.a;
  out.interval_s = line.T;
  double ss = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double e = t[k] - line.At(out.index[k]);
    ss += e * e;
    out.jitter_max_s = std::max(out.jitter_max_s, std::abs(e));
    if (k == 0) continue;
    const std::int64_t missing = out.index[k] - out.index[k - 1] - 1;
    if (missing > 0) {
      if (out.drop_places == 0) out.first_drop_s = t_s[k];
      out.dropped += static_cast<std::size_t>(missing);
      ++out.drop_places;
    } else if (dt[k - 1] > 1.25 * line.T) {
      ++out.long_intervals;
    }
    if (dt[k - 1] < 0.75 * line.T) ++out.short_intervals;
  }
  out.jitter_rms_s = std::sqrt(ss / static_cast<double>(t.size()));
  out.kind = out.jitter_rms_s < kUniformJitterFraction * line.T   ? ClockKind::kUniform
             : out.jitter_rms_s < kIrregularJitterFraction * line.T ? ClockKind::kHostArrival
                                                                    : ClockKind::kIrregular;
  return out;
}

void ApplyUniformClock(const TimeBase& base, std::vector<double>& t_s) {
  if (base.kind == ClockKind::kTooShort || base.kind == ClockKind::kIrregular ||
      base.index.size() != t_s.size()) {
    return;
  }
  for (std::size_t k = 0; k < t_s.size(); ++k) t_s[k] = base.UniformTime(k);
}

}  // namespace plumb::signal

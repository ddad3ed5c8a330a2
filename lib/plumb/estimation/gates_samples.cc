// plumb/estimation/gates_samples.cc — the samples' gates (gates.h: out_of_range, saturated):
// CheckSamples, one pass over the samples before the fit.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/core/option_name.h"
#include "plumb/core/units.h"
#include "plumb/estimation/gates.h"
#include "plumb/estimation/gates_internal.h"

namespace plumb::estimation {
namespace {

using gates_internal::Count;
using gates_internal::kAxis;
using gates_internal::Median;
using gates_internal::SiAccel;
using gates_internal::SiGyro;

/// A sample value as logged, to float precision ("%.7g"): -32768, not -3.277e+04.
std::string Exact(double v) { return SignificantText(v, 7); }

/// A vector to 4 significant digits: "(0.01, -9.81, 0.1)".
std::string Triple(const Vec3& v) {
  return "(" + Number(v.x(), 4) + ", " + Number(v.y(), 4) + ", " + Number(v.z(), 4) + ")";
}

/// The still segments as sorted, merged sample ranges, asked about samples in increasing order.
class StillRanges {
 public:
  explicit StillRanges(const std::vector<StillSegment>& still) {
    for (const auto& s : still) {
      if (s.end > s.begin) ranges_.emplace_back(s.begin, s.end);
    }
    std::sort(ranges_.begin(), ranges_.end());
  }
  /// Sample i lies in a still segment; i must not decrease between calls (until Rewind).
  bool Contains(std::size_t i) {
    while (k_ < ranges_.size() && ranges_[k_].second <= i) ++k_;
    for (std::size_t j = k_; j < ranges_.size() && ranges_[j].first <= i; ++j) {
      if (i < ranges_[j].second) return true;
    }
    return false;
  }
  void Rewind() { k_ = 0; }

 private:
  std::vector<std::pair<std::size_t, std::size_t>> ranges_;
  std::size_t k_ = 0;
};

/// The per-axis limit of out_of_range for one sensor of `series`.
double RangeLimit(const ImuSeries& series, bool gyro) {
  if (gyro) return SiGyro(series) ? kMaxGyroDegS * units::kRadPerDeg : kMaxCounts;
  return SiAccel(series) ? kMaxAccelG * units::kStandardGravity : kMaxCounts;
}

std::string LimitText(const ImuSeries& series, bool gyro) {
  const double limit = RangeLimit(series, gyro);
  const std::string unit = gyro ? series.gyr_unit : series.acc_unit;
  if (gyro && SiGyro(series)) {
    return Number(limit, 4) + " rad/s (" + Number(kMaxGyroDegS, 4) + " deg/s)";
  }
  if (!gyro && SiAccel(series)) {
    return Number(limit, 4) + " m/s^2 (" + Number(kMaxAccelG, 4) + " g)";
  }
  return Number(limit, 4) + " " + unit;
}

/// Axis k of sample i: accelerometer x, y, z for k = 0..2, gyroscope x, y, z for k = 3..5.
float Component(const ImuSeries& series, std::size_t i, int k) {
  return k < 3 ? series.acc[i][k] : series.gyr[i][k - 3];
}

/// One pass over the samples: those out of range, and each axis's extremes over the rest.
struct SampleScan {
  std::size_t bad = 0, bad_in_still = 0, first_bad = 0;
  std::array<float, 6> lo{}, hi{};
  std::array<bool, 6> any{};
};

/// Extremes of one sensor's axes over the components within `limit`; returns the number of
/// components beyond it or not finite. The samples are read as a flat array of floats, 12 (4
/// samples) at a time into 12 accumulators, which the compiler vectorises: one fast pass.
std::size_t Extremes(const std::vector<Vec3f>& v, float limit, float* lo, float* hi) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f is three packed floats");
  const float* p = v.empty() ? nullptr : v.data()->data();
  const std::size_t n = 3 * v.size();
  float l[12], h[12];
  unsigned bad[12] = {0};
  for (int k = 0; k < 12; ++k) l[k] = kInf, h[k] = -kInf;
  std::size_t i = 0;
  for (; i + 12 <= n; i += 12) {
    for (int k = 0; k < 12; ++k) {
      const float x = p[i + static_cast<std::size_t>(k)];
      const bool ok = std::abs(x) <= limit;  // false for NaN too
      const float xl = ok ? x : kInf, xh = ok ? x : -kInf;
      l[k] = xl < l[k] ? xl : l[k];
      h[k] = xh > h[k] ? xh : h[k];
      bad[k] += ok ? 0u : 1u;
    }
  }
  std::size_t total = 0;
  for (; i < n; ++i) {
    const float x = p[i];
    const std::size_t a = i % 3;
    if (std::abs(x) <= limit) {
      l[a] = std::min(l[a], x);
      h[a] = std::max(h[a], x);
    } else {
      ++total;
    }
  }
  for (int a = 0; a < 3; ++a) lo[a] = kInf, hi[a] = -kInf;
  for (int k = 0; k < 12; ++k) {
    lo[k % 3] = std::min(lo[k % 3], l[k]);
    hi[k % 3] = std::max(hi[k % 3], h[k]);
    total += bad[k];
  }
  return total;
}

SampleScan Scan(const ImuSeries& series, StillRanges& still) {
  SampleScan out;
  const float limit[2] = {static_cast<float>(RangeLimit(series, false)),
                          static_cast<float>(RangeLimit(series, true))};
  std::size_t bad = Extremes(series.acc, limit[0], out.lo.data(), out.hi.data());
  if (series.has_gyro()) bad += Extremes(series.gyr, limit[1], out.lo.data() + 3, out.hi.data() + 3);
  for (std::size_t k = 0; k < 6; ++k) out.any[k] = out.hi[k] >= out.lo[k];
  if (bad == 0) return out;
  // Some samples are out of range: count them, and find the first.
  const int axes = series.has_gyro() ? 6 : 3;
  for (std::size_t i = 0; i < series.size(); ++i) {
    bool ok = true;
    for (int k = 0; k < axes; ++k) ok = ok && std::abs(Component(series, i, k)) <= limit[k / 3];
    if (ok) continue;
    if (out.bad == 0) out.first_bad = i;
    ++out.bad;
    out.bad_in_still += still.Contains(i) ? 1 : 0;
  }
  return out;
}

std::optional<Gate> OutOfRange(const ImuSeries& series, const SampleScan& scan) {
  if (scan.bad == 0) return std::nullopt;
  const std::size_t first = scan.first_bad;
  std::string sample = "accel " + Triple(series.acc[first].cast<double>()) + " " + series.acc_unit;
  if (series.has_gyro()) {
    sample += ", gyro " + Triple(series.gyr[first].cast<double>()) + " " + series.gyr_unit;
  }
  return Gate{"out_of_range",
              Count(scan.bad, "sample") + " outside any IMU's range (an axis beyond " +
                  LimitText(series, false) +
                  (series.has_gyro() ? " or " + LimitText(series, true) : std::string()) +
                  ", or not finite), " + std::to_string(scan.bad_in_still) +
                  " of them inside the still segments; the first at t = " + Number(series.t_s[first], 4) +
                  " s (sample " + std::to_string(first) + "): " + sample +
                  ". A corrupt log (flipped bytes, a bad record) or a wrong unit: cut them out "
                  "(" + OptionText(Option::kTimeWindow) + ", " + OptionText(Option::kSegments) +
                  ") or fix the input before trusting this fit",
              {Option::kTimeWindow, Option::kSegments}};
}

/// out_of_range for the sensor's temperature: readings beyond kMinTemperatureC ..
/// kMaxTemperatureC or not finite, counted, the first named (nullopt without any).
std::optional<Gate> TemperatureOutOfRange(const ImuSeries& series) {
  std::size_t bad = 0, first = 0;
  for (std::size_t i = 0; i < series.temp_c.size(); ++i) {
    const float c = series.temp_c[i];
    if (c >= kMinTemperatureC && c <= kMaxTemperatureC) continue;  // false for NaN too
    if (bad++ == 0) first = i;
  }
  if (bad == 0) return std::nullopt;
  return Gate{"out_of_range",
              Count(bad, "temperature") + " outside any MEMS IMU's operating range (beyond " +
                  Number(kMinTemperatureC, 4) + " .. " + Number(kMaxTemperatureC, 4) +
                  " degC, or not finite); the first at t = " + Number(series.t_s[first], 4) +
                  " s (sample " + std::to_string(first) + "): " +
                  Exact(series.temp_c[first]) +
                  " degC. A corrupt log or a column that is not degC: cut them out "
                  "(" + OptionText(Option::kTimeWindow) +
                  ") or fix the input before trusting a temperature model",
              {Option::kTimeWindow}};
}

/// Runs of samples at one axis's extreme value outside the still segments.
struct Run {
  bool active = false;  ///< the extreme is beyond the saturation floor
  float value = 0;
  std::size_t current = 0, longest = 0, start = 0, runs = 0, samples = 0;

  void Close(std::size_t end) {
    if (current >= static_cast<std::size_t>(kSaturationRun)) {
      ++runs;
      samples += current;
      if (current > longest) {
        longest = current;
        start = end - current;
      }
    }
    current = 0;
  }
};

/// Median norm of the accelerometer mean over the still segments, sensor units (0 if none).
double StillAccelNorm(const ImuSeries& series, const std::vector<StillSegment>& still) {
  std::vector<double> norms;
  for (const auto& s : still) {
    if (s.spinning() || s.end <= s.begin || s.end > series.size()) continue;
    Vec3 sum = Vec3::Zero();
    for (std::size_t i = s.begin; i < s.end; ++i) sum += series.acc[i].cast<double>();
    norms.push_back((sum / static_cast<double>(s.end - s.begin)).norm());
  }
  const double m = Median(norms);
  return std::isfinite(m) ? m : 0.0;
}

/// Per axis (k = 0..5) and extreme (high, low): the runs at it, when beyond the floor.
std::array<Run, 12> SaturationRuns(const ImuSeries& series, const std::vector<StillSegment>& still,
                                   const SampleScan& scan, StillRanges& ranges) {
  std::array<Run, 12> runs{};
  const int axes = series.has_gyro() ? 6 : 3;
  const double floor[2] = {
      SiAccel(series) ? kSaturationMinAccelG * units::kStandardGravity
                      : kSaturationMinAccelG * StillAccelNorm(series, still),
      SiGyro(series) ? kSaturationMinGyroDegS * units::kRadPerDeg : 0.0};
  bool any = false;
  for (int k = 0; k < axes; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    for (int e = 0; e < 2; ++e) {
      Run& r = runs[2 * kk + static_cast<std::size_t>(e)];
      r.value = e == 0 ? scan.hi[kk] : scan.lo[kk];
      r.active = scan.any[kk] && std::abs(static_cast<double>(r.value)) >= floor[k / 3];
      any = any || r.active;
    }
  }
  if (!any) return runs;
  // Per active extreme, one pass over its axis: equal samples are rare, so the loop is a
  // compare with a branch almost never taken; runs are counted on the matches alone.
  for (std::size_t t = 0; t < runs.size(); ++t) {
    Run& r = runs[t];
    if (!r.active) continue;
    const int k = static_cast<int>(t / 2);
    const float* p = (k < 3 ? series.acc : series.gyr).data()->data() + k % 3;
    std::size_t last = 0;  // one past the last sample of the current run
    ranges.Rewind();
    for (std::size_t i = 0; i < series.size(); ++i) {
      if (p[3 * i] != r.value || ranges.Contains(i)) continue;
      if (r.current > 0 && i != last) r.Close(last);
      ++r.current;
      last = i + 1;
    }
    r.Close(last);
  }
  return runs;
}

std::optional<Gate> Saturated(const ImuSeries& series, const std::array<Run, 12>& runs) {
  std::string axes;
  for (std::size_t t = 0; t < runs.size(); ++t) {
    const Run& run = runs[t];
    if (!run.active || run.runs == 0) continue;
    const bool gyro = t >= 6;
    axes += std::string(axes.empty() ? "" : "; ") + (gyro ? "gyro " : "accel ") + kAxis[(t / 2) % 3] +
            " sits at " + Exact(run.value) + " " + (gyro ? series.gyr_unit : series.acc_unit) +
            " for " + std::to_string(run.longest) + " samples in a row from t = " +
            Number(series.t_s[run.start], 4) + " s (" + Count(run.runs, "such run") + ", " +
            Count(run.samples, "sample") + ")";
  }
  if (axes.empty()) return std::nullopt;
  return Gate{"saturated",
              axes + ": the sensor's full scale (" + std::to_string(kSaturationRun) +
                  " or more equal samples at the axis's extreme, outside the still segments): "
                  "the turns or shocks there are clipped, so the motion through them is wrong; "
                  "turn more slowly, or set a larger range on the sensor"};
}

}  // namespace

std::vector<Gate> CheckSamples(const ImuSeries& series, const std::vector<StillSegment>& still) {
  std::vector<Gate> gates;
  StillRanges ranges(still);
  const SampleScan scan = Scan(series, ranges);
  std::optional<Gate> range = OutOfRange(series, scan);
  if (auto t = TemperatureOutOfRange(series)) {
    if (range) {
      range->message += "; and " + t->message;
    } else {
      range = t;
    }
  }
  if (range) gates.push_back(*range);
  if (auto g = Saturated(series, SaturationRuns(series, still, scan, ranges))) gates.push_back(*g);
  return gates;
}

}  // namespace plumb::estimation

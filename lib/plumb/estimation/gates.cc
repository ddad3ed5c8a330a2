#include "plumb/estimation/gates.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "plumb/core/number_text.h"
#include "plumb/core/units.h"
#include "plumb/model/effects/gyro_linear.h"

namespace plumb::estimation {
namespace {

constexpr const char* kAxis[3] = {"x", "y", "z"};

/// A number with 4 significant digits ("%.4g").
std::string Num(double v) { return SignificantText(v, 4); }

/// A sample value as logged, to float precision ("%.7g"): -32768, not -3.277e+04.
std::string Exact(double v) { return SignificantText(v, 7); }

/// A time or a duration to a tenth of a second ("%.1f"): log times since boot and unix times
/// alike ("1710773367.1", not "1.711e+09").
std::string Tenth(double t) { return FixedText(t, 1); }

/// "N thing" or "N things".
std::string Count(std::size_t n, const std::string& thing) {
  return std::to_string(n) + " " + thing + (n == 1 ? "" : "s");
}

std::string Triple(const Vec3& v) { return "(" + Num(v.x()) + ", " + Num(v.y()) + ", " + Num(v.z()) + ")"; }

bool SiAccel(const ImuSeries& s) { return s.acc_unit == "m/s^2"; }
bool SiGyro(const ImuSeries& s) { return s.gyr_unit == "rad/s"; }

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
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
  if (gyro && SiGyro(series)) return Num(limit) + " rad/s (" + Num(kMaxGyroDegS) + " deg/s)";
  if (!gyro && SiAccel(series)) return Num(limit) + " m/s^2 (" + Num(kMaxAccelG) + " g)";
  return Num(limit) + " " + unit;
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
                  " of them inside the still segments; the first at t = " + Num(series.t_s[first]) +
                  " s (sample " + std::to_string(first) + "): " + sample +
                  ". A corrupt log (flipped bytes, a bad record) or a wrong unit: cut them out "
                  "(--from/--to, --segments) or fix the input before trusting this fit"};
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
                  Num(kMinTemperatureC) + " .. " + Num(kMaxTemperatureC) +
                  " degC, or not finite); the first at t = " + Num(series.t_s[first]) +
                  " s (sample " + std::to_string(first) + "): " +
                  Exact(series.temp_c[first]) +
                  " degC. A corrupt log or a column that is not degC: cut them out "
                  "(--from/--to) or fix the input before trusting a temperature model"};
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
            Num(series.t_s[run.start]) + " s (" + Count(run.runs, "such run") + ", " +
            Count(run.samples, "sample") + ")";
  }
  if (axes.empty()) return std::nullopt;
  return Gate{"saturated",
              axes + ": the sensor's full scale (" + std::to_string(kSaturationRun) +
                  " or more equal samples at the axis's extreme, outside the still segments): "
                  "the turns or shocks there are clipped, so the motion through them is wrong; "
                  "turn more slowly, or set a larger range on the sensor"};
}

/// The still segments at rest (not turning at a stated rate), in time order.
std::vector<const StillSegmentFit*> AtRest(const std::vector<StillSegmentFit>& still) {
  std::vector<const StillSegmentFit*> out;
  for (const auto& s : still) {
    if (!s.segment.spinning()) out.push_back(&s);
  }
  return out;
}

/// Same gravity direction within the noise (and kSamePoseMinDeg).
bool SameGravity(const StillSegmentFit& a, const StillSegmentFit& b, const NoiseLevels& noise) {
  const double na = a.acc_mean.norm(), nb = b.acc_mean.norm();
  if (!(na > 0) || !(nb > 0)) return false;
  const double cosine = std::clamp(a.acc_mean.dot(b.acc_mean) / (na * nb), -1.0, 1.0);
  const double angle = std::acos(cosine);
  const double s = noise.acc.maxCoeff() * std::sqrt(std::max(1.0, noise.tau_acc));
  const double sa = s / std::sqrt(static_cast<double>(std::max<std::size_t>(1, a.count))) / na;
  const double sb = s / std::sqrt(static_cast<double>(std::max<std::size_t>(1, b.count))) / nb;
  const double bound =
      std::max(kSamePoseSigmas * std::hypot(sa, sb), kSamePoseMinDeg * units::kRadPerDeg);
  return angle < bound;
}

/// No turn between a and b: the gyroscope between them, less the mean of their still rates,
/// integrates to less than its noise bound (and kSameTurnMinDeg in SI).
bool NoTurn(const ImuSeries& series, const StillSegmentFit& a, const StillSegmentFit& b,
            const NoiseLevels& noise) {
  if (!series.has_gyro()) return true;
  const std::size_t first = a.segment.end, last = std::min(b.segment.begin, series.size());
  const Vec3 rate = 0.5 * (a.gyr_mean + b.gyr_mean);
  const double dt_median = series.median_dt_s();
  Vec3 turn = Vec3::Zero();
  for (std::size_t i = first; i < last; ++i) {
    const double dt = i + 1 < series.size() ? series.t_s[i + 1] - series.t_s[i] : dt_median;
    turn += (series.gyr[i].cast<double>() - rate) * dt;
  }
  const double n = static_cast<double>(last > first ? last - first : 0);
  const double tau = std::max(1.0, noise.tau_gyr);
  const double sigma = noise.gyr.maxCoeff();
  const double integral = sigma * dt_median * std::sqrt(n * tau);
  const double mean = sigma * std::sqrt(tau) * 0.5 *
                      std::sqrt(1.0 / std::max<std::size_t>(1, a.count) +
                                1.0 / std::max<std::size_t>(1, b.count)) *
                      n * dt_median;
  double bound = kSamePoseSigmas * std::sqrt(3.0) * std::hypot(integral, mean);
  if (SiGyro(series)) bound = std::max(bound, kSameTurnMinDeg * units::kRadPerDeg);
  return turn.norm() < bound;
}

Gate NotConverged(const FitReport& fit) {
  const auto at = fit.solver_report.find("Termination: ");
  const std::string why =
      at == std::string::npos ? std::string("no convergence") : fit.solver_report.substr(at);
  return Gate{"not_converged",
              "the solver did not converge: its last solve stopped after " +
                  std::to_string(fit.last_solve_iterations) + " iterations (" +
                  std::to_string(fit.iterations) + " over its " + std::to_string(fit.solves) +
                  " solves; " + why +
                  "); the values, sigmas and chi2 are not those of a minimum. Check the "
                  "segments and the input's units and rate (the other gates), or allow more "
                  "iterations (--max-iterations)"};
}

std::optional<Gate> Nonlinear(const FitReport& fit) {
  const LinearityReport& lin = fit.linearity;
  if (!lin.checked || !(lin.worst_ratio > kMaxLinearityRatio)) return std::nullopt;
  const double c2 = lin.step_sigmas * lin.step_sigmas;
  return Gate{"nonlinear",
              "the covariance does not describe this fit: " + Num(lin.step_sigmas) +
                  " sigma out along " + lin.worst_direction + " (in sigma of each) chi2 rises by " +
                  Num(lin.worst_ratio * c2) + " where the covariance says " + Num(c2) +
                  ". The fit lies in a curved valley of near-equal fits (the data tie these "
                  "parameters together only nonlinearly): each sigma may still cover its "
                  "parameter, the combinations' do not, and the values can be far off. Record "
                  "more well-spread poses (9 or more gravity directions when the attitudes are "
                  "free) or state the attitudes"};
}

/// "1-12" style list of the runs of merged segments (1-based), at most a few.
std::string MergedRuns(const std::vector<bool>& same_as_previous) {
  std::string out;
  int shown = 0;
  std::size_t k = 0;
  while (k < same_as_previous.size()) {
    std::size_t end = k + 1;
    while (end < same_as_previous.size() && same_as_previous[end]) ++end;
    if (end - k > 1) {
      if (shown == 4) return out + ", ...";
      out += (out.empty() ? "" : ", ") + std::to_string(k + 1) + "-" + std::to_string(end);
      ++shown;
    }
    k = end;
  }
  return out;
}

std::optional<Gate> OnePose(const ImuSeries& series, const Calibration& cal,
                            const FitReport& fit) {
  const auto rest = AtRest(fit.still);
  const int segments = static_cast<int>(rest.size());
  int free_accel = 0;
  for (const auto& p : cal.parameters) free_accel += (!p.fixed && p.name.rfind("accel.", 0) == 0) ? 1 : 0;
  const bool known = std::any_of(rest.begin(), rest.end(),
                                 [](const StillSegmentFit* s) { return s->attitude_known; });
  const int needed = known ? (free_accel + 2) / 3 : free_accel;
  if (fit.distinct_poses >= segments || fit.distinct_poses >= needed) return std::nullopt;
  std::vector<bool> same(rest.size(), false);
  for (std::size_t k = 1; k < rest.size(); ++k) {
    same[k] = SameGravity(*rest[k - 1], *rest[k], cal.noise) &&
              NoTurn(series, *rest[k - 1], *rest[k], cal.noise);
  }
  const int poses = fit.distinct_poses;
  return Gate{"one_pose",
              "the " + std::to_string(segments) + " still segments lie in " + std::to_string(poses) +
                  " distinct pose" + (poses == 1 ? "" : "s") + " (segments " + MergedRuns(same) +
                  " have the same gravity direction within the noise and no turn between "
                  "them): the rank (" + std::to_string(cal.observability.rank) + " of " +
                  std::to_string(cal.observability.num_unknowns) +
                  ") and the sigmas rest on " + std::to_string(poses) + " pose" +
                  (poses == 1 ? "" : "s") + ", and the differences between pieces of one pose "
                  "are noise, not information; the accelerometer's " + std::to_string(free_accel) +
                  " free parameters need at least " + std::to_string(needed) + " distinct poses" +
                  (known ? " (with known attitudes)" : "") +
                  ". Record more poses, or give one segment per pose"};
}

/// Mean of the fitted diagonal entries prefix.matrix.xx/yy/zz that are free and observable;
/// nullopt when none is.
std::optional<double> FittedScale(const Calibration& cal, const std::string& prefix,
                                  const Mat3& m, std::string* diagonal) {
  double sum = 0;
  int n = 0;
  for (int a = 0; a < 3; ++a) {
    const std::string name = prefix + ".matrix." + kAxis[a] + kAxis[a];
    const auto p = std::find_if(cal.parameters.begin(), cal.parameters.end(),
                                [&](const ParameterEstimate& q) { return q.name == name; });
    if (p == cal.parameters.end() || p->fixed || !p->observable) continue;
    sum += m(a, a);
    ++n;
    *diagonal += (diagonal->empty() ? "" : ", ") + Num(m(a, a));
  }
  if (n == 0) return std::nullopt;
  return sum / n;
}

/// The segments whose mean is a possible reading (finite, within out_of_range's limit): a mean
/// over samples out of range says nothing about units (out_of_range says it).
std::vector<const StillSegmentFit*> Plausible(const std::vector<const StillSegmentFit*>& rest,
                                              const Calibration& cal) {
  const double acc_limit = cal.acc_unit == "m/s^2" ? kMaxAccelG * units::kStandardGravity : kMaxCounts;
  const double gyr_limit = cal.gyr_unit == "rad/s" ? kMaxGyroDegS * units::kRadPerDeg : kMaxCounts;
  std::vector<const StillSegmentFit*> out;
  for (const auto* s : rest) {
    const bool acc = s->acc_mean.allFinite() && s->acc_mean.cwiseAbs().maxCoeff() <= acc_limit;
    const bool gyr = !cal.has_gyro ||
                     (s->gyr_mean.allFinite() && s->gyr_mean.cwiseAbs().maxCoeff() <= gyr_limit);
    if (acc && gyr) out.push_back(s);
  }
  return out;
}

/// The raw still norm; then, when the fit is `usable` (converged, poses enough: otherwise its
/// values are noise), the fitted scale and the corrected still norm.
std::optional<Gate> AccelUnit(const Calibration& cal, const std::vector<const StillSegmentFit*>& rest,
                              bool usable) {
  std::vector<double> raw, corrected;
  const Mat3 F = cal.AccelMatrix();
  const Eigen::FullPivLU<Mat3> lu(F);
  for (const auto* s : rest) {
    raw.push_back(s->acc_mean.norm());
    if (lu.isInvertible()) corrected.push_back(lu.solve(s->acc_mean - cal.AccelBias()).norm());
  }
  const double g = cal.site.gravity();
  const double norm = Median(raw);
  const int n = static_cast<int>(rest.size());
  if (cal.acc_unit == "m/s^2" && std::abs(norm / g - 1.0) > kMaxNormError) {
    const double ratio = norm / g;
    const std::string hint =
        std::abs(norm - 1.0) < 0.2 ? "the samples look like g, not m/s^2: give --acc-unit g"
        : ratio > 20.0 ? "the samples look like raw counts (or mg): give --acc-unit counts, or "
                         "--acc-scale"
                       : "check the accelerometer's unit and scale (--acc-unit, --acc-scale)";
    return Gate{"unit_or_rate", "the still accelerometer reads " + Num(norm) +
                                    " m/s^2 (median norm over " + Count(n, "still segment") +
                                    ") where gravity is " + Num(g) + " m/s^2: " +
                                    hint};
  }
  std::string diagonal;
  const auto scale = FittedScale(cal, "accel", F, &diagonal);
  if (!usable || !scale) return std::nullopt;
  if (cal.acc_unit == "m/s^2" && std::abs(*scale - 1.0) > kMaxScaleError) {
    return Gate{"unit_or_rate", "the accelerometer's scale came out " + Num(*scale) +
                                    " (accel.matrix diagonal " + diagonal +
                                    "), more than " + Num(100 * kMaxScaleError) +
                                    " % from 1: check the accelerometer's unit and scale "
                                    "(--acc-unit, --acc-scale)"};
  }
  const double after = Median(corrected);
  if (std::isfinite(after) && std::abs(after / g - 1.0) > kMaxCorrectedNormError) {
    return Gate{"unit_or_rate", "after calibration the still accelerometer reads " + Num(after) +
                                    " m/s^2 (median of |F^-1 (mean - b_a)| over " +
                                    Count(n, "still segment") + ") where gravity is " +
                                    Num(g) + " m/s^2: the fit does not explain the poses"};
  }
  return std::nullopt;
}

/// The raw still norm; then, when the fit is `usable`, the fitted scale (turn angles).
std::optional<Gate> GyroUnitOrRate(const ImuSeries& series, const Calibration& cal,
                                   const std::vector<const StillSegmentFit*>& rest, bool usable) {
  if (!cal.has_gyro || cal.gyr_unit != "rad/s") return std::nullopt;
  std::vector<double> raw;
  for (const auto* s : rest) raw.push_back(s->gyr_mean.norm());
  const double norm = Median(raw);
  const double allowed = kMaxGyroBiasDegS * units::kRadPerDeg + units::kEarthRate;
  if (norm > allowed) {
    return Gate{"unit_or_rate",
                "the still gyroscope reads " + Num(norm) + " rad/s (median norm over " +
                    Count(rest.size(), "still segment") + ") where Earth rate (" +
                    Num(units::kEarthRate) + " rad/s) and a plausible bias (" +
                    Num(kMaxGyroBiasDegS) + " deg/s) allow at most " + Num(allowed) +
                    " rad/s: the samples look like deg/s or raw counts, not rad/s (give "
                    "--gyr-unit deg/s, --gyr-unit counts or --gyr-scale)"};
  }
  std::string diagonal;
  const auto scale = FittedScale(cal, "gyro", cal.GyroMatrix(), &diagonal);
  if (!usable || !scale || std::abs(*scale - 1.0) <= kMaxScaleError) return std::nullopt;
  const std::string what = "the gyroscope's scale came out " + Num(*scale) +
                           " (gyro.matrix diagonal " + diagonal + "), not about 1: ";
  if (std::abs(*scale / units::kDegPerRad - 1.0) < 0.15) {
    return Gate{"unit_or_rate", what + "the samples look like deg/s, not rad/s: give --gyr-unit deg/s"};
  }
  if (std::abs(*scale * units::kDegPerRad - 1.0) < 0.15) {
    return Gate{"unit_or_rate",
                what + "the samples look like rad/s, given as deg/s: drop --gyr-unit deg/s"};
  }
  const double dt = series.median_dt_s();
  return Gate{"unit_or_rate",
              what + "the turns integrate to " + Num(*scale) +
                  " times the angles the accelerometer sees between the poses, so the sample "
                  "times are likely wrong by that factor: the samples are " + Num(dt) +
                  " s apart (" + Num(1.0 / dt) + " Hz), the turns say about " +
                  Num(*scale / dt) + " Hz (check --rate, or the time column's unit)"};
}

/// The free parameters of the gyroscope's matrix (its linear stage's block before the bias,
/// model/effects/gyro_linear.h) that the fit leaves undetermined, or determines only to more
/// than kNotATurnMatrixSigma (Earth rate alone), by name.
std::vector<std::string> UndeterminedGyroMatrix(const Calibration& cal) {
  std::vector<std::string> out;
  const int base = cal.model.BaseTerm(model::Sensor::kGyro);
  if (!cal.has_gyro || base < 0) return out;
  const auto offset = static_cast<std::size_t>(cal.model.FirstParameter(base));
  for (int i = 0; i < model::gyro_linear::kBias; ++i) {
    const std::size_t k = offset + static_cast<std::size_t>(i);
    if (k >= cal.parameters.size()) break;
    const ParameterEstimate& p = cal.parameters[k];
    if (!p.fixed && (!p.observable || !(p.sigma <= kNotATurnMatrixSigma))) out.push_back(p.name);
  }
  return out;
}

/// not_a_turn: motion left out where no turn is left to determine the gyroscope's matrix.
std::optional<Gate> NotATurnGate(const Calibration& cal, const FitReport& fit) {
  if (fit.not_turns.empty()) return std::nullopt;
  const std::vector<std::string> undetermined = UndeterminedGyroMatrix(cal);
  if (undetermined.empty()) return std::nullopt;
  std::string what;
  for (const NotATurn& m : fit.not_turns) what += (what.empty() ? "" : "; ") + NotATurnText(fit, m);
  return Gate{"not_a_turn", what + "; without it the turns left (" +
                                std::to_string(fit.motion_segments) + ") leave " +
                                Count(undetermined.size(), "parameter") +
                                " of the gyroscope's matrix undetermined or known only to more "
                                "than " + Num(kNotATurnMatrixSigma) + " (" + undetermined.front() +
                                (undetermined.size() > 1 ? ", ..." : "") +
                                "): record turns of seconds between the still poses"};
}

}  // namespace

std::string NotATurnText(const FitReport& fit, const NotATurn& m) {
  auto label = [&](std::size_t k) {
    return k < fit.still.size() ? "'" + fit.still[k].segment.label + "'" : "#" + std::to_string(k);
  };
  const std::string motion = "the motion " + Tenth(m.t_begin_s) + "-" + Tenth(m.t_end_s) +
                             " s (" + Tenth(m.t_end_s - m.t_begin_s) + " s) between " +
                             label(m.from) + " and " + label(m.to) +
                             " is left out of the fit, not a turn: ";
  if (m.flown) {
    return motion + "the log says the vehicle was " + Describe(*m.flown) +
           ", a flight or a vehicle carried, whose vibration and translation logged samples "
           "do not resolve";
  }
  return motion + "longer than " + Num(m.limit_s) +
         " s, more than a MEMS gyroscope integrates to its noise (a flight, a vehicle carried)";
}

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

int CountDistinctPoses(const ImuSeries& series, const std::vector<StillSegmentFit>& still,
                       const NoiseLevels& noise) {
  const auto rest = AtRest(still);
  int poses = rest.empty() ? 0 : 1;
  for (std::size_t k = 1; k < rest.size(); ++k) {
    const bool same = SameGravity(*rest[k - 1], *rest[k], noise) &&
                      NoTurn(series, *rest[k - 1], *rest[k], noise);
    poses += same ? 0 : 1;
  }
  return poses;
}

namespace {

/// Per-sample scatter, the largest axis's RMS about the mean, of `v` over [begin, end).
double Scatter(const std::vector<Vec3f>& v, std::size_t begin, std::size_t end) {
  if (end <= begin + 1) return 0.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero();
  for (std::size_t k = begin; k < end; ++k) {
    const Eigen::Vector3d x = v[k].cast<double>();
    sum += x;
    sum2 += x.cwiseProduct(x);
  }
  const double n = static_cast<double>(end - begin);
  const Eigen::Vector3d mean = sum / n;
  return ((sum2 / n - mean.cwiseProduct(mean)).cwiseMax(0.0)).cwiseSqrt().maxCoeff();
}

/// One sensor's scatter per segment, SI: as logged for SI samples (`si`), else divided by the
/// fitted scale (counts per SI unit). SI samples are not divided by the fit's scale: a fit
/// left without turns (not_a_turn) or poses (one_pose) leaves it undetermined, at any value.
std::vector<double> ScatterSi(const std::vector<Vec3f>& v,
                              const std::vector<const StillSegmentFit*>& still,
                              const Mat3& matrix, bool si) {
  const double scale = si ? 1.0 : matrix.diagonal().cwiseAbs().mean();
  std::vector<double> out;
  for (const StillSegmentFit* s : still) {
    out.push_back(Scatter(v, s->segment.begin, s->segment.end) / (scale > 0 ? scale : 1.0));
  }
  return out;
}

/// Why segment k of one sensor is not still ("" when it is).
std::string Unstill(const std::vector<double>& scatter, std::size_t k, double limit,
                    double floor, const char* sensor, const char* unit) {
  const double quietest =
      std::max(floor, *std::min_element(scatter.begin(), scatter.end()));
  const bool loud = scatter[k] > limit;
  const bool apart = scatter.size() > 1 && scatter[k] > kNotStillRatio * quietest;
  if (!loud && !apart) return "";
  return std::string(sensor) + " " + Num(scatter[k]) + " " + unit + " (" +
         Num(scatter[k] / quietest) + " times the quietest segment's" +
         (loud ? ", above " + Num(limit) + " " + unit : std::string()) + ")";
}

/// The not_still gate (gates.h).
std::optional<Gate> NotStill(const ImuSeries& series, const Calibration& cal,
                             const std::vector<LogMotion>& log_motion, const FitReport& fit) {
  // At rest only: a turntable's spinning segments are meant to move.
  const std::vector<const StillSegmentFit*> rest = AtRest(fit.still);
  if (rest.empty()) return std::nullopt;
  const std::vector<double> acc = ScatterSi(series.acc, rest, cal.AccelMatrix(), SiAccel(series));
  const bool gyro = cal.has_gyro && series.has_gyro();
  const std::vector<double> gyr =
      gyro ? ScatterSi(series.gyr, rest, cal.GyroMatrix(), SiGyro(series)) : std::vector<double>();
  std::string list;
  int count = 0;
  bool flown = false;  // some segment falls where the log says the vehicle flew or moved
  for (std::size_t k = 0; k < rest.size(); ++k) {
    std::string why = Unstill(acc, k, kNotStillAccel, kStillScatterFloorAccel,
                              "accelerometer", "m/s^2");
    if (gyro) {
      const std::string g =
          Unstill(gyr, k, kNotStillGyro, kStillScatterFloorGyro, "gyroscope", "rad/s");
      if (!g.empty()) why += (why.empty() ? "" : ", ") + g;
    }
    const StillSegment& seg = rest[k]->segment;
    for (const LogMotion& m : log_motion) {
      if (!m.Covers(series.t_s[seg.begin], series.t_s[seg.end - 1])) continue;
      why += (why.empty() ? "" : ", ") + std::string("the log says the vehicle was ") + Describe(m);
      flown = true;
      break;
    }
    if (why.empty()) continue;
    ++count;
    if (count <= 3) {
      const StillSegmentFit& s = *rest[k];
      list += std::string(list.empty() ? "" : "; ") + "'" + s.segment.label + "' (" +
              Tenth(series.t_s[s.segment.begin]) + "-" + Tenth(series.t_s[s.segment.end - 1]) +
              " s): " + why;
    }
  }
  if (count == 0) return std::nullopt;
  return Gate{"not_still",
              std::to_string(count) + " of " + std::to_string(rest.size()) +
                  " still segments scatter far beyond an IMU at rest, per sample" +
                  (flown ? ", or fall where the log says the vehicle flew or moved" : "") +
                  ": " + list +
                  (count > 3 ? "; ..." : "") +
                  ". A flight, running motors or a vehicle carried is not a still pose, and "
                  "the noise measured there is motion: give the still periods (a segments "
                  "file, or the log's time window before take-off)"};
}

}  // namespace

std::vector<Gate> CheckFit(const ImuSeries& series, const Calibration& calibration,
                           const std::vector<LogMotion>& log_motion, FitReport& fit) {
  std::vector<Gate> gates;
  if (!fit.converged) gates.push_back(NotConverged(fit));
  const auto one_pose = OnePose(series, calibration, fit);
  if (one_pose) gates.push_back(*one_pose);
  if (fit.converged && !one_pose) {
    if (auto g = Nonlinear(fit)) gates.push_back(*g);
  }
  if (auto g = NotStill(series, calibration, log_motion, fit)) gates.push_back(*g);
  if (auto g = NotATurnGate(calibration, fit)) gates.push_back(*g);
  const auto rest = Plausible(AtRest(fit.still), calibration);
  if (rest.empty()) return gates;
  const bool usable = fit.converged && !one_pose;
  if (auto g = AccelUnit(calibration, rest, usable)) gates.push_back(*g);
  if (auto g = GyroUnitOrRate(series, calibration, rest, usable)) gates.push_back(*g);
  return gates;
}

std::vector<Gate> CheckGates(const ImuSeries& series, const std::vector<StillSegment>& still,
                             const Calibration& calibration,
                             const std::vector<LogMotion>& log_motion, FitReport& fit) {
  std::vector<Gate> gates = CheckSamples(series, still);
  for (auto& g : CheckFit(series, calibration, log_motion, fit)) gates.push_back(std::move(g));
  return gates;
}

}  // namespace plumb::estimation

#include "plumb/diagnostics/residual_analysis.h"

#include <iomanip>

#include <sstream>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "plumb/core/error.h"
#include "plumb/core/so3.h"
#include "plumb/signal/allan.h"
#include "plumb/signal/segment_stats.h"

namespace plumb::diagnostics {
namespace {

using estimation::CalibrationResult;
using estimation::StillSegmentFit;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void Validate(const ResidualAnalysisOptions& o) {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw Error("residual analysis: " + what);
  };
  check(o.sample_stride >= 1, "sample_stride must be >= 1");
  check(o.significance > 0.0 && o.significance < 0.5, "significance must be in (0, 0.5)");
  check(o.min_points >= 4, "min_points must be >= 4");
  check(o.worst_count >= 1, "worst_count must be >= 1");
  check(o.stretch_s > 0.0 && std::isfinite(o.stretch_s), "stretch_s must be > 0 and finite");
  check(o.allan_length_fraction > 0.0 && o.allan_length_fraction <= 1.0,
        "allan_length_fraction must be in (0, 1]");
  check(o.allan_min_clusters >= 2, "allan_min_clusters must be >= 2");
  check(o.allan_points_per_decade >= 1 && o.allan_points_per_decade <= 100,
        "allan_points_per_decade must be in [1, 100]");
}

std::string TimeText(double t0_s, double t1_s) {
  char buf[64];
  std::snprintf(buf, sizeof buf, " %.1f-%.1f s", t0_s, t1_s);
  return buf;
}

/// The model's inputs on still segment `s` at time t_s and temperature temp_c (NaN: none),
/// as the still residuals form them (model::AtRest).
model::SensorInput<double> StillInput(const CalibrationResult& fit, const StillSegmentFit& s,
                                      double t_s, double temp_c) {
  const model::Model& m = fit.calibration.model;
  return model::AtRest<double>(s.R_n_b.toRotationMatrix().transpose(), fit.calibration.site.g_n,
                               fit.calibration.site.omega_ie_n,
                               s.segment.known_omega_eb_b.value_or(Vec3::Zero()), t_s - m.t_ref_s,
                               std::isfinite(temp_c) ? temp_c - m.temp_ref_c : 0.0);
}

/// Model::Predict on the fit's blocks.
struct Predictor {
  explicit Predictor(const CalibrationResult& fit) : model(&fit.calibration.model) {
    for (const auto& b : fit.calibration.theta) blocks.push_back(b.data());
  }
  model::SensorOutput<double> operator()(const model::SensorInput<double>& in) const {
    return model->Predict(blocks.data(), in);
  }
  const model::Model* model;
  std::vector<const double*> blocks;
};

SegmentComparison CompareSegment(const ImuSeries& series, const CalibrationResult& fit,
                                 const Predictor& predict, std::size_t k, bool still_gyro) {
  const StillSegmentFit& s = fit.fit.still[k];
  const signal::SegmentStats stats = signal::ComputeSegmentStats(series, s.segment);
  SegmentComparison c;
  c.index = k;
  c.label = s.segment.label;
  c.t_begin_s = stats.t_begin_s;
  c.t_end_s = stats.t_end_s;
  c.t_mid_s = stats.t_mid_s;
  c.temp_c = stats.temp_mean_c;
  const model::SensorInput<double> in = StillInput(fit, s, stats.t_mid_s, stats.temp_mean_c);
  const model::SensorOutput<double> out = predict(in);
  c.f_b = in.f_b;
  c.omega_b = in.omega_b;
  c.has_acc = !s.segment.spinning();
  c.has_gyr = still_gyro;
  if (c.has_acc) {
    c.acc_measured = s.acc_mean;
    c.acc_predicted = out.acc;
    c.acc_residual = s.acc_residual;
    c.acc_whitened = s.acc_whitened;
  }
  if (c.has_gyr) {
    c.gyr_measured = s.gyr_mean;
    c.gyr_predicted = out.gyr;
    c.gyr_residual = s.gyr_residual;
    c.gyr_whitened = s.gyr_whitened;
  }
  c.whitened_norm = std::sqrt(c.acc_whitened.squaredNorm() + c.gyr_whitened.squaredNorm());
  return c;
}

MotionComparison CompareMotion(const ImuSeries& series, const CalibrationResult& fit,
                               std::size_t k) {
  const estimation::MotionFit& m = fit.fit.motion[k];
  const StillSegmentFit& a = fit.fit.still[m.from];
  const StillSegmentFit& b = fit.fit.still[m.to];
  MotionComparison c;
  c.index = k;
  c.from = m.from;
  c.to = m.to;
  const std::size_t first = a.segment.end - 1, last = b.segment.begin;
  c.t_begin_s = series.t_s[first];
  c.t_end_s = series.t_s[last];
  const Mat3 A = a.R_n_b.toRotationMatrix().transpose() * b.R_n_b.toRotationMatrix();
  c.rotation_attitudes = so3::Log(A);
  c.rotation_gyro = so3::Log(A * so3::Exp(-m.rotation_residual));
  c.residual = m.rotation_residual;
  c.whitened = m.whitened;
  c.whitened_norm = m.whitened.norm();
  // Rates from the raw gyroscope through the fit's linear part; angular acceleration by
  // central differences, as the backend forms alpha_b.
  const Mat3 E_inv = fit.calibration.GyroMatrix().inverse();
  auto rate = [&](std::size_t i) {
    return Vec3(E_inv * (series.gyr[i].cast<double>() - fit.calibration.GyroBias()));
  };
  for (std::size_t i = first; i <= last; ++i) {
    const Vec3 w = rate(i);
    c.mean_rate += w.norm();
    c.mean_rate2 += w.squaredNorm();
    const std::size_t lo = i > 0 ? i - 1 : i, hi = std::min(i + 1, series.size() - 1);
    const double h = series.t_s[hi] - series.t_s[lo];
    if (h > 0) c.max_angular_acc = std::max(c.max_angular_acc, (rate(hi) - rate(lo)).norm() / h);
  }
  const double n = static_cast<double>(last - first + 1);
  c.mean_rate /= n;
  c.mean_rate2 /= n;
  return c;
}

/// Full-rate predictions and residuals of one still segment (NaN where absent).
struct SegmentSamples {
  std::vector<Vec3> acc_predicted, acc_residual, gyr_predicted, gyr_residual;
};

SegmentSamples PredictSamples(const ImuSeries& series, const CalibrationResult& fit,
                              const Predictor& predict, const SegmentComparison& c) {
  const StillSegmentFit& s = fit.fit.still[c.index];
  SegmentSamples out;
  const Vec3 none = Vec3::Constant(kNaN);
  for (std::size_t i = s.segment.begin; i < s.segment.end; ++i) {
    const double temp_c = series.has_temperature() ? series.temp_c[i] : kNaN;
    const model::SensorOutput<double> y = predict(StillInput(fit, s, series.t_s[i], temp_c));
    out.acc_predicted.push_back(c.has_acc ? y.acc : none);
    out.acc_residual.push_back(c.has_acc ? Vec3(series.acc[i].cast<double>() - y.acc) : none);
    out.gyr_predicted.push_back(c.has_gyr ? y.gyr : none);
    out.gyr_residual.push_back(c.has_gyr ? Vec3(series.gyr[i].cast<double>() - y.gyr) : none);
  }
  return out;
}

void AppendSamples(const ImuSeries& series, const CalibrationResult& fit,
                   const SegmentComparison& c, const SegmentSamples& s, std::size_t stride,
                   SampleResiduals& out) {
  const std::size_t begin = fit.fit.still[c.index].segment.begin;
  for (std::size_t j = 0; j < s.acc_residual.size(); j += stride) {
    out.sample.push_back(begin + j);
    out.segment.push_back(c.index);
    out.t_s.push_back(series.t_s[begin + j]);
    out.acc_predicted.push_back(s.acc_predicted[j]);
    out.acc_residual.push_back(s.acc_residual[j]);
    out.gyr_predicted.push_back(s.gyr_predicted[j]);
    out.gyr_residual.push_back(s.gyr_residual[j]);
    out.acc_normalised.push_back(s.acc_residual[j].cwiseQuotient(fit.calibration.noise.acc));
    out.gyr_normalised.push_back(s.gyr_residual[j].cwiseQuotient(fit.calibration.noise.gyr));
  }
}

/// Largest |component| of a whitened residual: (score, axis).
std::pair<double, int> Largest(const Vec3& w) {
  Eigen::Index axis = 0;
  const double score = w.cwiseAbs().maxCoeff(&axis);
  return {score, static_cast<int>(axis)};
}

void AddRange(WorstRange::Kind kind, std::size_t index, double t0, double t1, std::string name,
              ResidualKind residual, const Vec3& w, std::vector<WorstRange>& out) {
  const auto [score, axis] = Largest(w);
  out.push_back({kind, index, t0, t1, std::move(name) + TimeText(t0, t1), residual, axis, score});
}

/// Sums of the residual over one stretch of a long still segment.
struct Stretch {
  std::size_t index = 0;  ///< fit.fit.still index
  double t0_s = 0, t1_s = 0;
  std::string label;
  Vec3 acc = Vec3::Zero(), gyr = Vec3::Zero();  ///< sums of the residuals, series' units
  double count = 0;
};

/// Cuts a still segment of at least two stretch_s into stretches of about stretch_s.
void AddStretches(const ImuSeries& series, const CalibrationResult& fit,
                  const SegmentComparison& c, const SegmentSamples& s, double stretch_s,
                  std::vector<Stretch>& out) {
  const double length_s = c.t_end_s - c.t_begin_s;
  const auto blocks = static_cast<std::size_t>(std::floor(length_s / stretch_s));
  const std::size_t n = s.acc_residual.size(), begin = fit.fit.still[c.index].segment.begin;
  for (std::size_t b = 0; blocks >= 2 && b < blocks; ++b) {
    const std::size_t i0 = n * b / blocks, i1 = n * (b + 1) / blocks;
    Stretch st{c.index, series.t_s[begin + i0], series.t_s[begin + i1 - 1], c.label};
    for (std::size_t i = i0; i < i1; ++i) {
      if (c.has_acc) st.acc += s.acc_residual[i];
      if (c.has_gyr) st.gyr += s.gyr_residual[i];
    }
    st.count = static_cast<double>(i1 - i0);
    out.push_back(st);
  }
}

/// Scores stretches by z = sum(r) / (sqrt(n) sigma_white) per sensor and axis (0 where the
/// white level is not positive).
void ScoreStretches(const std::vector<Stretch>& stretches, const Vec3& white_acc,
                    const Vec3& white_gyr, std::vector<WorstRange>& out) {
  auto z = [](const Vec3& sum, const Vec3& white, double n) {
    return Vec3((white.array() > 0).select(sum.array() / (white.array() * std::sqrt(n)), 0.0));
  };
  for (const Stretch& st : stretches) {
    const Vec3 acc = z(st.acc, white_acc, st.count);
    const Vec3 gyr = z(st.gyr, white_gyr, st.count);
    const bool gyro_worse = Largest(gyr).first > Largest(acc).first;
    AddRange(WorstRange::Kind::kStretch, st.index, st.t0_s, st.t1_s,
             "stretch of still '" + st.label + "'",
             gyro_worse ? ResidualKind::kStillGyro : ResidualKind::kStillAccel,
             gyro_worse ? gyr : acc, out);
  }
}

/// Least-squares line y = a + slope x: correlation, slope and its standard error.
struct LineFit {
  bool ok = false;  ///< x and y both vary
  double r = 0, slope = 0, slope_sigma = 0;
};

LineFit FitLine(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const double my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxx = 0, syy = 0, sxy = 0, scale = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
    sxy += (x[i] - mx) * (y[i] - my);
    scale = std::max(scale, std::abs(x[i]));
  }
  LineFit f;
  // A regressor constant to rounding (e.g. Earth rate's norm on still poses) is no test.
  if (!(sxx > n * std::pow(1e-9 * scale, 2)) || !(syy > 0)) return f;
  f.ok = true;
  f.r = std::clamp(sxy / std::sqrt(sxx * syy), -1.0, 1.0);
  f.slope = sxy / sxx;
  f.slope_sigma = std::sqrt(std::max(0.0, syy - f.slope * sxy) / (n - 2.0) / sxx);
  return f;
}

/// One regressor's values at the points of a test.
struct Regressor {
  std::string name, unit;
  std::vector<double> x;
};

std::vector<Regressor> StillRegressors(const std::vector<const SegmentComparison*>& segs,
                                       double t0_s, bool temperature) {
  std::vector<Regressor> regs = {{"time", "s", {}}};
  if (temperature) regs.push_back({"temperature", "degC", {}});
  for (int j = 0; j < 3; ++j) regs.push_back({std::string("f_b.") + kAxisName[j], "m/s^2", {}});
  for (int j = 0; j < 3; ++j) {
    regs.push_back({std::string("f_b.") + kAxisName[j] + "^2", "m^2/s^4", {}});
  }
  regs.push_back({"|omega|", "rad/s", {}});
  regs.push_back({"|omega|^2", "rad^2/s^2", {}});
  for (const SegmentComparison* s : segs) {
    std::size_t r = 0;
    regs[r++].x.push_back(s->t_mid_s - t0_s);
    if (temperature) regs[r++].x.push_back(s->temp_c);
    for (int j = 0; j < 3; ++j) regs[r++].x.push_back(s->f_b[j]);
    for (int j = 0; j < 3; ++j) regs[r++].x.push_back(s->f_b[j] * s->f_b[j]);
    regs[r++].x.push_back(s->omega_b.norm());
    regs[r++].x.push_back(s->omega_b.squaredNorm());
  }
  return regs;
}

/// Every (regressor, axis) test of one residual kind over its points.
void AddTests(ResidualKind kind, const std::vector<Vec3>& whitened,
              const std::vector<Vec3>& residual, const std::vector<Regressor>& regs,
              int min_points, std::vector<Signature>& out) {
  if (static_cast<int>(whitened.size()) < min_points) return;
  for (const Regressor& reg : regs) {
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<double> w, r;
      for (std::size_t i = 0; i < whitened.size(); ++i) {
        w.push_back(whitened[i][axis]);
        r.push_back(residual[i][axis]);
      }
      const LineFit fw = FitLine(reg.x, w);
      if (!fw.ok) continue;
      const LineFit fr = FitLine(reg.x, r);
      Signature s;
      s.residual = kind;
      s.axis = axis;
      s.regressor = reg.name;
      s.unit = reg.unit;
      s.points = static_cast<int>(w.size());
      s.correlation = fw.r;
      s.slope = fw.slope;
      s.slope_sigma = fw.slope_sigma;
      s.slope_residual = fr.slope;
      s.slope_residual_sigma = fr.slope_sigma;
      const double z = std::atanh(std::abs(fw.r)) * std::sqrt(s.points - 3.0);
      s.p_value = std::erfc(z / std::sqrt(2.0));
      out.push_back(s);
    }
  }
}

std::vector<Signature> Signatures(const ResidualAnalysis& a, double t0_s, bool temperature,
                                  int min_points) {
  std::vector<Signature> out;
  for (const ResidualKind kind : {ResidualKind::kStillAccel, ResidualKind::kStillGyro}) {
    const bool accel = kind == ResidualKind::kStillAccel;
    std::vector<const SegmentComparison*> segs;
    std::vector<Vec3> w, r;
    for (const auto& s : a.still) {
      if (!(accel ? s.has_acc : s.has_gyr)) continue;
      segs.push_back(&s);
      w.push_back(accel ? s.acc_whitened : s.gyr_whitened);
      r.push_back(accel ? s.acc_residual : s.gyr_residual);
    }
    AddTests(kind, w, r, StillRegressors(segs, t0_s, temperature), min_points, out);
  }
  std::vector<Regressor> regs = {{"|omega|", "rad/s", {}},
                                 {"|omega|^2", "rad^2/s^2", {}},
                                 {"max |alpha|", "rad/s^2", {}}};
  std::vector<Vec3> w, r;
  for (const auto& m : a.motion) {
    regs[0].x.push_back(m.mean_rate);
    regs[1].x.push_back(m.mean_rate2);
    regs[2].x.push_back(m.max_angular_acc);
    w.push_back(m.whitened);
    r.push_back(m.residual);
  }
  AddTests(ResidualKind::kMotion, w, r, regs, min_points, out);
  return out;
}

/// The still segments pooled for the Allan deviation and the cluster sizes (empty: none).
std::pair<std::vector<std::size_t>, std::vector<std::size_t>> AllanPlan(
    const CalibrationResult& fit, const ResidualAnalysisOptions& o) {
  std::size_t longest = 0;
  for (const auto& s : fit.fit.still) {
    if (!s.segment.spinning()) longest = std::max(longest, s.segment.count());
  }
  std::vector<std::size_t> segments;
  std::size_t shortest = longest;
  for (std::size_t k = 0; k < fit.fit.still.size(); ++k) {
    const StillSegment& seg = fit.fit.still[k].segment;
    const double fraction = static_cast<double>(seg.count()) / static_cast<double>(longest);
    if (seg.spinning() || fraction < o.allan_length_fraction) continue;
    segments.push_back(k);
    shortest = std::min(shortest, seg.count());
  }
  const std::size_t m_max = shortest / static_cast<std::size_t>(o.allan_min_clusters);
  if (m_max < 2) return {};
  std::vector<std::size_t> sizes;
  for (int j = 0;; ++j) {
    const double decades = static_cast<double>(j) / o.allan_points_per_decade;
    const auto m = static_cast<std::size_t>(std::round(std::pow(10.0, decades)));
    if (m >= m_max) break;
    if (sizes.empty() || m != sizes.back()) sizes.push_back(m);
  }
  sizes.push_back(m_max);
  return {segments, sizes};
}

/// Accumulates one segment's AVAR (times its terms) per sensor and axis.
void AccumulateAllan(const SegmentSamples& s, const std::vector<std::size_t>& sizes, double dt_s,
                     bool gyro, std::vector<std::vector<double>>& weighted,
                     std::vector<std::vector<double>>& terms) {
  signal::AllanOptions options;
  options.cluster_sizes = sizes;
  std::vector<float> x(s.acc_residual.size());
  for (int sensor = 0; sensor < (gyro ? 2 : 1); ++sensor) {
    for (int axis = 0; axis < 3; ++axis) {
      const auto& r = sensor == 0 ? s.acc_residual : s.gyr_residual;
      for (std::size_t i = 0; i < r.size(); ++i) x[i] = static_cast<float>(r[i][axis]);
      const signal::AllanDeviation ad = signal::OverlappingAllanDeviation(
          signal::ViewContiguous(x.data(), x.size()), dt_s, options);
      auto& wsum = weighted[static_cast<std::size_t>(3 * sensor + axis)];
      auto& tsum = terms[static_cast<std::size_t>(3 * sensor + axis)];
      for (std::size_t j = 0; j < sizes.size(); ++j) {
        wsum[j] += ad.adev[j] * ad.adev[j] * static_cast<double>(ad.terms[j]);
        tsum[j] += static_cast<double>(ad.terms[j]);
      }
    }
  }
}

std::vector<ResidualAllan> FinishAllan(const CalibrationResult& fit,
                                       const std::vector<std::size_t>& sizes, double dt_s,
                                       const std::vector<std::vector<double>>& weighted,
                                       const std::vector<std::vector<double>>& terms) {
  std::vector<ResidualAllan> out;
  for (std::size_t c = 0; c < weighted.size(); ++c) {
    if (terms[c].empty() || terms[c][0] == 0) continue;
    const bool accel = c < 3;
    const int axis = static_cast<int>(c % 3);
    ResidualAllan a;
    a.residual = accel ? ResidualKind::kStillAccel : ResidualKind::kStillGyro;
    a.axis = axis;
    a.fit_sigma = (accel ? fit.calibration.noise.acc[axis] : fit.calibration.noise.gyr[axis]) *
                  std::sqrt(accel ? fit.calibration.noise.tau_acc : fit.calibration.noise.tau_gyr);
    for (std::size_t j = 0; j < sizes.size(); ++j) {
      a.tau_s.push_back(static_cast<double>(sizes[j]) * dt_s);
      a.adev.push_back(std::sqrt(weighted[c][j] / terms[c][j]));
    }
    // Reference: the middle of the log-spaced sizes, about sqrt(m_max).
    const std::size_t ref = (sizes.size() - 1) / 2;
    a.reference_tau_s = a.tau_s[ref];
    a.sigma_white = a.adev[ref] * std::sqrt(static_cast<double>(sizes[ref]));
    for (std::size_t m : sizes) {
      a.white.push_back(a.sigma_white / std::sqrt(static_cast<double>(m)));
    }
    a.ratio = a.adev.back() / a.white.back();
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace

const char* ResidualKindName(ResidualKind kind) {
  switch (kind) {
    case ResidualKind::kStillAccel: return "accel";
    case ResidualKind::kStillGyro: return "gyro";
    case ResidualKind::kMotion: return "motion";
  }
  return "?";
}

ResidualAnalysis AnalyseResiduals(const ImuSeries& series, const CalibrationResult& fit,
                                  const ResidualAnalysisOptions& options) {
  Validate(options);
  if (fit.calibration.has_gyro && !series.has_gyro()) {
    throw Error("residual analysis: the fit has a gyroscope but the series has none");
  }
  for (const auto& m : fit.fit.motion) {
    if (m.from >= fit.fit.still.size() || m.to >= fit.fit.still.size()) {
      throw Error("residual analysis: motion interval " + std::to_string(m.from) + "->" +
                  std::to_string(m.to) + " names a still segment the fit does not have");
    }
  }
  for (const auto& s : fit.fit.still) {
    if (s.segment.begin >= s.segment.end || s.segment.end > series.size()) {
      throw Error("residual analysis: still segment '" + s.segment.label + "' [" +
                  std::to_string(s.segment.begin) + ", " + std::to_string(s.segment.end) +
                  ") is outside the " + std::to_string(series.size()) + " samples");
    }
  }
  const bool still_gyro = fit.calibration.has_gyro && fit.fit.rms_gyr.squaredNorm() > 0;
  const Predictor predict(fit);
  ResidualAnalysis a;
  std::vector<WorstRange> ranges;
  std::vector<Stretch> stretches;
  const auto [allan_segments, sizes] = AllanPlan(fit, options);
  a.allan_segments = allan_segments;
  const double dt_s = series.median_dt_s();
  std::vector<std::vector<double>> weighted(6, std::vector<double>(sizes.size(), 0.0));
  std::vector<std::vector<double>> terms = weighted;

  for (std::size_t k = 0; k < fit.fit.still.size(); ++k) {
    const SegmentComparison c = CompareSegment(series, fit, predict, k, still_gyro);
    const SegmentSamples s = PredictSamples(series, fit, predict, c);
    AppendSamples(series, fit, c, s, options.sample_stride, a.samples);
    AddStretches(series, fit, c, s, options.stretch_s, stretches);
    if (std::find(allan_segments.begin(), allan_segments.end(), k) != allan_segments.end()) {
      AccumulateAllan(s, sizes, dt_s, still_gyro, weighted, terms);
    }
    const bool gyro_worse = Largest(c.gyr_whitened).first > Largest(c.acc_whitened).first;
    AddRange(WorstRange::Kind::kStill, k, c.t_begin_s, c.t_end_s, "still '" + c.label + "'",
             gyro_worse ? ResidualKind::kStillGyro : ResidualKind::kStillAccel,
             gyro_worse ? c.gyr_whitened : c.acc_whitened, ranges);
    a.still.push_back(c);
  }
  for (std::size_t k = 0; k < fit.fit.motion.size(); ++k) {
    const MotionComparison m = CompareMotion(series, fit, k);
    AddRange(WorstRange::Kind::kMotion, k, m.t_begin_s, m.t_end_s,
             "motion " + std::to_string(m.from) + "->" + std::to_string(m.to),
             ResidualKind::kMotion, m.whitened, ranges);
    a.motion.push_back(m);
  }
  if (!sizes.empty()) a.allan = FinishAllan(fit, sizes, dt_s, weighted, terms);
  // Stretches against the white level of the residual (the fit's when there is no Allan).
  Vec3 white_acc = fit.calibration.noise.acc * std::sqrt(fit.calibration.noise.tau_acc);
  Vec3 white_gyr = fit.calibration.noise.gyr * std::sqrt(fit.calibration.noise.tau_gyr);
  for (const auto& x : a.allan) {
    (x.residual == ResidualKind::kStillAccel ? white_acc : white_gyr)[x.axis] = x.sigma_white;
  }
  ScoreStretches(stretches, white_acc, white_gyr, ranges);
  auto rank = [](const auto& items) {
    std::vector<std::size_t> order(items.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
      return items[i].whitened_norm > items[j].whitened_norm;
    });
    return order;
  };
  a.still_rank = rank(a.still);
  a.motion_rank = rank(a.motion);
  std::stable_sort(ranges.begin(), ranges.end(),
                   [](const WorstRange& x, const WorstRange& y) { return x.score > y.score; });
  ranges.resize(std::min(ranges.size(), options.worst_count));
  a.worst = std::move(ranges);

  a.signatures = Signatures(a, series.t_s.front(), series.has_temperature(), options.min_points);
  a.num_tests = static_cast<int>(a.signatures.size());
  a.p_threshold = options.significance / std::max(1, a.num_tests);
  for (auto& s : a.signatures) s.significant = s.p_value < a.p_threshold;
  return a;
}

}  // namespace plumb::diagnostics

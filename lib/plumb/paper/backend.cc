// plumb/paper/backend.cc — see backend.h.
#include "plumb/paper/backend.h"

#include <algorithm>
#include <cmath>

#include "plumb/core/error.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/initialization.h"
#include "plumb/model/model.h"

namespace plumb::paper {

PaperBenchmarkBackend CalibratePaperBenchmarkOnBackend(const ImuSeries& series,
                                                       const PaperBenchmarkResult& closed,
                                                       const geo::Site& site,
                                                       double max_tilt_rad) {
  PaperBenchmarkBackend out;
  for (const StillPeriod& p : closed.still) {
    if (p.pose.axis < 0 || p.pose.tilt_rad > max_tilt_rad) continue;
    StillSegment s = p.segment;
    // The paper's assumption: the axis is exactly along gravity ("parallel": it points down).
    Vec3 down_b = Vec3::Zero();
    down_b[p.pose.axis] = p.pose.parallel ? 1.0 : -1.0;
    s.known_R_n_b = estimation::AttitudeFromDown(down_b, 0.0);
    s.heading_free = true;
    s.known_omega_eb_b.reset();
    out.segments.push_back(s);
  }
  for (const TurnPeriod& turn : closed.turns) {
    const std::size_t n = turn.range.end - turn.range.begin;
    // The segment mean of N samples spans N sample intervals: duration = span * N / (N - 1).
    const double span = series.t_s[turn.range.end - 1] - series.t_s[turn.range.begin];
    if (n < 2 || !(span > 0.0)) continue;
    const double duration = span * static_cast<double>(n) / static_cast<double>(n - 1);
    StillSegment s;
    s.begin = turn.range.begin;
    s.end = turn.range.end;
    s.label = turn.range.label;
    Vec3 omega = Vec3::Zero();
    omega[turn.axis] = turn.nominal_angle_rad / duration;
    s.known_omega_eb_b = omega;
    // The attitude enters only through Earth rate, R^T omega_ie: its horizontal part (up to
    // 7.3e-5 rad/s) is not negligible against the noise of a turn's mean rate (5e-5 rad/s for
    // 3 s at 200 Hz of a typical MEMS gyro), so the heading is estimated like a face's; the
    // tilt is that of the mean specific force over the turn.
    Vec3 acc_mean = Vec3::Zero();
    for (std::size_t k = s.begin; k < s.end; ++k) acc_mean += series.acc[k].cast<double>();
    s.known_R_n_b =
        acc_mean.norm() > 0.0 ? estimation::AttitudeFromDown(-acc_mean, 0.0) : Quat::Identity();
    s.heading_free = true;
    out.segments.push_back(s);
  }
  std::sort(out.segments.begin(), out.segments.end(),
            [](const StillSegment& a, const StillSegment& b) { return a.begin < b.begin; });

  out.model_spec = "accel_linear:full+gyro_linear+gyro_bias_drift";
  model::Model model = model::Model::Parse(out.model_spec);
  model.t_ref_s = closed.t0_s;
  estimation::CalibrationOptions options;
  options.method = "paper-benchmark (backend)";
  options.use_motion = false;
  options.constant_bias = true;  // the paper's method: one bias per session
  out.result = estimation::Calibrate(series, out.segments, model, site, options);
  return out;
}

const std::vector<MatrixEntryRef>& PaperStaticFixedEntries() {
  using model::Sensor;
  static const std::vector<MatrixEntryRef> entries = {
      {Sensor::kAccel, 0, 0}, {Sensor::kAccel, 1, 1}, {Sensor::kAccel, 0, 1},
      {Sensor::kGyro, 0, 0},  {Sensor::kGyro, 1, 1},  {Sensor::kGyro, 0, 1}};
  return entries;
}

PaperStaticBackend CalibratePaperStaticOnBackend(const ImuSeries& series, std::size_t begin,
                                                 std::size_t end, const geo::Site& site) {
  if (begin >= end || end > series.size()) {
    throw Error("paper-static (backend): sample range [" + std::to_string(begin) + ", " +
                std::to_string(end) + ") is not inside the " + std::to_string(series.size()) +
                " samples");
  }
  StillSegment s;
  s.begin = begin;
  s.end = end;
  s.label = "level, x north";
  s.known_R_n_b = Quat::Identity();  // R_n_b = I: body axes along north, east, down
  const std::vector<StillSegment> segments = {s};

  estimation::CalibrationOptions options;
  options.method = "paper-static (backend)";
  options.use_motion = false;
  options.constant_bias = true;  // the paper's method: one bias per session

  model::Model freed = model::Model::Parse("paper");
  freed.t_ref_s = series.t_s.front();
  if (!site.known && freed.has_gyro()) freed.DropGyro();  // no Earth rate: nothing to fit
  model::Model fixed = freed;
  for (const MatrixEntryRef& e : PaperStaticFixedEntries()) {
    if (const auto place = fixed.MatrixEntry(e.sensor, e.row, e.col)) fixed.Fix(*place);
  }

  PaperStaticBackend out;
  out.fixed = estimation::Calibrate(series, segments, fixed, site, options);
  options.method = "paper-static (backend, the paper's constants freed)";
  out.freed = estimation::Calibrate(series, segments, freed, site, options);
  const estimation::Calibration& c = out.freed.calibration;
  for (const MatrixEntryRef& e : PaperStaticFixedEntries()) {
    const auto place = c.model.MatrixEntry(e.sensor, e.row, e.col);
    if (!place) continue;  // no gyroscope in the data
    const auto it = std::find_if(c.parameters.begin(), c.parameters.end(),
                                 [&](const estimation::ParameterEstimate& p) { return p.place == *place; });
    (it->observable ? out.fixed_observable : out.fixed_unobservable).push_back(it->name);
  }
  return out;
}

}  // namespace plumb::paper

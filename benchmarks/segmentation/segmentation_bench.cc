// Still-segment detection speed (SPEC section 7: segmenting costs one pass over the samples).
//   BM_Detect/OneHour1kHz*: a simulated one-hour 1 kHz session (3.6 M samples), built
//   deterministically: 60 poses of 55 s still, 5 s smooth 90 degree turns between them.
//   BM_Detect/MikoffImu0: the real 160 s, 100 Hz log when ../shared/data is present.
//   BM_CorrelationTime_Drifting: the noise's correlation-time estimate on a drifting axis.
// items_per_second is samples per second. The `segments` counter of the one-hour runs reads
// 60 plus the splits that false_alarm (1e-3 per window length, Bonferroni-bounded) allows in
// about 3240 s of stillness: 63 with the gyroscope tests, 60 without.
#include <cmath>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "plumb/segmentation/still_detector.h"
#include "plumb/signal/correlation_time.h"
#include "plumb/signal/segment_stats.h"

namespace {

using plumb::ImuSeries;
using plumb::Mat3;
using plumb::Vec3;

const ImuSeries& OneHourAt1kHz() {
  static const ImuSeries series = [] {
    const double kPi = 3.14159265358979323846;
    const double rate_hz = 1000.0;
    const double dt = 1.0 / rate_hz;
    const std::size_t still_n = 55000;
    const std::size_t turn_n = 5000;
    std::mt19937_64 rng(20240601);
    std::normal_distribution<float> unit(0.0F, 1.0F);
    ImuSeries s;
    s.reserve(60 * (still_n + turn_n));
    Mat3 R_n_b = Mat3::Identity();
    const Vec3 axes[3] = {Vec3::UnitX(), Vec3::UnitY(), Vec3(1.0, 1.0, 0.0).normalized()};
    for (int pose = 0; pose < 60; ++pose) {
      for (std::size_t k = 0; k < still_n + turn_n; ++k) {
        double rate = 0.0;
        if (k >= still_n) {
          const double tau = (static_cast<double>(k - still_n) + 0.5) / turn_n;
          rate = (kPi / 2.0) / (turn_n * dt) * (1.0 - std::cos(2.0 * kPi * tau));
        }
        const Vec3& axis = axes[pose % 3];
        const Vec3 f_b = R_n_b.transpose() * Vec3(0.0, 0.0, -9.80665);
        const Vec3 w_b = R_n_b.transpose() * (rate * axis);
        s.t_s.push_back(static_cast<double>(s.t_s.size()) * dt);
        s.acc.emplace_back(static_cast<float>(f_b.x()) + 0.03F * unit(rng),
                           static_cast<float>(f_b.y()) + 0.03F * unit(rng),
                           static_cast<float>(f_b.z()) + 0.03F * unit(rng));
        s.gyr.emplace_back(static_cast<float>(w_b.x()) + 0.004F * unit(rng) + 0.002F,
                           static_cast<float>(w_b.y()) + 0.004F * unit(rng) - 0.001F,
                           static_cast<float>(w_b.z()) + 0.004F * unit(rng));
        if (rate != 0.0) R_n_b = Eigen::AngleAxisd(rate * dt, axis).toRotationMatrix() * R_n_b;
      }
    }
    return s;
  }();
  return series;
}

ImuSeries ReadMikoffImu0() {
  ImuSeries s;
  std::ifstream in(std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log");  // bundled
  float v[6];
  while (in >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5]) {
    s.t_s.push_back(0.01 * static_cast<double>(s.t_s.size()));
    s.acc.emplace_back(v[0], v[1], v[2]);
    s.gyr.emplace_back(v[3], v[4], v[5]);
  }
  return s;
}

void RunDetection(benchmark::State& state, const ImuSeries& series,
                  const plumb::segmentation::StillDetectorOptions& options) {
  std::size_t found = 0;
  for (auto _ : state) {
    const auto result = plumb::segmentation::DetectStillSegments(series, options);
    found = result.segments.size();
    benchmark::DoNotOptimize(found);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * series.size()));
  state.counters["segments"] = static_cast<double>(found);
}

void BM_Detect_OneHour1kHz_Auto(benchmark::State& state) {
  RunDetection(state, OneHourAt1kHz(), {});
}
BENCHMARK(BM_Detect_OneHour1kHz_Auto)->Unit(benchmark::kMillisecond);

void BM_Detect_OneHour1kHz_InitialStill(benchmark::State& state) {
  plumb::segmentation::StillDetectorOptions options;
  options.init_still_s = 30.0;
  RunDetection(state, OneHourAt1kHz(), options);
}
BENCHMARK(BM_Detect_OneHour1kHz_InitialStill)->Unit(benchmark::kMillisecond);

void BM_Detect_OneHour1kHz_AccelOnly(benchmark::State& state) {
  plumb::segmentation::StillDetectorOptions options;
  options.use_gyro = false;
  RunDetection(state, OneHourAt1kHz(), options);
}
BENCHMARK(BM_Detect_OneHour1kHz_AccelOnly)->Unit(benchmark::kMillisecond);

void BM_Detect_MikoffImu0(benchmark::State& state) {
  static const ImuSeries series = ReadMikoffImu0();
  if (series.empty()) {
    state.SkipWithError("bundled data/mikoff/imu0.log absent");
    return;
  }
  RunDetection(state, series, {});
}
BENCHMARK(BM_Detect_MikoffImu0)->Unit(benchmark::kMicrosecond);

/// imu_tk's own data (raw counts, 511 s at 100 Hz) with imu_tk's 50 s initial still period.
ImuSeries ReadImuTk() {
  const std::string dir = std::string(PLUMB_SHARED_DATA_DIR) + "/multipose/imu_tk/";
  std::ifstream acc(dir + "xsens_acc.mat"), gyr(dir + "xsens_gyro.mat");
  ImuSeries s;
  double t = 0, tg = 0;
  float a[3], g[3];
  while (acc >> t >> a[0] >> a[1] >> a[2] && gyr >> tg >> g[0] >> g[1] >> g[2]) {
    s.t_s.push_back(t);
    s.acc.emplace_back(a[0], a[1], a[2]);
    s.gyr.emplace_back(g[0], g[1], g[2]);
  }
  return s;
}

void BM_Detect_ImuTk(benchmark::State& state) {
  static const ImuSeries series = ReadImuTk();
  if (series.empty()) {
    state.SkipWithError("shared data absent: multipose/imu_tk");
    return;
  }
  plumb::segmentation::StillDetectorOptions options;
  options.init_still_s = 50.0;
  RunDetection(state, series, options);
}
BENCHMARK(BM_Detect_ImuTk)->Unit(benchmark::kMicrosecond);

void BM_SegmentStats_OneHour1kHz(benchmark::State& state) {
  const ImuSeries& series = OneHourAt1kHz();
  for (auto _ : state) {
    benchmark::DoNotOptimize(plumb::signal::ComputeSegmentStats(series, 0, series.size()));
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * series.size()));
}
BENCHMARK(BM_SegmentStats_OneHour1kHz)->Unit(benchmark::kMillisecond);

/// The still detector's correlation-time estimate at its sample budget (131072 samples of the
/// still periods) on an axis that drifts: 18 chunks of AR(1) noise with phi = 0.9995, slow
/// against chunks of 7281 samples, so that the window runs to thousands of lags, as on the
/// accelerometer axes of the PX4 sample log (tau_int 234 and 2129 samples). Counters: the
/// lags summed (`window`) and the samples read.
void BM_CorrelationTime_Drifting(benchmark::State& state) {
  static const std::vector<std::vector<float>> chunks = [] {
    std::vector<std::vector<float>> out;
    std::mt19937_64 rng(20261128);
    std::normal_distribution<double> e(0.0, 1e-3);
    for (int c = 0; c < 18; ++c) {
      std::vector<float> x(131072 / 18);
      double v = 0.0;
      for (float& sample : x) {
        v = 0.9995 * v + e(rng);
        sample = static_cast<float>(9.81 + v);
      }
      out.push_back(std::move(x));
    }
    return out;
  }();
  std::vector<plumb::signal::AxisView> views;
  for (const std::vector<float>& x : chunks) {
    views.push_back(plumb::signal::ViewContiguous(x.data(), x.size()));
  }
  plumb::signal::CorrelationTime ct;
  for (auto _ : state) {
    ct = plumb::signal::EstimateCorrelationTime(views);
    benchmark::DoNotOptimize(ct.tau_int);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * ct.samples));
  state.counters["window"] = static_cast<double>(ct.window);
  state.counters["samples"] = static_cast<double>(ct.samples);
}
BENCHMARK(BM_CorrelationTime_Drifting)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

// The motion residual's cost per sample (docs/performance.md, "The motion residual"): one
// 5 s turn at 100 Hz (500 samples, the length of imu_tk's session's turns), the base model or
// one with two gyroscope effects (general: the rates' Jacobians by implicit differentiation),
// with and without the bias walk's states and Earth rate, evaluated for its value alone (what
// a trust-region step's candidate and the linearity check ask) and with every Jacobian (what
// a Gauss-Newton iteration asks). The counter samples/s counts the samples integrated.
//
//   build/benchmarks/residuals/plumb_bench_residuals
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <vector>

#include "plumb/model/model.h"
#include "plumb/residuals/motion_residual.h"

namespace plumb {
namespace {

/// A turn about a tilted axis, rate a raised cosine peaking at 2 rad/s, seen by a sensor with
/// E = 1.01 I, measured in rad/s.
residuals::MotionSamples Turn() {
  residuals::MotionSamples s;
  constexpr int kSamples = 500;
  constexpr double kRateHz = 100.0;
  const Vec3 axis = Vec3(0.3, -0.5, 0.8).normalized();
  const double T = kSamples / kRateHz;
  for (int i = 0; i < kSamples; ++i) {
    const double t = i / kRateHz;
    const double rate = 1.0 - std::cos(2 * M_PI * t / T);
    s.dt_s.push_back(t);
    s.gyr.push_back(1.01 * rate * axis + Vec3(1e-3, -2e-3, 5e-4));
    s.acc.push_back(Vec3(0, 0, -9.81));
    s.alpha_b.push_back(Vec3::Zero());
    s.dtemp_c.push_back(0.0);
  }
  s.sqrt_info = Vec3::Constant(1000.0);
  return s;
}

/// Arguments: jacobians (0/1), walk processes (0/2), Earth rate (0/1), model (0: base, 1:
/// base+gyro_g_sensitivity+gyro_scale_nonlinearity, its effects off zero).
void BM_MotionResidual(benchmark::State& state) {
  const bool jacobians = state.range(0) != 0;
  const int walk = static_cast<int>(state.range(1));
  const bool earth = state.range(2) != 0;
  const bool general = state.range(3) != 0;
  const model::Model m =
      model::Model::Parse(general ? "base+gyro_g_sensitivity+gyro_scale_nonlinearity" : "base");
  const residuals::MotionSamples s = Turn();
  const residuals::MotionResidual r(m, s, earth ? Vec3(4e-5, 0, -5e-5) : Vec3::Zero(), walk);
  auto theta = m.ZeroParameters();
  for (int d = 0; d < 3; ++d) theta[1][static_cast<std::size_t>(4 * d)] = 0.01;  // E = 1.01 I
  for (std::size_t t = 2; t < theta.size(); ++t) {
    for (std::size_t j = 0; j < theta[t].size(); ++j) theta[t][j] = 1e-4 * (1.0 + 0.5 * j);
  }
  const double q0[4] = {0, 0, 0, 1}, q1[4] = {0.1, 0.2, 0.3, 0.927};
  const double zero[3] = {0, 0, 0};
  std::vector<const double*> p = {q0, q1};
  for (const auto& b : theta) p.push_back(b.data());
  for (int b = 0; b < 2 * walk; ++b) p.push_back(zero);
  std::vector<std::vector<double>> blocks;
  std::vector<double*> jac;
  for (int size : r.parameter_block_sizes()) {
    blocks.emplace_back(static_cast<std::size_t>(3 * size));
    jac.push_back(blocks.back().data());
  }
  double res[3];
  for (auto _ : state) {
    r.Evaluate(p.data(), res, jacobians ? jac.data() : nullptr);
    benchmark::DoNotOptimize(res);
    benchmark::ClobberMemory();
  }
  state.counters["samples/s"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * static_cast<double>(s.size()),
      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MotionResidual)
    ->ArgNames({"jacobians", "walk", "earth", "model"})
    ->ArgsProduct({{0, 1}, {0, 2}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace plumb

BENCHMARK_MAIN();

// Speed of diagnose over the whole catalogue (SPEC section 7: under 1 s for a typical
// session): mikoff's imu0 (bundled, 18 still poses, no site) and imu_tk's own data (38 poses,
// 51 k samples), with the score test alone (confirm 0) and with the best three refitted.
// Reading and segmentation are not timed.
//
//   build/benchmarks/diagnostics/plumb_bench_diagnostics --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <filesystem>

#include "plumb/diagnostics/diagnose.h"
#include "support/sessions.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb {
namespace {

using bench::ImuTkPresent;
using bench::ReadImuTk;
using bench::ReadMikoff;

void DiagnoseSession(benchmark::State& state, const Session& s, const geo::Site& site,
                     double init_still_s) {
  segmentation::StillDetectorOptions d;
  d.init_still_s = init_still_s;
  const auto seg = segmentation::DetectStillSegments(s.series, d);
  model::Model m = model::Model::Parse("base");
  m.t_ref_s = s.series.t_s.front();
  diagnostics::DiagnoseOptions options;
  options.confirm = static_cast<int>(state.range(0));
  diagnostics::Diagnosis result;
  for (auto _ : state) {
    result = diagnostics::Diagnose(s.series, seg.segments, m, site, options);
    benchmark::DoNotOptimize(result);
  }
  state.counters["segments"] = static_cast<double>(result.fit.fit.still_segments);
  state.counters["candidates"] = static_cast<double>(result.candidates.size());
  state.counters["samples"] = static_cast<double>(s.series.size());
}

void BM_DiagnoseMikoff(benchmark::State& state) {
  static const Session s = ReadMikoff();
  DiagnoseSession(state, s, geo::Site::Unknown(), 0.0);
}
BENCHMARK(BM_DiagnoseMikoff)->Arg(0)->Arg(3)->Unit(benchmark::kMillisecond);

void BM_DiagnoseImuTk(benchmark::State& state) {
  if (!ImuTkPresent()) {
    state.SkipWithError("shared data absent");
    return;
  }
  static const Session s = ReadImuTk();
  DiagnoseSession(state, s, geo::Site::Unknown(9.81744), 50.0);
}
BENCHMARK(BM_DiagnoseImuTk)->Arg(0)->Arg(3)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace plumb

BENCHMARK_MAIN();

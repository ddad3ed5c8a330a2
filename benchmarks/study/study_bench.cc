// Throughput of sensitivity studies (plumb/study): one Monte Carlo run (simulate, fit, score)
// per iteration, per method, on one core. items_per_second is calibrations per second per core.
#include <benchmark/benchmark.h>

#include <nlohmann/json.hpp>

#include "plumb/study/run.h"
#include "plumb/study/study.h"

namespace {

using nlohmann::json;

plumb::study::Study StudyOf(const std::string& schedule, const std::string& method, double still_s) {
  const json doc = {{"seed", 1}, {"runs", 1}, {"design", "grid"},
                    {"base", {{"schedule", schedule}, {"still_s", still_s}, {"rate_hz", 100},
                              {"lat_deg", 6.67}, {"lon_deg", -1.57}, {"height_m", 250}}},
                    {"fit", {{"method", method}}}};
  return plumb::study::ParseStudy(doc, "benchmark");
}

void Runs(benchmark::State& state, const plumb::study::Study& study) {
  const plumb::study::Point point = plumb::study::DesignPoints(study).front();
  int run = 0, failed = 0;
  for (auto _ : state) {
    const plumb::study::RunOutcome out = plumb::study::RunOnce(study, point, run++);
    failed += out.failed ? 1 : 0;
    benchmark::DoNotOptimize(out.nees);
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["failed"] = failed;
}

/// The seed paper's static minute (60 s at 100 Hz), its closed forms (no sigma).
void BM_StudyRunPaperStatic(benchmark::State& state) {
  Runs(state, StudyOf("paper_static", "paper_static", 60.0));
}
BENCHMARK(BM_StudyRunPaperStatic)->Unit(benchmark::kMillisecond);

/// The same minute on the backend with the paper's constants held.
void BM_StudyRunPaperStaticBackend(benchmark::State& state) {
  Runs(state, StudyOf("paper_static", "paper_static_backend", 60.0));
}
BENCHMARK(BM_StudyRunPaperStaticBackend)->Unit(benchmark::kMillisecond);

/// The same minute, the generalized method (the bias wandering).
void BM_StudyRunPaperStaticGeneralized(benchmark::State& state) {
  Runs(state, StudyOf("paper_static", "generalized", 60.0));
}
BENCHMARK(BM_StudyRunPaperStaticGeneralized)->Unit(benchmark::kMillisecond);

/// 12 poses of 5 s joined by 2 s turns, the generalized method.
void BM_StudyRunMultiPoseGeneralized(benchmark::State& state) {
  Runs(state, StudyOf("multipose", "generalized", 5.0));
}
BENCHMARK(BM_StudyRunMultiPoseGeneralized)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

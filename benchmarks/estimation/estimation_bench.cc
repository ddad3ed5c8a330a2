// Speed of the full calibration (SPEC section 7): imu_tk's own data (imu_tk takes about 1 s
// of calibration on this kind of machine), mikoff's imu0 (bundled), and a simulated one-hour
// 1 kHz session; the cost of many poses (BM_CalibratePoses/60 and /600) and of a board's
// three IMUs against one (BM_CalibrateBoard/1 and /3). Reading and segmentation are measured apart (io and segmentation benches)
// and, for the end-to-end figure, together in BM_EndToEndImuTk.
//
//   build/benchmarks/estimation/plumb_bench_estimation --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <filesystem>

#include "plumb/estimation/calibrator.h"
#include "support/sessions.h"
#include "plumb/segmentation/still_detector.h"
#include "plumb/sim/schedule.h"
#include "plumb/sim/simulate.h"
#include "plumb/sim/truth.h"

namespace plumb {
namespace {

using bench::ImuTkPresent;
using bench::ReadImuTk;
using bench::ReadMikoff;

/// Calibrates `s` with the default options (the bias wanders: walk and instability states per
/// segment) or, with `constant_bias`, one constant bias as imu_tk assumes.
void CalibrateSession(benchmark::State& state, const Session& s, const geo::Site& site,
                      double init_still_s, bool constant_bias = false) {
  estimation::CalibrationOptions options;
  options.constant_bias = constant_bias;
  segmentation::StillDetectorOptions d;
  d.init_still_s = init_still_s;
  const auto seg = segmentation::DetectStillSegments(s.series, d);
  model::Model m = model::Model::Parse("base");
  m.t_ref_s = s.series.t_s.front();
  estimation::CalibrationResult r;
  for (auto _ : state) {
    r = estimation::Calibrate(s.series, seg.segments, m, site, options);
    benchmark::DoNotOptimize(r);
  }
  state.counters["segments"] = static_cast<double>(r.fit.still_segments);
  state.counters["unknowns"] = static_cast<double>(r.calibration.observability.num_unknowns);
  state.counters["chi2_dof"] = r.fit.chi2_dof();
  state.counters["samples"] = static_cast<double>(s.series.size());
  state.counters["iterations"] = r.fit.iterations;
}

void BM_CalibrateImuTk(benchmark::State& state) {
  if (!ImuTkPresent()) {
    state.SkipWithError("shared data absent");
    return;
  }
  CalibrateSession(state, ReadImuTk(), geo::Site::Unknown(9.81744), 50.0);
}
BENCHMARK(BM_CalibrateImuTk)->Unit(benchmark::kMillisecond);

void BM_CalibrateImuTkConstantBias(benchmark::State& state) {
  if (!ImuTkPresent()) {
    state.SkipWithError("shared data absent");
    return;
  }
  CalibrateSession(state, ReadImuTk(), geo::Site::Unknown(9.81744), 50.0, true);
}
BENCHMARK(BM_CalibrateImuTkConstantBias)->Unit(benchmark::kMillisecond);

void BM_CalibrateMikoff(benchmark::State& state) {
  CalibrateSession(state, ReadMikoff(), geo::Site::Unknown(), 0.0);
}
BENCHMARK(BM_CalibrateMikoff)->Unit(benchmark::kMillisecond);

void BM_EndToEndImuTk(benchmark::State& state) {
  if (!ImuTkPresent()) {
    state.SkipWithError("shared data absent");
    return;
  }
  for (auto _ : state) {
    const Session s = ReadImuTk();
    segmentation::StillDetectorOptions d;
    d.init_still_s = 50.0;
    const auto seg = segmentation::DetectStillSegments(s.series, d);
    model::Model m = model::Model::Parse("base");
    m.t_ref_s = s.series.t_s.front();
    benchmark::DoNotOptimize(estimation::Calibrate(s.series, seg.segments, m, geo::Site::Unknown(9.81744)));
  }
}
BENCHMARK(BM_EndToEndImuTk)->Unit(benchmark::kMillisecond);

/// One hour at 1 kHz: 60 still poses of about 55 s joined by 3 s turns.
void BM_CalibrateSimulatedHour(benchmark::State& state) {
  sim::SimulationOptions opt = sim::SimulationOptions::TypicalMems();
  opt.rate_hz = 1000.0;
  opt.truth = sim::RandomParameters(opt.model, 1.0, 3);
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
  opt.seed = 3;
  const sim::Simulation sim = sim::Simulate(sim::MultiPose(60, 57.0, 3.0, 3), opt);
  CalibrateSession(state, sim.session, sim.site, 0.0);
  state.counters["bytes_per_sample"] = static_cast<double>(
      sizeof(double) + 2 * sizeof(Vec3f) + sizeof(float));
}
BENCHMARK(BM_CalibrateSimulatedHour)->Unit(benchmark::kMillisecond)->Iterations(3);

/// The cost of poses (issue 14): N still poses of 57 s joined by 3 s turns at 100 Hz, the
/// same 6000 samples per pose whatever N; 600 poses should cost at most 12 times 60 poses.
void BM_CalibratePoses(benchmark::State& state) {
  const auto poses = static_cast<int>(state.range(0));
  sim::SimulationOptions opt = sim::SimulationOptions::TypicalMems();
  opt.rate_hz = 100.0;
  opt.truth = sim::RandomParameters(opt.model, 1.0, 3);
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
  opt.seed = 3;
  const sim::Simulation sim = sim::Simulate(sim::MultiPose(poses, 57.0, 3.0, 3), opt);
  CalibrateSession(state, sim.session, sim.site, 0.0);
  state.counters["poses"] = poses;
}
BENCHMARK(BM_CalibratePoses)->Arg(60)->Arg(600)->Unit(benchmark::kMillisecond)->Iterations(3);

/// The cost of a board (issue 38: three IMUs at most 3.5 times one): a simulated three-IMU
/// board, 16 still poses of 20 s joined by 3 s turns at 100 Hz, typical MEMS noise; fitted
/// with IMU 0 alone (/1) and with all three (/3) on the same samples, the default options.
void BM_CalibrateBoard(benchmark::State& state) {
  const auto imus = static_cast<std::size_t>(state.range(0));
  sim::SimulationOptions opt = sim::SimulationOptions::TypicalMems();
  opt.rate_hz = 100.0;
  opt.truth = sim::RandomParameters(opt.model, 1.0, 3);
  opt.board = sim::RandomBoard(3, opt.model, 1.0, 4);
  opt.site = geo::Site::At(51.64, -1.2, 100.0, "flags");
  opt.seed = 3;
  const sim::Simulation sim = sim::Simulate(sim::MultiPose(16, 20.0, 3.0, 3), opt);
  const std::vector<BoardImu> board(sim.session.other_imus.begin(),
                                    sim.session.other_imus.begin() + (imus - 1));
  const auto seg = segmentation::DetectStillSegments(sim.session.series, {});
  model::Model m = model::Model::Parse("base");
  m.t_ref_s = sim.session.series.t_s.front();
  estimation::CalibrationResult r;
  for (auto _ : state) {
    r = estimation::CalibrateBoard(sim.session.series, board, seg.segments, m, sim.site);
    benchmark::DoNotOptimize(r);
  }
  state.counters["imus"] = static_cast<double>(imus);
  state.counters["unknowns"] = static_cast<double>(r.calibration.observability.num_unknowns);
  state.counters["chi2_dof"] = r.fit.chi2_dof();
  state.counters["iterations"] = r.fit.iterations;
}
BENCHMARK(BM_CalibrateBoard)->Arg(1)->Arg(3)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace plumb

BENCHMARK_MAIN();

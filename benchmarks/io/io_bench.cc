// Reading speed of the text readers (SPEC section 7: log readers at 200 MB/s or more).
//
// BM_ReadNativeCsvHour reads a simulated one-hour 1 kHz session (3.6 M rows with gyroscope and
// temperature, about 330 MB) that the setup writes once, deterministically, into a temporary
// file (removed at exit). BM_ReadMikoffImu0 reads the real mikoff/imu0.log through the generic
// table reader when the shared data is present. Counters: MB/s of input and samples/s.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "plumb/io/text/native_csv.h"
#include "plumb/io/text/text_table.h"

namespace {

constexpr std::size_t kHourSamples = 3600 * 1000;

plumb::Session SimulatedHour() {
  std::mt19937_64 rng(20240611);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  plumb::Session s;
  s.series.reserve(kHourSamples);
  s.series.temp_c.reserve(kHourSamples);
  for (std::size_t i = 0; i < kHourSamples; ++i) {
    s.series.t_s.push_back(static_cast<double>(i) / 1000.0);
    s.series.acc.emplace_back(0.02f * noise(rng) + 0.1f, 0.02f * noise(rng) - 0.05f,
                              0.02f * noise(rng) - 9.81f);
    s.series.gyr.emplace_back(0.003f * noise(rng), 0.003f * noise(rng), 0.003f * noise(rng));
    s.series.temp_c.push_back(30.0f + 5.0f * static_cast<float>(i) / kHourSamples +
                              0.01f * noise(rng));
  }
  return s;
}

// The hour file, written on first use and removed when the program ends.
class HourFile {
 public:
  HourFile()
      : path_((std::filesystem::temp_directory_path() /
               ("plumb_bench_io_hour_" + std::to_string(::getpid()) + ".csv"))
                  .string()) {
    plumb::io::WriteNativeCsv(path_, SimulatedHour());
  }
  ~HourFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

const std::string& HourPath() {
  static const HourFile file;
  return file.path();
}

void SetCounters(benchmark::State& state, std::size_t bytes, std::size_t samples) {
  const double iterations = static_cast<double>(state.iterations());
  state.counters["MB/s"] = benchmark::Counter(iterations * static_cast<double>(bytes) / 1e6,
                                              benchmark::Counter::kIsRate);
  state.counters["samples/s"] =
      benchmark::Counter(iterations * static_cast<double>(samples), benchmark::Counter::kIsRate);
}

void BM_ReadNativeCsvHour(benchmark::State& state) {
  const std::string& path = HourPath();
  std::size_t samples = 0;
  for (auto _ : state) {
    const plumb::Session s = plumb::io::ReadNativeCsv(path);
    samples = s.series.size();
    benchmark::DoNotOptimize(s.series.acc.data());
  }
  SetCounters(state, std::filesystem::file_size(path), samples);
}
BENCHMARK(BM_ReadNativeCsvHour)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WriteNativeCsvHour(benchmark::State& state) {
  const plumb::Session hour = SimulatedHour();
  const std::string path = HourPath() + ".out";
  for (auto _ : state) plumb::io::WriteNativeCsv(path, hour);
  SetCounters(state, std::filesystem::file_size(path), hour.series.size());
  std::remove(path.c_str());
}
BENCHMARK(BM_WriteNativeCsvHour)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ReadMikoffImu0(benchmark::State& state) {
  const std::string path = std::string(PLUMB_SOURCE_DIR) + "/data/mikoff/imu0.log";  // bundled
  if (!std::filesystem::exists(path)) {
    state.SkipWithError(("shared data absent: " + path).c_str());
    return;
  }
  plumb::io::TextTableOptions options;
  options.acc.axes = {0, 1, 2};
  options.gyr.axes = {3, 4, 5};
  options.rate_hz = 100.0;
  std::size_t samples = 0;
  for (auto _ : state) {
    const plumb::Session s = plumb::io::ReadTextTable(path, options);
    samples = s.series.size();
    benchmark::DoNotOptimize(s.series.acc.data());
  }
  SetCounters(state, std::filesystem::file_size(path), samples);
}
BENCHMARK(BM_ReadMikoffImu0)->Unit(benchmark::kMillisecond);

/// imu_tk's own data: two `t x y z` files of raw counts (6.6 MB, 51175 samples).
void BM_ReadImuTkPair(benchmark::State& state) {
  const std::string dir = std::string(PLUMB_SHARED_DATA_DIR) + "/multipose/imu_tk/";
  if (!std::filesystem::exists(dir + "xsens_acc.mat")) {
    state.SkipWithError(("shared data absent: " + dir).c_str());
    return;
  }
  plumb::io::TextTableOptions options;
  options.time = 0;
  options.acc.axes = {1, 2, 3};
  options.gyr.axes = {1, 2, 3};
  std::size_t samples = 0;
  for (auto _ : state) {
    const plumb::Session s =
        plumb::io::ReadSplitTables(dir + "xsens_acc.mat", dir + "xsens_gyro.mat", options);
    samples = s.series.size();
    benchmark::DoNotOptimize(s.series.acc.data());
  }
  SetCounters(state,
              std::filesystem::file_size(dir + "xsens_acc.mat") +
                  std::filesystem::file_size(dir + "xsens_gyro.mat"),
              samples);
}
BENCHMARK(BM_ReadImuTkPair)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

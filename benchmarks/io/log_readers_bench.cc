// Reading speed of the flight-log readers (SPEC section 7: 200 MB/s or more on one core; goal
// 1.5 GB/s for .bin and ULog, 400 MB/s for .tlog with CRC checked).
//
// Each benchmark reads a large log made by repeating a real one from ../shared/data end to end
// (about 150 MB, written once into a temporary file, removed at exit; the page cache holds it,
// so this measures the reader, not the disk), then decodes every IMU sample of it, as
// `plumb calibrate LOG` does. Counters: MB/s of log and IMU samples/s. Skipped with the reason
// when the shared data is absent.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/mavlink/mavlink_tlog.h"
#include "plumb/io/px4/ulog.h"

namespace {

constexpr std::size_t kTargetBytes = 150u * 1000u * 1000u;

/// A temporary file holding `source` repeated up to about kTargetBytes; removed at exit.
class RepeatedLog {
 public:
  explicit RepeatedLog(const std::string& source) {
    std::ifstream in(source, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    path_ = (std::filesystem::temp_directory_path() /
             ("plumb_bench_" + std::to_string(::getpid()) + "_" +
              std::filesystem::path(source).filename().string()))
                .string();
    std::ofstream out(path_, std::ios::binary);
    for (std::size_t written = 0; !bytes.empty() && written < kTargetBytes;
         written += bytes.size()) {
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
  }
  ~RepeatedLog() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// The repeated copy of shared-data file `relative`, made on first use; nullptr if absent.
const RepeatedLog* Repeated(const std::string& relative) {
  static std::map<std::string, std::unique_ptr<RepeatedLog>> logs;
  const std::string source = std::string(PLUMB_SHARED_DATA_DIR) + "/" + relative;
  if (!std::filesystem::exists(source)) return nullptr;
  auto& slot = logs[relative];
  if (!slot) slot = std::make_unique<RepeatedLog>(source);
  return slot.get();
}

void SetCounters(benchmark::State& state, std::size_t bytes, std::size_t samples) {
  const double iterations = static_cast<double>(state.iterations());
  state.counters["MB/s"] = benchmark::Counter(iterations * static_cast<double>(bytes) / 1e6,
                                              benchmark::Counter::kIsRate);
  state.counters["samples/s"] =
      benchmark::Counter(iterations * static_cast<double>(samples), benchmark::Counter::kIsRate);
  state.counters["MB"] = static_cast<double>(bytes) / 1e6;
}

/// Reads the repeated copy of `relative` once per iteration with `read`, which returns the
/// number of IMU samples it decoded.
template <typename Read>
void ReadRepeated(benchmark::State& state, const std::string& relative, Read read) {
  const RepeatedLog* log = Repeated(relative);
  if (log == nullptr) {
    state.SkipWithError(("shared data absent: " + relative).c_str());
    return;
  }
  std::size_t samples = 0;
  for (auto _ : state) samples = read(log->path());
  SetCounters(state, std::filesystem::file_size(log->path()), samples);
}

/// ArduPilot DataFlash .bin: decode the log and every IMU instance's samples.
void BM_ReadDataflash(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative, [](const std::string& path) {
    const plumb::io::DataflashLog decoded = plumb::io::ReadDataflash(path);
    std::size_t samples = 0;
    for (const auto& imu : plumb::io::DataflashImuInstances(decoded)) {
      const plumb::ImuSeries s = plumb::io::ImuFromDataflash(decoded, imu.instance);
      samples += s.size();
      benchmark::DoNotOptimize(s.acc.data());
    }
    return samples;
  });
}
BENCHMARK_CAPTURE(BM_ReadDataflash, copter36_chibios, std::string("ardupilot/copter36_chibios.bin"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadDataflash, plane408_centre_point,
                  std::string("ardupilot/plane408_centre_point.BIN"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// MAVLink .tlog: every frame's CRC checked and the IMU messages decoded.
void BM_ReadTlog(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative, [](const std::string& path) {
    const plumb::io::MavlinkLog decoded = plumb::io::ReadTlog(path);
    benchmark::DoNotOptimize(decoded.raw_imu.data());
    return decoded.raw_imu.size() + decoded.scaled_imu2.size() + decoded.scaled_imu3.size();
  });
}
BENCHMARK_CAPTURE(BM_ReadTlog, plane385_disarmed, std::string("mavlink/plane385_disarmed.tlog"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// PX4 ULog: decode the log (every topic). A repeated ULog is one header and definitions
/// followed by the data of every copy (later copies' headers are resynchronised over), so the
/// bytes are all walked.
void BM_ReadULog(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative, [](const std::string& path) {
    const plumb::io::ULog decoded = plumb::io::ReadULog(path);
    std::size_t samples = 0;
    for (const auto& topic : decoded.topics) {
      if (topic.name == "sensor_combined") samples += topic.rows;
    }
    benchmark::DoNotOptimize(decoded.topics.data());
    return samples;
  });
}
BENCHMARK_CAPTURE(BM_ReadULog, sample, std::string("px4/sample.ulg"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

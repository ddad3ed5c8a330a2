// Reading speed of the flight-log readers (SPEC section 7: 200 MB/s or more on one core; goal
// 1.5 GB/s for .bin and ULog, 400 MB/s for .tlog with CRC checked).
//
// Each benchmark reads a large log made by repeating a real one from ../shared/data end to end
// (about 150 MB, written once into a temporary file, removed at exit; the page cache holds it,
// so this measures the reader, not the disk), then decodes every IMU sample of it, as
// `plumb calibrate LOG` does. A repeated DataFlash log gets a continuing clock (each copy's
// TimeUS/TimeMS fields shifted past the previous copy's), so the IMU samples of every copy are
// decoded and counted, not only the first copy's. Counters: MB/s of log and IMU samples/s.
// Skipped with the reason when the shared data is absent.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/mavlink/mavlink_tlog.h"
#include "plumb/io/px4/ulog.h"

namespace {

constexpr std::size_t kTargetBytes = 150u * 1000u * 1000u;

/// A temporary file holding `source` repeated up to about kTargetBytes; removed at exit.
/// Where each DataFlash record type keeps its time: byte offset in the record (header
/// included) and format ('Q' TimeUS in us, 'I' TimeMS in ms); offset 0 when it has none.
struct TimeField {
  std::size_t offset = 0;
  char format = 0;
};

/// Calls `visit(record_start, type_id)` for every record of the DataFlash log `bytes`, walking
/// them as the reader does (a record is 0xA3 0x95, a known type and its FMT length).
template <typename Visit>
void ForEachRecord(std::vector<char>& bytes, const std::array<std::size_t, 256>& length,
                   Visit visit) {
  for (std::size_t pos = 0; pos + 3 <= bytes.size();) {
    const auto id = static_cast<std::uint8_t>(bytes[pos + 2]);
    if (static_cast<std::uint8_t>(bytes[pos]) == 0xA3 &&
        static_cast<std::uint8_t>(bytes[pos + 1]) == 0x95 && length[id] > 0 &&
        pos + length[id] <= bytes.size()) {
      visit(pos, id);
      pos += length[id];
    } else {
      ++pos;
    }
  }
}

/// `copies` copies of the DataFlash log `bytes`, copy k's clock shifted by k times (the log's
/// last time + 1 s), so that times keep increasing across copies.
std::vector<char> ContinuingDataflash(std::vector<char> bytes, std::size_t copies) {
  const plumb::io::DataflashLog log = plumb::io::ParseDataflash(
      reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size(), "benchmark");
  std::array<std::size_t, 256> length{};
  std::array<TimeField, 256> time{};
  for (const plumb::io::DataflashType& t : log.types) {
    length[t.id] = t.length;
    for (const char* name : {"TimeUS", "TimeMS"}) {
      const int c = t.ColumnIndex(name);
      if (c >= 0 && time[t.id].offset == 0) {
        time[t.id] = {3 + t.columns[static_cast<std::size_t>(c)].offset,
                      t.columns[static_cast<std::size_t>(c)].format};
      }
    }
  }
  std::uint64_t last_us = 0;
  ForEachRecord(bytes, length, [&](std::size_t pos, std::uint8_t id) {
    const TimeField& f = time[id];
    if (f.format == 'Q') {
      std::uint64_t v;
      std::memcpy(&v, &bytes[pos + f.offset], sizeof v);
      last_us = std::max(last_us, v);
    } else if (f.format == 'I') {
      std::uint32_t v;
      std::memcpy(&v, &bytes[pos + f.offset], sizeof v);
      last_us = std::max<std::uint64_t>(last_us, std::uint64_t{v} * 1000u);
    }
  });
  const std::uint64_t shift_us = last_us + 1000000u;
  std::vector<char> out;
  out.reserve(bytes.size() * copies);
  for (std::size_t k = 0; k < copies; ++k) {
    std::vector<char> copy = bytes;
    ForEachRecord(copy, length, [&](std::size_t pos, std::uint8_t id) {
      const TimeField& f = time[id];
      if (f.format == 'Q') {
        std::uint64_t v;
        std::memcpy(&v, &copy[pos + f.offset], sizeof v);
        v += k * shift_us;
        std::memcpy(&copy[pos + f.offset], &v, sizeof v);
      } else if (f.format == 'I') {
        std::uint32_t v;
        std::memcpy(&v, &copy[pos + f.offset], sizeof v);
        v += static_cast<std::uint32_t>(k * shift_us / 1000u);
        std::memcpy(&copy[pos + f.offset], &v, sizeof v);
      }
    });
    out.insert(out.end(), copy.begin(), copy.end());
  }
  return out;
}

class RepeatedLog {
 public:
  /// `continuing_clock`: shift each DataFlash copy's times past the previous copy's.
  RepeatedLog(const std::string& source, bool continuing_clock) {
    std::ifstream in(source, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    path_ = (std::filesystem::temp_directory_path() /
             ("plumb_bench_" + std::to_string(::getpid()) + "_" +
              std::filesystem::path(source).filename().string()))
                .string();
    std::ofstream out(path_, std::ios::binary);
    if (bytes.empty()) return;
    const std::size_t copies = (kTargetBytes + bytes.size() - 1) / bytes.size();
    if (continuing_clock) {
      const std::vector<char> all = ContinuingDataflash(std::move(bytes), copies);
      out.write(all.data(), static_cast<std::streamsize>(all.size()));
      return;
    }
    for (std::size_t k = 0; k < copies; ++k) {
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
  if (!slot) {
    const bool dataflash = relative.rfind("ardupilot/", 0) == 0 &&
                           plumb::io::LooksLikeDataflash(source);
    slot = std::make_unique<RepeatedLog>(source, dataflash);
  }
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

/// ArduPilot DataFlash .bin: decode the log as FlightLog does (the bodies a session reads)
/// and every IMU instance's samples, of every copy.
void BM_ReadDataflash(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative, [](const std::string& path) {
    const plumb::io::DataflashLog decoded =
        plumb::io::ReadDataflash(path, plumb::io::ArdupilotSessionRecords());
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

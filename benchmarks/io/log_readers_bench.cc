// Reading speed of the flight-log readers (SPEC section 7: 200 MB/s or more on one core; goal
// 1.5 GB/s for .bin and ULog, 400 MB/s for .tlog with CRC checked).
//
// Each benchmark reads a large log made by repeating a real one from ../shared/data end to end
// (about 150 MB, written once into a temporary file, removed at exit; the page cache holds it,
// so this measures the reader, not the disk), then decodes every IMU sample of it, as
// `plumb calibrate LOG` does. A repeated DataFlash log gets a continuing clock (each copy's
// TimeUS/TimeMS fields shifted past the previous copy's), and so does a repeated ULog (the
// file once, then its D messages again and again with their timestamp/timestamp_sample fields
// shifted), so the IMU samples of every copy are decoded and counted, not only the first
// copy's. Counters: MB/s of log and IMU samples/s.
//
// BM_Cat/<log> runs the system `cat LOG` (posix_spawn, standard output to /dev/null, the whole
// process as a shell would run it) on the very same temporary file: the speed of getting the
// bytes out of the page cache. Each reader benchmark registered after it also reports `x_cat`,
// its MB/s over the MB/s of the BM_Cat of the same file measured last in the same process (run
// both in one invocation: --benchmark_filter='BM_(Cat|Read)').
// BM_WalkDataflash/<log> walks the records of the same file (ReadForward, headers and FMT
// lengths only): the floor under the DataFlash reader's record loop (one thread).
// BM_ReadDataflashInParts/<log>, BM_ReadULogInParts/<log> and BM_ReadTlogInParts/<log>
// are BM_ReadDataflash, BM_ReadULog and BM_ReadTlog in parts at once on two threads, as `plumb`
// reads a .bin, .ulg or .tlog of 32 MiB or more; their argument is the number of parts (/2 as
// `plumb` reads, SplitReadOptions' default; /8 to compare), their CPU time the process's.
// Skipped with the reason when the shared data is absent. With PLUMB_BENCH_LOG_DIR=DIR set, the
// repeated logs are written to DIR/big_<name> and kept (to time `plumb info` on them).
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "plumb/io/ardupilot/ardupilot_session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/mavlink/mavlink_tlog.h"
#include "plumb/io/px4/px4_session.h"
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

/// Writes `copies` copies of the DataFlash log `bytes` to `out`, copy k's clock shifted by k
/// times (the log's last time + 1 s), so that times keep increasing across copies. Each copy
/// is written as it is made: the whole file is never held in memory.
void WriteContinuingDataflash(std::vector<char> bytes, std::size_t copies, std::ostream& out) {
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
  std::vector<char> copy;
  for (std::size_t k = 0; k < copies; ++k) {
    copy = bytes;
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
    out.write(copy.data(), static_cast<std::streamsize>(copy.size()));
  }
}

/// Writes `copies` copies of the ULog `bytes` with a continuing clock to `out`: the file once,
/// then its D messages `copies - 1` more times, copy k's top-level uint64 "timestamp" and
/// "timestamp_sample" fields shifted by k times (the log's last timestamp + 1 s); each copy
/// written as it is made.
void WriteContinuingULog(const std::vector<char>& bytes, std::size_t copies, std::ostream& out) {
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  const plumb::io::ULog log = plumb::io::ParseULog(data, bytes.size(), "benchmark");
  std::map<std::uint16_t, std::vector<std::size_t>> clocks;  // msg_id -> field offsets
  std::uint64_t last_us = 0;
  for (const plumb::io::ULogTopic& t : log.topics) {
    for (const plumb::io::ULogColumn& c : t.columns) {
      if ((c.name == "timestamp" || c.name == "timestamp_sample") &&
          c.type == plumb::io::ULogType::kUInt64) {
        clocks[t.msg_id].push_back(c.offset);
      }
    }
    if (t.rows > 0) last_us = std::max(last_us, t.TimestampUs(t.rows - 1));
  }
  const std::uint64_t shift_us = last_us + 1000000u;
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  std::vector<char> copy;
  for (std::size_t k = 1; k < copies; ++k) {
    copy.clear();
    for (std::size_t pos = 16; pos + 5 <= bytes.size();) {  // after the 16-byte file header
      std::uint16_t size, msg_id;
      std::memcpy(&size, data + pos, 2);
      if (size == 0 || pos + 3 + size > bytes.size()) break;
      std::memcpy(&msg_id, data + pos + 3, 2);
      if (data[pos + 2] == 'D' && size >= 2) {
        const std::size_t at = copy.size();
        copy.insert(copy.end(), bytes.begin() + static_cast<std::ptrdiff_t>(pos),
                    bytes.begin() + static_cast<std::ptrdiff_t>(pos + 3 + size));
        for (std::size_t offset : clocks[msg_id]) {
          if (5 + offset + 8 > 3u + size) continue;
          std::uint64_t v;
          std::memcpy(&v, &copy[at + 5 + offset], 8);
          v += k * shift_us;
          std::memcpy(&copy[at + 5 + offset], &v, 8);
        }
      }
      pos += 3 + size;
    }
    out.write(copy.data(), static_cast<std::streamsize>(copy.size()));
  }
}

class RepeatedLog {
 public:
  enum class Clock { kRepeated, kDataflash, kULog };
  /// `clock`: shift each DataFlash or ULog copy's times past the previous copy's.
  RepeatedLog(const std::string& source, Clock clock) {
    std::ifstream in(source, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    const char* keep_dir = std::getenv("PLUMB_BENCH_LOG_DIR");
    keep_ = keep_dir != nullptr && *keep_dir != '\0';
    path_ = keep_ ? (std::filesystem::path(keep_dir) /
                     ("big_" + std::filesystem::path(source).filename().string()))
                        .string()
                  : (std::filesystem::temp_directory_path() /
                     ("plumb_bench_" + std::to_string(::getpid()) + "_" +
                      std::filesystem::path(source).filename().string()))
                        .string();
    std::ofstream out(path_, std::ios::binary);
    if (bytes.empty()) return;
    const std::size_t copies = (kTargetBytes + bytes.size() - 1) / bytes.size();
    if (clock == Clock::kDataflash) {
      WriteContinuingDataflash(std::move(bytes), copies, out);
      return;
    }
    if (clock == Clock::kULog) {
      WriteContinuingULog(bytes, copies, out);
      return;
    }
    for (std::size_t k = 0; k < copies; ++k) {
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
  }
  ~RepeatedLog() {
    if (!keep_) std::remove(path_.c_str());
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  bool keep_ = false;  ///< PLUMB_BENCH_LOG_DIR given: the file stays there
};

/// The repeated copy of shared-data file `relative`, made on first use; nullptr if absent.
const RepeatedLog* Repeated(const std::string& relative) {
  static std::map<std::string, std::unique_ptr<RepeatedLog>> logs;
  const std::string source = std::string(PLUMB_SHARED_DATA_DIR) + "/" + relative;
  if (!std::filesystem::exists(source)) return nullptr;
  auto& slot = logs[relative];
  if (!slot) {
    using Clock = RepeatedLog::Clock;
    Clock clock = Clock::kRepeated;
    if (plumb::io::LooksLikeDataflash(source)) clock = Clock::kDataflash;
    if (plumb::io::LooksLikeULog(source)) clock = Clock::kULog;
    slot = std::make_unique<RepeatedLog>(source, clock);
  }
  return slot.get();
}

/// MB/s of the last BM_Cat of each file (by its shared-data name) in this process.
std::map<std::string, double>& CatSpeeds() {
  static std::map<std::string, double> speeds;
  return speeds;
}

/// `cat path > /dev/null` as a separate process, waited for. False when it could not run or
/// failed.
bool RunCat(const std::string& path) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  const std::string cat = "cat";
  char* argv[] = {const_cast<char*>(cat.c_str()), const_cast<char*>(path.c_str()), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, "cat", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return false;
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

void SetCounters(benchmark::State& state, std::size_t bytes, std::size_t samples,
                 const std::string& relative = "") {
  const double iterations = static_cast<double>(state.iterations());
  state.counters["MB/s"] = benchmark::Counter(iterations * static_cast<double>(bytes) / 1e6,
                                              benchmark::Counter::kIsRate);
  // The same rate against the last cat of this file (counters are divided by the real time
  // after the run, so the ratio is made from the figures by hand here).
  const auto cat = CatSpeeds().find(relative);
  if (cat != CatSpeeds().end() && cat->second > 0.0) {
    state.counters["x_cat"] = benchmark::Counter(
        iterations * static_cast<double>(bytes) / 1e6 / cat->second, benchmark::Counter::kIsRate);
  }
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
  SetCounters(state, std::filesystem::file_size(log->path()), samples, relative);
}

/// The system's `cat` of the same repeated file, to /dev/null: the baseline of the readers.
void BM_Cat(benchmark::State& state, const std::string& relative) {
  const RepeatedLog* log = Repeated(relative);
  if (log == nullptr) {
    state.SkipWithError(("shared data absent: " + relative).c_str());
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    if (!RunCat(log->path())) {
      state.SkipWithError("cat failed");
      return;
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto bytes = static_cast<double>(std::filesystem::file_size(log->path()));
  CatSpeeds()[relative] = static_cast<double>(state.iterations()) * bytes / 1e6 / seconds;
  SetCounters(state, std::filesystem::file_size(log->path()), 0);
}
BENCHMARK_CAPTURE(BM_Cat, copter36_chibios, std::string("ardupilot/copter36_chibios.bin"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Cat, plane408_centre_point, std::string("ardupilot/plane408_centre_point.BIN"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Cat, plane385_disarmed, std::string("mavlink/plane385_disarmed.tlog"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Cat, sample, std::string("px4/sample.ulg"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// A read in `parts` parts at once through `run_jobs` for any size (SplitReadOptions; the
/// second part's start at 1 / parts of the bytes after the lead, the others at its multiples);
/// empty run_jobs: one part.
plumb::io::SplitReadOptions InParts(const plumb::JobRunner& run_jobs, int parts) {
  plumb::io::SplitReadOptions options;
  options.run_jobs = run_jobs;
  options.parts = parts;
  options.second_part_at = 1.0 / parts;
  return options;
}

/// The parts of an InParts benchmark: its argument (2, as `plumb` reads; 8 to compare).
int Parts(const benchmark::State& state) { return static_cast<int>(state.range(0)); }

/// Reads the DataFlash log at `path` as FlightLog does (the bodies a session reads; the IMU
/// messages' samples decoded in the pass; in parts at once with `run_jobs`) and returns
/// the number of IMU samples of every instance: counted where the reader put them, or with
/// `copy_out` copied out as ImuFromDataflash returns them.
std::size_t ReadDataflashSamples(const std::string& path, bool copy_out,
                                 const plumb::JobRunner& run_jobs = {}, int parts = 8) {
  const plumb::io::DataflashReadOptions options = InParts(run_jobs, parts);
  const plumb::io::DataflashLog decoded =
      plumb::io::ReadDataflash(path, plumb::io::ArdupilotSessionRecords(), options);
  std::size_t samples = 0;
  for (const auto& imu : plumb::io::DataflashImuInstances(decoded)) {
    if (copy_out) {
      const plumb::ImuSeries s = plumb::io::ImuFromDataflash(decoded, imu.instance);
      samples += s.size();
      benchmark::DoNotOptimize(s.acc.data());
    } else if (const plumb::ImuSeries* s = plumb::io::DecodedDataflashImu(decoded, imu.instance)) {
      samples += s->size();
      benchmark::DoNotOptimize(s->acc.data());
    }
  }
  return samples;
}

/// ArduPilot DataFlash .bin: every IMU instance's samples, of every copy, counted where the
/// reader put them (DecodedDataflashImu: by reference, as BM_ReadULog counts its streams').
void BM_ReadDataflash(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative,
               [](const std::string& path) { return ReadDataflashSamples(path, false); });
}
BENCHMARK_CAPTURE(BM_ReadDataflash, copter36_chibios, std::string("ardupilot/copter36_chibios.bin"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadDataflash, plane408_centre_point,
                  std::string("ardupilot/plane408_centre_point.BIN"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// The jobs at once on two OpenMP threads, as `plumb` runs them on a machine of two cores or
/// more (apps/plumb/jobs.cc, ParallelJobs).
void TwoThreads(int count, const std::function<void(int)>& job) {
#pragma omp parallel for schedule(dynamic) num_threads(2)
  for (int k = 0; k < count; ++k) job(k);
}

/// BM_ReadDataflash in parts at once on two threads, as `plumb` reads a .bin of 32 MiB or
/// more on a machine of two cores or more (DataflashReadOptions): the same samples. Its CPU
/// time is the process's (both threads).
void BM_ReadDataflashInParts(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative,
               [&](const std::string& path) {
                 return ReadDataflashSamples(path, false, TwoThreads, Parts(state));
               });
}
BENCHMARK_CAPTURE(BM_ReadDataflashInParts, copter36_chibios,
                  std::string("ardupilot/copter36_chibios.bin"))
    ->Arg(2)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadDataflashInParts, plane408_centre_point,
                  std::string("ardupilot/plane408_centre_point.BIN"))
    ->Arg(2)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

/// BM_ReadDataflash, then every IMU instance's samples copied out as ImuFromDataflash returns
/// them (a session of each instance starts from such a copy).
void BM_ReadDataflashAndCopy(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative,
               [](const std::string& path) { return ReadDataflashSamples(path, true); });
}
BENCHMARK_CAPTURE(BM_ReadDataflashAndCopy, copter36_chibios,
                  std::string("ardupilot/copter36_chibios.bin"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// The floor under the DataFlash reader: the same file read the same way (ReadForward) and its
/// records walked (header, type, FMT lengths), nothing checked, stored or decoded. "samples"
/// counts records here.
void BM_WalkDataflash(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative, [](const std::string& path) {
    std::array<std::size_t, 256> length{};
    length[128] = 89;  // FMT
    std::size_t records = 0;
    plumb::io::ReadForward(
        path, "DataFlash log", 255,
        [&](const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
          std::size_t i = 0;
          while (n - i >= 3 && (at_end || n - i >= 255)) {
            const std::size_t len = length[data[i + 2]];
            if (data[i] == 0xA3 && data[i + 1] == 0x95 && len > 0 && len <= n - i) {
              if (data[i + 2] == 128) length[data[i + 3]] = data[i + 4];
              ++records;
              i += len;
            } else {
              ++i;
            }
          }
          return offset + (at_end ? n : i);
        });
    return records;
  });
}
BENCHMARK_CAPTURE(BM_WalkDataflash, copter36_chibios,
                  std::string("ardupilot/copter36_chibios.bin"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// Reads the tlog at `path` as FlightLog does (every frame's CRC checked, the IMU messages
/// decoded; in parts at once with `run_jobs`) and returns the IMU messages decoded.
std::size_t ReadTlogSamples(const std::string& path, const plumb::JobRunner& run_jobs = {},
                            int parts = 8) {
  const plumb::io::MavlinkLog decoded = plumb::io::ReadTlog(path, InParts(run_jobs, parts));
  benchmark::DoNotOptimize(decoded.raw_imu.data());
  return decoded.raw_imu.size() + decoded.scaled_imu.size() + decoded.scaled_imu2.size() +
         decoded.scaled_imu3.size() + decoded.highres_imu.size();
}

/// MAVLink .tlog: every frame's CRC checked and the IMU messages decoded (one thread).
void BM_ReadTlog(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative, [](const std::string& path) { return ReadTlogSamples(path); });
}
BENCHMARK_CAPTURE(BM_ReadTlog, plane385_disarmed, std::string("mavlink/plane385_disarmed.tlog"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// Reads the ULog at `path` as FlightLog does (the bodies of the topics a session reads;
/// sensor_combined's samples decoded in the pass; in parts at once with `run_jobs`) and
/// returns the samples of every IMU stream (sensor_combined, vehicle_imu, sensor_accel paired
/// with sensor_gyro), of every copy.
std::size_t ReadULogSamples(const std::string& path, const plumb::JobRunner& run_jobs = {},
                            int parts = 8) {
  const plumb::io::ULog decoded =
      plumb::io::ReadULog(path, plumb::io::Px4SessionTopics(), InParts(run_jobs, parts));
  std::size_t samples = 0;
  for (const plumb::io::ImuStreamInfo& s : plumb::io::ULogImuStreams(decoded)) {
    samples += s.samples;
  }
  benchmark::DoNotOptimize(decoded.topics.data());
  return samples;
}

/// PX4 ULog, in one part (one thread).
void BM_ReadULog(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative, [](const std::string& path) { return ReadULogSamples(path); });
}
BENCHMARK_CAPTURE(BM_ReadULog, sample, std::string("px4/sample.ulg"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// BM_ReadULog in parts at once on two threads, as `plumb` reads a .ulg of 32 MiB or more
/// on a machine of two cores or more (ULogReadOptions): the same samples. Its CPU time is the
/// process's (both threads).
void BM_ReadULogInParts(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative,
               [&](const std::string& path) {
                 return ReadULogSamples(path, TwoThreads, Parts(state));
               });
}
BENCHMARK_CAPTURE(BM_ReadULogInParts, sample, std::string("px4/sample.ulg"))
    ->Arg(2)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

/// BM_ReadTlog in parts at once on two threads, as `plumb` reads a .tlog of 32 MiB or more
/// on a machine of two cores or more (TlogReadOptions): the same messages, every CRC checked.
/// Its CPU time is the process's (both threads).
void BM_ReadTlogInParts(benchmark::State& state, const std::string& relative) {
  ReadRepeated(state, relative,
               [&](const std::string& path) {
                 return ReadTlogSamples(path, TwoThreads, Parts(state));
               });
}
BENCHMARK_CAPTURE(BM_ReadTlogInParts, plane385_disarmed,
                  std::string("mavlink/plane385_disarmed.tlog"))
    ->Arg(2)
    ->Arg(8)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

}  // namespace

// Reading speed of the ROS 1 bag reader (SPEC section 7: at least 1 GB/s uncompressed, near the
// decompressor's own speed compressed).
//
// BM_ReadRosBag/<bag> reads a large bag made from a real one of ../shared/data/ros end to end
// (ReadRosBag: every record, every chunk decompressed, every sensor_msgs/Imu message decoded,
// as `plumb info` and `plumb calibrate` read it): the bag's header record, then its
// connections and chunks again and again (the index section left out: the reader does not need
// it) up to about kTargetBytes (a bz2 bag less: its chunks decompress to 3.5 times their size),
// written once into a temporary file removed at exit; the page cache holds it, so this measures
// the reader, not the disk. Counters: MB/s of bag, imu_msgs (IMU messages decoded per read) and
// msgs/s.
// BM_ReadRosBag/<bag>_lz4 reads the same bag with each chunk recompressed as an LZ4 frame (as
// `rosbag record --lz4` writes them). BM_ReadRosBag reads with no JobRunner (on the calling
// thread alone, as `plumb --jobs 1`); BM_ReadRosBagAhead/<bag> the same file with a runner of
// two threads (OnTwoThreads), as `plumb` reads it on a machine of two cores or more: the chunks
// decompressed up to three ahead of their parse, on either thread. Their process_cpu_ms
// counter is the CPU time of all the process's threads per read (getrusage), which the CPU
// column (the benchmark's thread alone) leaves out; the Time column is wall time.
// BM_ReadRealRosBag/<bag>_{alone,ahead} reads the real bag itself, a few chunks, with and
// without the two-thread runner: where reading ahead pays.
// BM_Bunzip2/<bag> and BM_Lz4/<bag>_lz4 decompress the same file's chunks with libbz2 alone
// (BZ2_bzBuffToBuffDecompress) or liblz4 alone (LZ4F_decompress) into one buffer: the floor
// under BM_ReadRosBag of a compressed bag.
// Skipped with the reason when the shared data is absent.
#include <benchmark/benchmark.h>
#include <bzlib.h>
#include <lz4frame.h>
#include <sys/resource.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "plumb/core/jobs.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/ros/rosbag.h"
#include "plumb/io/ros/rosbag_format.h"
#include "support/reverse_jobs.h"

namespace {

constexpr std::size_t kTargetBytes = 150u * 1000u * 1000u;
constexpr std::size_t kTargetBz2Bytes = 30u * 1000u * 1000u;

/// A top-level record of a bag: where it is and its op.
struct TopRecord {
  std::size_t begin = 0;
  std::size_t end = 0;
  std::uint8_t op = 0;
  std::size_t data_begin = 0;     ///< its data
  std::uint32_t size = 0;         ///< a chunk's uncompressed size
  std::string compression;
};

/// The top-level records of `bytes` (a whole bag 2.0).
std::vector<TopRecord> Records(const std::vector<char>& bytes) {
  std::vector<TopRecord> out;
  const auto* p = reinterpret_cast<const std::uint8_t*>(bytes.data());
  std::size_t pos = plumb::io::detail::kRosBagMagicSize;
  while (pos + 8 <= bytes.size()) {
    const auto header_len = plumb::io::LoadLittleEndian<std::uint32_t>(p + pos);
    const auto data_len = plumb::io::LoadLittleEndian<std::uint32_t>(p + pos + 4 + header_len);
    plumb::io::detail::RosRecordFields fields;
    std::string why;
    plumb::io::detail::ParseRecordFields(p + pos + 4, header_len, &fields, &why);
    TopRecord r;
    r.begin = pos;
    r.data_begin = pos + 8 + header_len;
    r.end = r.data_begin + data_len;
    r.op = fields.op;
    r.size = fields.size;
    r.compression = std::string(fields.compression);
    out.push_back(r);
    pos = r.end;
  }
  return out;
}

/// `bytes` (a whole bag 2.0) with every bz2 or uncompressed chunk recompressed as an LZ4 frame.
std::vector<char> AsLz4(const std::vector<char>& bytes) {
  std::vector<char> out;
  std::size_t copied = 0;
  for (const TopRecord& r : Records(bytes)) {
    if (r.op != plumb::io::detail::kOpChunk) continue;
    out.insert(out.end(), bytes.begin() + static_cast<long>(copied),
               bytes.begin() + static_cast<long>(r.begin));
    std::vector<char> plain(r.size);
    if (r.compression == "bz2") {
      unsigned n = r.size;
      BZ2_bzBuffToBuffDecompress(plain.data(), &n, const_cast<char*>(bytes.data() + r.data_begin),
                                 static_cast<unsigned>(r.end - r.data_begin), 0, 0);
    } else {
      std::copy(bytes.begin() + static_cast<long>(r.data_begin),
                bytes.begin() + static_cast<long>(r.end), plain.begin());
    }
    std::vector<char> packed(LZ4F_compressFrameBound(plain.size(), nullptr));
    packed.resize(LZ4F_compressFrame(packed.data(), packed.size(), plain.data(), plain.size(),
                                     nullptr));
    const auto field = [](const std::string& name, const std::string& value) {
      const auto len = static_cast<std::uint32_t>(name.size() + 1 + value.size());
      return std::string(reinterpret_cast<const char*>(&len), 4) + name + "=" + value;
    };
    const std::uint32_t size = r.size;
    const std::string header = field("op", std::string(1, '\x05')) + field("compression", "lz4") +
                               field("size", std::string(reinterpret_cast<const char*>(&size), 4));
    const auto header_len = static_cast<std::uint32_t>(header.size());
    const auto data_len = static_cast<std::uint32_t>(packed.size());
    out.insert(out.end(), reinterpret_cast<const char*>(&header_len),
               reinterpret_cast<const char*>(&header_len) + 4);
    out.insert(out.end(), header.begin(), header.end());
    out.insert(out.end(), reinterpret_cast<const char*>(&data_len),
               reinterpret_cast<const char*>(&data_len) + 4);
    out.insert(out.end(), packed.begin(), packed.end());
    copied = r.end;
  }
  out.insert(out.end(), bytes.begin() + static_cast<long>(copied), bytes.end());
  return out;
}

/// A temporary file holding the bag `relative` (its chunks as LZ4 frames when `lz4`) with its
/// connections and chunks repeated up to about `target` bytes; removed at exit.
class RepeatedBag {
 public:
  RepeatedBag(const std::string& source, std::size_t target, bool lz4) {
    std::ifstream in(source, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    if (lz4) bytes = AsLz4(bytes);
    const std::vector<TopRecord> records = Records(bytes);
    std::size_t body_begin = records.at(0).end;  // after the bag header
    std::size_t body_end = body_begin;
    for (const TopRecord& r : records) {
      if (r.op == plumb::io::detail::kOpChunk || r.op == plumb::io::detail::kOpConnection) {
        body_end = r.end;
      } else if (r.op != plumb::io::detail::kOpBagHeader) {
        break;  // the index section
      }
    }
    path_ = (std::filesystem::temp_directory_path() /
             ("plumb_bench_" + std::string(lz4 ? "lz4_" : "") +
              std::filesystem::path(source).filename().string()))
                .string();
    std::ofstream out(path_, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(body_begin));
    const std::size_t copies = std::max<std::size_t>(1, target / (body_end - body_begin));
    for (std::size_t k = 0; k < copies; ++k) {
      out.write(bytes.data() + body_begin, static_cast<std::streamsize>(body_end - body_begin));
    }
  }
  ~RepeatedBag() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// The repeated copy of `relative` (under ../shared/data; its chunks as LZ4 frames when `lz4`),
/// made once; nullptr when absent.
const RepeatedBag* Repeated(const std::string& relative, std::size_t target, bool lz4 = false) {
  static std::map<std::string, std::unique_ptr<RepeatedBag>> made;
  const std::string source = std::string(PLUMB_SHARED_DATA_DIR) + "/" + relative;
  if (!std::filesystem::exists(source)) return nullptr;
  auto& slot = made[relative + (lz4 ? " lz4" : "")];
  if (!slot) slot = std::make_unique<RepeatedBag>(source, target, lz4);
  return slot.get();
}

void SetCounters(benchmark::State& state, std::size_t bytes, std::size_t messages) {
  const double iterations = static_cast<double>(state.iterations());
  state.counters["MB/s"] = benchmark::Counter(iterations * static_cast<double>(bytes) / 1e6,
                                              benchmark::Counter::kIsRate);
  state.counters["msgs/s"] =
      benchmark::Counter(iterations * static_cast<double>(messages), benchmark::Counter::kIsRate);
  state.counters["imu_msgs"] = static_cast<double>(messages);
  state.counters["MB"] = static_cast<double>(bytes) / 1e6;
}

/// The CPU time this process's threads have used, ms (user and system).
double ProcessCpuMs() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto ms = [](const timeval& t) { return 1e3 * t.tv_sec + 1e-3 * t.tv_usec; };
  return ms(usage.ru_utime) + ms(usage.ru_stime);
}

/// ReadRosBag of the repeated `relative` through `run_jobs` (empty: on this thread alone).
void ReadRosBagWith(benchmark::State& state, const std::string& relative, std::size_t target,
                    bool lz4, const plumb::JobRunner& run_jobs) {
  const RepeatedBag* bag = Repeated(relative, target, lz4);
  if (bag == nullptr) {
    state.SkipWithError(("shared data absent: " + relative).c_str());
    return;
  }
  std::size_t messages = 0;
  const double cpu_before = ProcessCpuMs();
  for (auto _ : state) {
    const plumb::io::RosBag read = plumb::io::ReadRosBag(bag->path(), run_jobs);
    messages = 0;
    for (const plumb::io::RosImuTopic& t : read.imu_topics) messages += t.samples.size();
    benchmark::DoNotOptimize(messages);
  }
  const double cpu_ms = ProcessCpuMs() - cpu_before;
  SetCounters(state, std::filesystem::file_size(bag->path()), messages);
  state.counters["process_cpu_ms"] = cpu_ms / static_cast<double>(state.iterations());
}

void BM_ReadRosBag(benchmark::State& state, const std::string& relative, std::size_t target,
                   bool lz4 = false) {
  ReadRosBagWith(state, relative, target, lz4, {});
}
void BM_ReadRosBagAhead(benchmark::State& state, const std::string& relative,
                        std::size_t target, bool lz4 = false) {
  ReadRosBagWith(state, relative, target, lz4, plumb::testing::OnTwoThreads);
}
BENCHMARK_CAPTURE(BM_ReadRosBag, ardrone_imu_uncompressed,
                  std::string("ros/ardrone_imu_uncompressed.bag"), kTargetBytes)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRosBag, ardrone_imu_bz2, std::string("ros/ardrone_imu.bag"),
                  kTargetBz2Bytes)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRosBag, phidgets_imu_upside_down_bz2,
                  std::string("ros/phidgets_imu_upside_down.bag"), kTargetBz2Bytes)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRosBag, ardrone_imu_lz4, std::string("ros/ardrone_imu.bag"),
                  kTargetBytes, true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRosBagAhead, ardrone_imu_uncompressed,
                  std::string("ros/ardrone_imu_uncompressed.bag"), kTargetBytes)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRosBagAhead, ardrone_imu_bz2, std::string("ros/ardrone_imu.bag"),
                  kTargetBz2Bytes)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRosBagAhead, phidgets_imu_upside_down_bz2,
                  std::string("ros/phidgets_imu_upside_down.bag"), kTargetBz2Bytes)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRosBagAhead, ardrone_imu_lz4, std::string("ros/ardrone_imu.bag"),
                  kTargetBytes, true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// The real bag `relative` itself (4 bz2, 10 bz2 or 3 uncompressed chunks), read through
/// `run_jobs`, or on this thread alone: where reading ahead pays (detail::kRosChunksReadAhead).
void BM_ReadRealRosBag(benchmark::State& state, const std::string& relative, bool ahead) {
  const std::string path = std::string(PLUMB_SHARED_DATA_DIR) + "/" + relative;
  if (!std::filesystem::exists(path)) {
    state.SkipWithError(("shared data absent: " + relative).c_str());
    return;
  }
  const plumb::JobRunner run_jobs =
      ahead ? plumb::JobRunner(plumb::testing::OnTwoThreads) : plumb::JobRunner();
  std::size_t messages = 0;
  const double cpu_before = ProcessCpuMs();
  for (auto _ : state) {
    const plumb::io::RosBag read = plumb::io::ReadRosBag(path, run_jobs);
    messages = 0;
    for (const plumb::io::RosImuTopic& t : read.imu_topics) messages += t.samples.size();
    benchmark::DoNotOptimize(messages);
  }
  const double cpu_ms = ProcessCpuMs() - cpu_before;
  SetCounters(state, std::filesystem::file_size(path), messages);
  state.counters["process_cpu_ms"] = cpu_ms / static_cast<double>(state.iterations());
}
BENCHMARK_CAPTURE(BM_ReadRealRosBag, ardrone_imu_bz2_alone, std::string("ros/ardrone_imu.bag"),
                  false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRealRosBag, ardrone_imu_bz2_ahead, std::string("ros/ardrone_imu.bag"),
                  true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRealRosBag, phidgets_bz2_alone,
                  std::string("ros/phidgets_imu_upside_down.bag"), false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRealRosBag, phidgets_bz2_ahead,
                  std::string("ros/phidgets_imu_upside_down.bag"), true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRealRosBag, ardrone_imu_uncompressed_alone,
                  std::string("ros/ardrone_imu_uncompressed.bag"), false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadRealRosBag, ardrone_imu_uncompressed_ahead,
                  std::string("ros/ardrone_imu_uncompressed.bag"), true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Bunzip2(benchmark::State& state, const std::string& relative, std::size_t target) {
  const RepeatedBag* bag = Repeated(relative, target);
  if (bag == nullptr) {
    state.SkipWithError(("shared data absent: " + relative).c_str());
    return;
  }
  std::ifstream in(bag->path(), std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  const std::vector<TopRecord> records = Records(bytes);
  std::vector<char> out;
  for (auto _ : state) {
    for (const TopRecord& r : records) {
      if (r.op != plumb::io::detail::kOpChunk || r.compression != "bz2") continue;
      out.resize(r.size);
      unsigned n = r.size;
      BZ2_bzBuffToBuffDecompress(out.data(), &n, bytes.data() + r.data_begin,
                                 static_cast<unsigned>(r.end - r.data_begin), 0, 0);
      benchmark::DoNotOptimize(out.data());
    }
  }
  SetCounters(state, bytes.size(), 0);
}
BENCHMARK_CAPTURE(BM_Bunzip2, ardrone_imu_bz2, std::string("ros/ardrone_imu.bag"),
                  kTargetBz2Bytes)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Bunzip2, phidgets_imu_upside_down_bz2,
                  std::string("ros/phidgets_imu_upside_down.bag"), kTargetBz2Bytes)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Lz4(benchmark::State& state, const std::string& relative, std::size_t target) {
  const RepeatedBag* bag = Repeated(relative, target, true);
  if (bag == nullptr) {
    state.SkipWithError(("shared data absent: " + relative).c_str());
    return;
  }
  std::ifstream in(bag->path(), std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  const std::vector<TopRecord> records = Records(bytes);
  std::vector<char> out;
  LZ4F_dctx* ctx = nullptr;
  LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION);
  for (auto _ : state) {
    for (const TopRecord& r : records) {
      if (r.op != plumb::io::detail::kOpChunk || r.compression != "lz4") continue;
      out.resize(r.size);
      std::size_t out_size = out.size();
      std::size_t in_size = r.end - r.data_begin;
      const std::size_t rc = LZ4F_decompress(ctx, out.data(), &out_size,
                                             bytes.data() + r.data_begin, &in_size, nullptr);
      if (LZ4F_isError(rc) || rc != 0 || out_size != r.size) {
        state.SkipWithError("lz4 decompression failed");
        LZ4F_freeDecompressionContext(ctx);
        return;
      }
      benchmark::DoNotOptimize(out.data());
    }
  }
  LZ4F_freeDecompressionContext(ctx);
  SetCounters(state, bytes.size(), 0);
}
BENCHMARK_CAPTURE(BM_Lz4, ardrone_imu_lz4, std::string("ros/ardrone_imu.bag"), kTargetBytes)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

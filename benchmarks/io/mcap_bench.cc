// Reading speed of the ROS 2 MCAP reader (SPEC section 7: at least 1 GB/s uncompressed, near
// the decompressor's own speed compressed).
//
// BM_ReadMcap/<copy> reads a large MCAP file end to end (ReadMcap: every record, every chunk
// decompressed, every sensor_msgs/msg/Imu message decoded from CDR, as `plumb info` and
// `plumb calibrate` read it). The file is made from the MCAP copies of
// ../shared/data/ros/ardrone_imu.bag that tests/io/ros2_fixtures/make-fixtures writes with
// @mcap/core into build/ros2_fixtures (uncompressed, zstd, lz4 chunks of 256 KiB): its magic and
// Header, then its data section (Schema, Channel, Chunk and MessageIndex records, up to
// DataEnd) again and again up to about kTargetBytes, then a Footer; written once into a
// temporary file removed at exit, held by the page cache (this measures the reader, not the
// disk). Counters: bytes_per_second of file, items_per_second (IMU messages decoded), MB (of
// file), imu_msgs (IMU messages decoded per read) and process_cpu_ms (the CPU time of all the
// process's threads per read, getrusage: BM_ReadMcapAhead's runner decompresses chunks on a
// second thread, which the CPU column, the benchmark's thread alone, leaves out; the Time
// column is wall time, UseRealTime). BM_ReadMcap reads with no JobRunner (on the calling
// thread alone, as `plumb --jobs 1`); BM_ReadMcapAhead/<copy> the same file with a runner of
// two threads (OnTwoThreads), as `plumb` reads it on a machine of two cores or more: the chunks
// decompressed and CRC-checked up to three ahead of their parse.
// BM_McapZstd/<copy> and BM_McapLz4/<copy> decompress the same file's chunks with libzstd alone
// (ZSTD_decompressDCtx, into one buffer of the largest chunk's size and one byte, as the
// reader's) or liblz4 alone (LZ4F_decompress, into one buffer with room for the frames' 4 MiB
// block, as the reader's since liblz4 then decodes a block without copying it;
// BM_McapLz4/ardrone_imu_lz4_chunk_room with room for the chunk's size and one byte, as the
// reader had before: liblz4 then decodes into its own buffer and copies each chunk out): the
// floor under BM_ReadMcap of a compressed file. Their <copy>_crc32 variants then check each
// chunk's CRC-32 (libdeflate_crc32, the reader's detail::Crc32) on the chunk just
// decompressed, in cache, as the reader does: decompression and check, the floor under the
// whole read. items_per_second counts chunks, "MB out" the bytes decompressed per pass.
// BM_ReadMcap/ardrone_imu_zstd_decompressed reads the repeated zstd file with its chunks stored
// decompressed (compression "", the same records and CRCs): the same messages as
// BM_ReadMcap/ardrone_imu_zstd without the decompression, i.e. the reader's own share (the
// records walked, the CRCs checked, the messages decoded), which libzstd alone does not do.
// BM_McapCrc32/ardrone_imu_zstd computes the CRC-32 (libdeflate_crc32, as the reader) of every
// chunk's records of that decompressed copy, read from memory (bytes_per_second: of records
// checked). BM_McapCrc32Chunk/libdeflate_in_cache: libdeflate_crc32 of one 256 KiB chunk held
// in cache, again and again: the check's own speed where the reader does it.
// BM_ParseMcapAhead/<copy>_{alone,ahead}: the fixture itself (9 chunks of 256 KiB) or its data
// section repeated to about 10 MB (108 lz4, 126 zstd chunks), parsed from memory with the chunks
// read ahead through OnTwoThreads (`ahead`) or on the calling thread alone (`alone`), whatever
// their number (the reader itself reads ahead from detail::kMcapChunksReadAhead chunks): where
// reading ahead pays.
// Skipped with the reason when the fixtures cannot be made (data, node or the npm packages
// absent).
#include <benchmark/benchmark.h>
#include <libdeflate.h>
#include <sys/resource.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "plumb/core/jobs.h"
#include "support/reverse_jobs.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/ros/mcap.h"
#include "plumb/io/ros/read_ahead.h"

namespace {

constexpr std::size_t kTargetBytes = 150u * 1000u * 1000u;
constexpr std::size_t kMagic = 8;

/// A top-level record: where it is and its opcode; a chunk's compression, uncompressed size and
/// where its compressed records are.
struct TopRecord {
  std::uint8_t op = 0;
  std::size_t begin = 0, end = 0;
  std::string compression;
  std::uint64_t size = 0;
  std::size_t data_begin = 0, data_end = 0;
};

std::vector<TopRecord> Records(const std::vector<char>& bytes) {
  using plumb::io::LoadLittleEndian;
  std::vector<TopRecord> out;
  const auto* p = reinterpret_cast<const std::uint8_t*>(bytes.data());
  std::size_t pos = kMagic;
  while (pos + 9 <= bytes.size()) {
    TopRecord r;
    r.op = p[pos];
    r.begin = pos;
    r.end = pos + 9 + LoadLittleEndian<std::uint64_t>(p + pos + 1);
    if (r.op == 0x06) {
      const std::uint8_t* c = p + pos + 9;
      r.size = LoadLittleEndian<std::uint64_t>(c + 16);
      const auto len = LoadLittleEndian<std::uint32_t>(c + 28);
      r.compression.assign(reinterpret_cast<const char*>(c + 32), len);
      r.data_begin = pos + 9 + 32 + len + 8;
      r.data_end = r.end;
    }
    out.push_back(r);
    if (r.op == 0x02) break;  // Footer
    pos = r.end;
  }
  return out;
}

/// Runs make-fixtures once; "" when the fixtures are there, else why not.
std::string MakeFixtures(const std::string& prefix) {
  static const std::string why = [&] {
    const std::string bag = std::string(PLUMB_SHARED_DATA_DIR) + "/ros/ardrone_imu.bag";
    const std::string command = std::string(PLUMB_SOURCE_DIR) +
                                "/tests/io/ros2_fixtures/make-fixtures '" + bag + "' '" + prefix +
                                "' 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) return std::string("cannot run make-fixtures");
    char buffer[4096];
    std::string out;
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out.append(buffer, n);
    return ::pclose(pipe) == 0 ? std::string() : "ROS 2 fixtures absent: " + out;
  }();
  return why;
}

/// A temporary file holding the MCAP `source`'s data section repeated up to about `target`
/// bytes; removed at exit.
class RepeatedMcap {
 public:
  RepeatedMcap(const std::string& source, std::size_t target) {
    std::ifstream in(source, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    const std::vector<TopRecord> records = Records(bytes);
    const std::size_t body_begin = records.at(0).end;  // after the Header
    std::size_t body_end = body_begin;
    for (const TopRecord& r : records) {
      if (r.op == 0x0F) break;  // DataEnd
      body_end = r.end;
    }
    path_ = (std::filesystem::temp_directory_path() /
             ("plumb_bench_" + std::to_string(target) + "_" +
              std::filesystem::path(source).filename().string()))
                .string();
    std::ofstream out(path_, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(body_begin));
    const std::size_t copies = std::max<std::size_t>(1, target / (body_end - body_begin));
    for (std::size_t k = 0; k < copies; ++k) {
      out.write(bytes.data() + body_begin, static_cast<std::streamsize>(body_end - body_begin));
    }
    const char footer[] = {0x02, 20, 0, 0, 0, 0, 0, 0, 0};
    out.write(footer, sizeof footer);
    out.write(std::string(20, '\0').data(), 20);
    out.write(bytes.data(), kMagic);
  }
  ~RepeatedMcap() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// A chunk record holding `records` uncompressed, its other fields those of chunk `r` of `p`.
std::string UncompressedChunk(const std::uint8_t* p, const TopRecord& r,
                              const std::vector<char>& records) {
  std::string out(1, '\x06');
  const auto put = [&out](std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out += static_cast<char>((v >> (8 * i)) & 0xff);
  };
  put(8 + 8 + 8 + 4 + 4 + 8 + records.size(), 8);
  out.append(reinterpret_cast<const char*>(p + r.begin + 9), 28);  // times, size, CRC
  put(0, 4);                                                        // compression ""
  put(records.size(), 8);
  out.append(records.data(), records.size());
  return out;
}

/// `source` (an MCAP file of zstd chunks) with every chunk stored decompressed, written to a
/// temporary file removed at exit.
class DecompressedMcap {
 public:
  explicit DecompressedMcap(const std::string& source) : path_(source + ".decompressed") {
    std::ifstream in(source, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    const auto* p = reinterpret_cast<const std::uint8_t*>(bytes.data());
    std::ofstream out(path_, std::ios::binary);
    out.write(bytes.data(), kMagic);
    std::vector<char> records;
    for (const TopRecord& r : Records(bytes)) {
      if (r.op != 0x06 || r.compression != "zstd") {
        out.write(bytes.data() + r.begin, static_cast<std::streamsize>(r.end - r.begin));
        continue;
      }
      records.resize(r.size);
      ZSTD_decompress(records.data(), records.size(), bytes.data() + r.data_begin,
                      r.data_end - r.data_begin);
      out << UncompressedChunk(p, r, records);
    }
    out.write(bytes.data(), kMagic);
  }
  ~DecompressedMcap() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// The repeated copy of fixture `name` ("ardrone_imu_zstd.mcap") up to about `target` bytes (0:
/// the data section once), made once; nullptr with `why` when the fixtures are absent. `name`
/// "ardrone_imu_zstd_decompressed": the zstd one's DecompressedMcap.
const std::string* Repeated(const std::string& name, std::string* why,
                            std::size_t target = kTargetBytes) {
  static std::map<std::pair<std::string, std::size_t>, std::unique_ptr<RepeatedMcap>> made;
  static std::unique_ptr<DecompressedMcap> decompressed;
  const std::string dir = std::string(PLUMB_BINARY_DIR) + "/ros2_fixtures";
  *why = MakeFixtures(dir + "/ardrone_imu");
  if (!why->empty()) return nullptr;
  if (name == "ardrone_imu_zstd_decompressed") {
    const std::string* zstd = Repeated("ardrone_imu_zstd.mcap", why);
    if (!decompressed) decompressed = std::make_unique<DecompressedMcap>(*zstd);
    return &decompressed->path();
  }
  auto& slot = made[{name, target}];
  if (!slot) slot = std::make_unique<RepeatedMcap>(dir + "/" + name, target);
  return &slot->path();
}

/// Per pass: `bytes` processed (bytes_per_second), `items` decoded (items_per_second: IMU
/// messages, or chunks for the baselines).
void SetCounters(benchmark::State& state, std::size_t bytes, std::size_t items) {
  const auto iterations = static_cast<std::int64_t>(state.iterations());
  state.SetBytesProcessed(iterations * static_cast<std::int64_t>(bytes));
  state.SetItemsProcessed(iterations * static_cast<std::int64_t>(items));
  state.counters["MB"] = static_cast<double>(bytes) / 1e6;
}

/// The CPU time this process's threads have used, ms (user and system): a pipelined read's
/// helper threads counted too, which the CPU column (the benchmark's thread) leaves out.
double ProcessCpuMs() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto ms = [](const timeval& t) { return 1e3 * t.tv_sec + 1e-3 * t.tv_usec; };
  return ms(usage.ru_utime) + ms(usage.ru_stime);
}

using plumb::testing::OnTwoThreads;

/// ReadMcap of the repeated `name` through `run_jobs` (empty: on this thread alone).
void ReadMcapWith(benchmark::State& state, const std::string& name,
                  const plumb::JobRunner& run_jobs) {
  std::string why;
  const std::string* file = Repeated(name, &why);
  if (file == nullptr) {
    state.SkipWithError(why.c_str());
    return;
  }
  std::size_t messages = 0;
  const double cpu_before = ProcessCpuMs();
  for (auto _ : state) {
    const plumb::io::RosBag read = plumb::io::ReadMcap(*file, run_jobs);
    messages = 0;
    for (const plumb::io::RosImuTopic& t : read.imu_topics) messages += t.samples.size();
    benchmark::DoNotOptimize(messages);
  }
  const double cpu_ms = ProcessCpuMs() - cpu_before;
  SetCounters(state, std::filesystem::file_size(*file), messages);
  state.counters["imu_msgs"] = static_cast<double>(messages);
  state.counters["process_cpu_ms"] = cpu_ms / static_cast<double>(state.iterations());
}

void BM_ReadMcap(benchmark::State& state, const std::string& name) {
  ReadMcapWith(state, name, {});
}
void BM_ReadMcapAhead(benchmark::State& state, const std::string& name) {
  ReadMcapWith(state, name, OnTwoThreads);
}
BENCHMARK_CAPTURE(BM_ReadMcap, ardrone_imu_uncompressed, std::string("ardrone_imu.mcap"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadMcap, ardrone_imu_zstd, std::string("ardrone_imu_zstd.mcap"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadMcap, ardrone_imu_lz4, std::string("ardrone_imu_lz4.mcap"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadMcap, ardrone_imu_zstd_decompressed,
                  std::string("ardrone_imu_zstd_decompressed"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadMcapAhead, ardrone_imu_uncompressed, std::string("ardrone_imu.mcap"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadMcapAhead, ardrone_imu_zstd, std::string("ardrone_imu_zstd.mcap"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadMcapAhead, ardrone_imu_lz4, std::string("ardrone_imu_lz4.mcap"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_ReadMcapAhead, ardrone_imu_zstd_decompressed,
                  std::string("ardrone_imu_zstd_decompressed"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// A small or middling copy read from memory (ParseMcap) with its chunks read ahead through
/// OnTwoThreads (`ahead`) or on this thread alone, whatever their number: what reading ahead
/// costs or gains below and above detail::kMcapChunksReadAhead. `target`: RepeatedMcap's.
void BM_ParseMcapAhead(benchmark::State& state, const std::string& name, std::size_t target,
                       bool ahead) {
  std::string why;
  const std::string* file = Repeated(name, &why, target);
  if (file == nullptr) {
    state.SkipWithError(why.c_str());
    return;
  }
  std::ifstream in(*file, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  const plumb::JobRunner run_jobs = ahead ? plumb::JobRunner(OnTwoThreads) : plumb::JobRunner();
  std::size_t chunks = 0;
  const double cpu_before = ProcessCpuMs();
  for (auto _ : state) {
    const plumb::io::RosBag read =
        plumb::io::detail::ParseMcapReadingAhead(data, bytes.size(), "bench", run_jobs, 0);
    chunks = read.chunks;
    benchmark::DoNotOptimize(chunks);
  }
  const double cpu_ms = ProcessCpuMs() - cpu_before;
  SetCounters(state, bytes.size(), chunks);
  state.counters["chunks"] = static_cast<double>(chunks);
  state.counters["process_cpu_ms"] = cpu_ms / static_cast<double>(state.iterations());
}
#define PLUMB_PARSE_AHEAD(copy, file, target)                                                   \
  BENCHMARK_CAPTURE(BM_ParseMcapAhead, copy##_alone, std::string(file), target, false)         \
      ->Unit(benchmark::kMillisecond)                                                          \
      ->UseRealTime();                                                                         \
  BENCHMARK_CAPTURE(BM_ParseMcapAhead, copy##_ahead, std::string(file), target, true)          \
      ->Unit(benchmark::kMillisecond)                                                          \
      ->UseRealTime()
PLUMB_PARSE_AHEAD(zstd_fixture, "ardrone_imu_zstd.mcap", 0);
PLUMB_PARSE_AHEAD(lz4_fixture, "ardrone_imu_lz4.mcap", 0);
PLUMB_PARSE_AHEAD(zstd_10MB, "ardrone_imu_zstd.mcap", 10000000);
PLUMB_PARSE_AHEAD(lz4_10MB, "ardrone_imu_lz4.mcap", 10000000);
#undef PLUMB_PARSE_AHEAD


/// The bytes of the repeated `name` and its top-level records (nullopt, the state skipped,
/// when it cannot be made).
struct McapBytes {
  std::vector<char> bytes;
  std::vector<TopRecord> records;
};
std::optional<McapBytes> LoadMcap(benchmark::State& state, const std::string& name) {
  std::string why;
  const std::string* file = Repeated(name, &why);
  if (file == nullptr) {
    state.SkipWithError(why.c_str());
    return std::nullopt;
  }
  std::ifstream in(*file, std::ios::binary);
  McapBytes out;
  out.bytes.assign(std::istreambuf_iterator<char>(in), {});
  out.records = Records(out.bytes);
  return out;
}

/// Decompresses every chunk of the repeated `name` with `decompress` (false: failed) into one
/// buffer of `room` bytes (at least the largest chunk's size and one byte), then, when
/// `check_crc`, checks its CRC-32 with libdeflate_crc32 (the chunk's records in cache, as in
/// the reader).
template <typename Decompress>
void DecompressChunks(benchmark::State& state, const std::string& name, Decompress decompress,
                      bool check_crc, std::size_t room) {
  const std::optional<McapBytes> mcap = LoadMcap(state, name);
  if (!mcap) return;
  const std::vector<char>& bytes = mcap->bytes;
  const auto* p = reinterpret_cast<const std::uint8_t*>(bytes.data());
  const std::vector<TopRecord>& records = mcap->records;
  // One buffer for all (as the reader's, never resized per chunk: resizing a vector per chunk
  // made liblz4 alone 3 to 5 times slower).
  std::size_t largest = 0, chunks = 0, out_bytes = 0;
  for (const TopRecord& r : records) {
    largest = std::max<std::size_t>(largest, r.size);
    chunks += r.op == 0x06;
    out_bytes += r.op == 0x06 ? r.size : 0;
  }
  std::vector<char> out(std::max<std::size_t>(largest + 1, room));
  const auto* q = reinterpret_cast<const std::uint8_t*>(out.data());
  for (auto _ : state) {
    for (const TopRecord& r : records) {
      if (r.op != 0x06) continue;
      if (!decompress(bytes.data() + r.data_begin, r.data_end - r.data_begin, r.size,
                      out.data())) {
        state.SkipWithError("decompression failed");
        return;
      }
      if (check_crc && libdeflate_crc32(0, q, r.size) !=
                           plumb::io::LoadLittleEndian<std::uint32_t>(p + r.begin + 9 + 24)) {
        state.SkipWithError("a chunk's CRC-32 differs");
        return;
      }
      benchmark::ClobberMemory();
    }
  }
  SetCounters(state, bytes.size(), chunks);
  state.counters["MB out"] = static_cast<double>(out_bytes) / 1e6;
}

void BM_McapZstd(benchmark::State& state, const std::string& name, bool check_crc) {
  ZSTD_DCtx* ctx = ZSTD_createDCtx();
  const auto decompress = [ctx](const char* in, std::size_t n, std::size_t size, char* out) {
    const std::size_t rc = ZSTD_decompressDCtx(ctx, out, size + 1, in, n);
    return !ZSTD_isError(rc) && rc == size;
  };
  DecompressChunks(state, name, decompress, check_crc, 0);
  ZSTD_freeDCtx(ctx);
}
BENCHMARK_CAPTURE(BM_McapZstd, ardrone_imu_zstd, std::string("ardrone_imu_zstd.mcap"), false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_McapZstd, ardrone_imu_zstd_crc32, std::string("ardrone_imu_zstd.mcap"), true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// Room for the LZ4 frames' largest block (4 MiB: the fixtures' frames state it, @mcap/core's
/// default), into which liblz4 decodes a block directly, as the reader gives it (Lz4Whole).
constexpr std::size_t kLz4Room = std::size_t{4} << 20;

/// liblz4 alone on every chunk, given `room` bytes of output (0: the chunk's size and one
/// byte, less than a block, so that liblz4 decodes into its own buffer and copies out).
void BM_McapLz4(benchmark::State& state, const std::string& name, bool check_crc,
                std::size_t room) {
  LZ4F_dctx* ctx = nullptr;
  LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION);
  const auto decompress = [ctx, room](const char* in, std::size_t n, std::size_t size,
                                      char* out) {
    LZ4F_resetDecompressionContext(ctx);  // as the reader does at each chunk
    std::size_t out_size = std::max<std::size_t>(size + 1, room);
    std::size_t in_size = n;
    const std::size_t rc = LZ4F_decompress(ctx, out, &out_size, in, &in_size, nullptr);
    return !LZ4F_isError(rc) && rc == 0 && out_size == size;
  };
  DecompressChunks(state, name, decompress, check_crc, room);
  LZ4F_freeDecompressionContext(ctx);
}
BENCHMARK_CAPTURE(BM_McapLz4, ardrone_imu_lz4, std::string("ardrone_imu_lz4.mcap"), false,
                  kLz4Room)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_McapLz4, ardrone_imu_lz4_crc32, std::string("ardrone_imu_lz4.mcap"), true,
                  kLz4Room)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_McapLz4, ardrone_imu_lz4_chunk_room, std::string("ardrone_imu_lz4.mcap"),
                  false, std::size_t{0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_McapCrc32(benchmark::State& state, const std::string& name) {
  const std::optional<McapBytes> mcap = LoadMcap(state, name);
  if (!mcap) return;
  const std::vector<char>& bytes = mcap->bytes;
  const auto* p = reinterpret_cast<const std::uint8_t*>(bytes.data());
  const std::vector<TopRecord>& records = mcap->records;
  std::size_t checked = 0, chunks = 0;
  for (auto _ : state) {
    checked = 0;
    chunks = 0;
    for (const TopRecord& r : records) {
      if (r.op != 0x06) continue;
      const auto stated = plumb::io::LoadLittleEndian<std::uint32_t>(p + r.begin + 9 + 24);
      if (libdeflate_crc32(0, p + r.data_begin, r.data_end - r.data_begin) != stated) {
        state.SkipWithError("a chunk's CRC-32 differs");
        return;
      }
      checked += r.data_end - r.data_begin;
      ++chunks;
    }
    benchmark::DoNotOptimize(checked);
  }
  SetCounters(state, checked, chunks);
}
BENCHMARK_CAPTURE(BM_McapCrc32, ardrone_imu_zstd, std::string("ardrone_imu_zstd_decompressed"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// libdeflate_crc32 of one 256 KiB chunk (pseudo-random bytes) held in cache, again and again:
/// the check's own speed where the reader does it, on a chunk just decompressed;
/// BM_McapCrc32/ardrone_imu_zstd reads its records from memory instead.
void BM_McapCrc32Chunk(benchmark::State& state) {
  std::vector<std::uint8_t> chunk(std::size_t{256} << 10);
  std::uint64_t x = 0x9E3779B97F4A7C15ull;  // xorshift64
  for (std::uint8_t& b : chunk) {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    b = static_cast<std::uint8_t>(x >> 56);
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(libdeflate_crc32(0, chunk.data(), chunk.size()));
  }
  SetCounters(state, chunk.size(), 1);
}
BENCHMARK(BM_McapCrc32Chunk)->Name("BM_McapCrc32Chunk/libdeflate_in_cache");

}  // namespace

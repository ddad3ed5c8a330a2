// plumb/io/common/log_common.cc — see log_common.h.
#include "plumb/io/common/log_common.h"

#include <fcntl.h>
#include <linux/mman.h>  // MADV_COLLAPSE (Linux 6.1), which glibc's header may lack
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <memory>
#include <cstring>
#include <fstream>
#include <iterator>
#include <new>

#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/io/common/flight_log.h"
#include "plumb/io/common/stream_spool.h"

namespace plumb::io {
namespace {

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

LogFile::LogFile(const std::string& path, const std::string& what) : path_(path) {
  const int fd = ::open(OpenPath(path).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    throw InputError(path, "byte 0",
                     "cannot open the " + what + " for reading: " + std::strerror(errno));
  }
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    size_ = static_cast<std::size_t>(st.st_size);
    void* m = ::mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (m != MAP_FAILED) {
      ::madvise(m, size_, MADV_SEQUENTIAL);
      mapping_ = m;
      guard_ = std::make_unique<detail::MappingGuard>(m, size_);
      data_ = static_cast<const std::uint8_t*>(m);
      ::close(fd);
      return;
    }
  }
  ::close(fd);
  // Not mappable (empty, a pipe, a special file): read it.
  std::ifstream in(OpenPath(path), std::ios::binary);
  if (!in) throw InputError(path, "byte 0", "cannot open the " + what + " for reading");
  buffer_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) {
    throw InputError(path, "byte " + std::to_string(buffer_.size()),
                     "read failed before the end of the file");
  }
  data_ = buffer_.data();
  size_ = buffer_.size();
}

void LogFile::ThrowIfCut() const {
  if (guard_ != nullptr && guard_->cut()) throw detail::CutShortError(path_, size_);
}

void LogFile::Release(std::size_t from, std::size_t up_to) const {
  if (mapping_ == nullptr) return;
  const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const std::size_t begin = (from + page - 1) / page * page;  // whole pages only
  const std::size_t end = std::min(up_to, size_) / page * page;
  if (end > begin) {
    ::madvise(static_cast<std::uint8_t*>(mapping_) + begin, end - begin, MADV_DONTNEED);
  }
}

namespace {

/// Bytes ReadForward reads into its buffer per call beyond the consumer's look-ahead, when the
/// file is not mapped: 256 KiB, about what stays in the L2 cache while the parser goes over it
/// (cat reads 128 KiB).
constexpr std::size_t kReadChunk = std::size_t{1} << 18;

/// Reads up to `n` bytes at file offset `at` into `out`: fewer only at the end of the file.
std::size_t ReadAt(int fd, std::uint8_t* out, std::size_t n, std::size_t at,
                   const std::string& path) {
  std::size_t got = 0;
  while (got < n) {
    const ssize_t r = ::pread(fd, out + got, n - got, static_cast<off_t>(at + got));
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      throw InputError(path, "byte " + std::to_string(at + got),
                       std::string("read failed before the end of the file: ") +
                           std::strerror(errno));
    }
    if (r == 0) break;
    got += static_cast<std::size_t>(r);
  }
  return got;
}

/// Closes a descriptor at scope exit.
struct FdCloser {
  int fd;
  ~FdCloser() { ::close(fd); }
};

/// Bytes ReadForward hands over per call beyond the consumer's look-ahead from a mapped file:
/// 4 MiB. Nothing is copied, so the span need not fit a cache, and each span costs an fstat
/// and an madvise (ForwardMapping::Prepare): with 256 KiB spans the .bin reader took 12-20 %
/// longer (docs/performance.md).
constexpr std::size_t kMapSpan = std::size_t{4} << 20;

/// A huge page, bytes.
constexpr std::size_t kHugePage = std::size_t{2} << 20;
/// Bytes of its own bookkeeping an allocator keeps next to a large buffer, at most (glibc: a
/// 16-byte header before it, up to 16 bytes of rounding after it).
constexpr std::size_t kAllocatorSlack = 64;

/// Whether this system gives processes transparent huge pages when they ask (the mode in
/// /sys/kernel/mm/transparent_hugepage/enabled is "always" or "madvise"; read once). When an
/// administrator chose "never", no page is collapsed into one either (MADV_COLLAPSE would).
bool HugePagesAllowed() {
  static const bool allowed = [] {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string modes;
    std::getline(in, modes);
    return modes.find("[always]") != std::string::npos ||
           modes.find("[madvise]") != std::string::npos;
  }();
  return allowed;
}

/// Bytes behind the parser after which a mapped file's pages are dropped from this process's
/// memory (MADV_DONTNEED): 2 MiB, so that a few MiB of it are resident at a time.
constexpr std::size_t kDropStep = std::size_t{2} << 20;

/// A whole regular file mapped read-only. Before the parser gets a span, the file's size is
/// checked and the span's new pages read in with MADV_POPULATE_READ, which reports a read
/// error (a failing card) as an error. A file cut short while the parser is inside a span
/// unmaps the pages past its new end, populated or not: touching one reads zeros (the
/// mapping is guarded, detail::MappingGuard) and cut() turns true.
class ForwardMapping {
 public:
  /// The file `fd` of `size` bytes, to be read from byte `from` on.
  ForwardMapping(int fd, std::size_t size, std::size_t from)
      : fd_(fd), size_(size), populated_(from / Page() * Page()), dropped_(populated_) {
    if (size == 0) return;
    void* m = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (m == MAP_FAILED) return;
    base_ = static_cast<std::uint8_t*>(m);
    guard_ = std::make_unique<detail::MappingGuard>(base_, size);
    ::madvise(base_, size, MADV_SEQUENTIAL);  // a hint: errors ignored
  }
  ~ForwardMapping() {
    guard_.reset();  // before the range can be mapped again by anything else
    if (base_ != nullptr) ::munmap(base_, size_);
  }
  ForwardMapping(const ForwardMapping&) = delete;
  ForwardMapping& operator=(const ForwardMapping&) = delete;

  const std::uint8_t* data() const { return base_; }

  /// Whether a page was found past the file's end (the file was cut short while read; the
  /// page reads as zeros: see detail::MappingGuard).
  bool cut() const { return guard_ != nullptr && guard_->cut(); }

  /// Makes the bytes [0, to) safe to touch: the file still holds them (fstat; a file cut
  /// short meanwhile would raise SIGBUS there) and the pages not read in yet are read in
  /// (MADV_POPULATE_READ). Returns 0, or errno: EINVAL when this kernel cannot populate
  /// (before Linux 5.14), EFAULT when the file is now shorter than `to`, else the read error.
  int Prepare(std::size_t to) {
    if (base_ == nullptr) return EINVAL;
#ifdef MADV_POPULATE_READ
    struct stat st {};
    if (::fstat(fd_, &st) != 0) return errno;
    if (static_cast<std::size_t>(st.st_size) < to) return EFAULT;
    if (to <= populated_) return 0;
    const std::size_t begin = populated_ / Page() * Page();
    if (::madvise(base_ + begin, to - begin, MADV_POPULATE_READ) != 0) return errno;
    populated_ = to;
    return 0;
#else
    (void)to;
    return EINVAL;
#endif
  }

  /// Drops the whole pages before byte `up_to` from this process's memory, every kDropStep
  /// bytes (the page cache keeps them; the parser never goes back).
  void DropBefore(std::size_t up_to) {
    if (up_to < dropped_ + kDropStep) return;
    const std::size_t end = up_to / Page() * Page();
    ::madvise(base_ + dropped_, end - dropped_, MADV_DONTNEED);  // errors ignored: memory only
    dropped_ = end;
  }

 private:
  static std::size_t Page() { return static_cast<std::size_t>(::sysconf(_SC_PAGESIZE)); }

  int fd_ = -1;                ///< the file, open while this lives
  std::uint8_t* base_ = nullptr;
  std::size_t size_ = 0;
  std::size_t populated_ = 0;  ///< bytes up to this one, from the first read, were read in
  std::size_t dropped_ = 0;    ///< pages before this byte were dropped
  std::unique_ptr<detail::MappingGuard> guard_;  ///< turns a cut's SIGBUS into cut()
};

/// ReadForward over a mapped file (see ForwardMapping): each call gets `span` bytes of the
/// mapping from the offset the last one returned (the first from `from`), as the read(2) loop
/// would hand them.
void ConsumeMapped(ForwardMapping& map, std::size_t size, std::size_t span, std::size_t from,
                   const std::string& path, const ForwardConsumer& consume) {
  std::size_t at = from;  // file offset of the next call's first byte
  while (true) {
    const std::size_t n = std::min(span, size - at);
    if (const int error = map.Prepare(at + n); error != 0) {
      if (error == EFAULT) throw detail::CutShortError(path, size);
      throw InputError(path, "byte " + std::to_string(at),
                       std::string("read failed before the end of the file: ") +
                           std::strerror(error));
    }
    const bool at_end = at + n >= size;
    std::size_t next = 0;
    try {
      next = consume(map.data() + at, n, at, at_end);
    } catch (const Error&) {
      if (map.cut()) throw detail::CutShortError(path, size);  // the zeros may have caused it
      throw;
    }
    if (map.cut()) throw detail::CutShortError(path, size);
    if (at_end || next == kStopReading) return;
    if (next < at) throw Error("ReadForward: the parser of " + path + " went backwards");
    if (next == at) {  // nothing consumed from a full span: hand over more
      span *= 2;
      continue;
    }
    at = std::min(next, size);  // at the end: one more call, with no bytes and at_end
    map.DropBefore(at);
  }
}

}  // namespace

std::size_t HugePageCapacity(std::size_t n, std::size_t element_size) {
  const std::size_t bytes = n * element_size;
  if (element_size == 0 || bytes < kHugePage) return n;
  const std::size_t whole = (bytes + kAllocatorSlack + kHugePage - 1) / kHugePage * kHugePage;
  return std::max(n, (whole - kAllocatorSlack) / element_size);
}

void AdviseHugePages(const void* p, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr std::uintptr_t kHuge = kHugePage;  // as an address step
  const auto begin = reinterpret_cast<std::uintptr_t>(p);
  // The 2 MiB pages inside the buffer, and those it fills but for its allocator's bookkeeping
  // (kAllocatorSlack bytes at either end: a buffer reserved by ReserveHugePages).
  const std::uintptr_t first = (begin - std::min<std::uintptr_t>(begin, kAllocatorSlack) +
                                kHuge - 1) / kHuge * kHuge;
  const std::uintptr_t last = (begin + bytes + kAllocatorSlack) / kHuge * kHuge;
  if (last <= first) return;
  ::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);  // a hint: errors ignored
#ifdef MADV_COLLAPSE
  // The allocator wrote its header into the first page already, so that page's 2 MiB would
  // fill by 4 KiB faults: made one huge page now (Linux 6.1 on; errors ignored).
  if (first < begin && HugePagesAllowed()) {
    ::madvise(reinterpret_cast<void*>(first), kHuge, MADV_COLLAPSE);
  }
#endif
#else
  (void)p;
  (void)bytes;
#endif
}

namespace {

template <typename T>
std::vector<T> CopyVector(const std::vector<T>& v) {
  std::vector<T> out;
  ReserveHugePages(out, v.size());
  out.assign(v.begin(), v.end());
  return out;
}

}  // namespace

ImuSeries CopySeries(const ImuSeries& s) {
  ImuSeries out;
  out.t_s = CopyVector(s.t_s);
  out.acc = CopyVector(s.acc);
  out.gyr = CopyVector(s.gyr);
  out.temp_c = CopyVector(s.temp_c);
  out.acc_unit = s.acc_unit;
  out.gyr_unit = s.gyr_unit;
  return out;
}

LeftOutTimes KeepIncreasingTimes(ImuSeries& s) {
  LeftOutTimes out;
  const std::size_t n = s.size();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = s.t_s[i];
    const bool keep = std::isfinite(t) && (kept == 0 || t > s.t_s[kept - 1]) &&
                      (i + 1 == n || t < s.t_s[i + 1]);
    if (!keep) {
      if (out.count++ == 0) out.first_t_s = t;
      continue;
    }
    if (kept != i) {
      s.t_s[kept] = t;
      s.acc[kept] = s.acc[i];
      if (s.has_gyro()) s.gyr[kept] = s.gyr[i];
      if (s.has_temperature()) s.temp_c[kept] = s.temp_c[i];
    }
    ++kept;
  }
  s.t_s.resize(kept);
  s.acc.resize(kept);
  if (!s.gyr.empty()) s.gyr.resize(kept);
  if (!s.temp_c.empty()) s.temp_c.resize(kept);
  return out;
}

ImuSeries WindowOf(const ImuSeries& all, const FlightLogSelection& selection) {
  ImuSeries out;
  out.acc_unit = all.acc_unit;
  out.gyr_unit = all.gyr_unit;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const double t = all.t_s[i];
    if (selection.from_s && t < *selection.from_s) continue;
    if (selection.to_s && t > *selection.to_s) continue;
    out.t_s.push_back(t);
    out.acc.push_back(all.acc[i]);
    if (all.has_gyro()) out.gyr.push_back(all.gyr[i]);
    if (all.has_temperature()) out.temp_c.push_back(all.temp_c[i]);
  }
  return out;
}

ImuStreamInfo StreamInfoOf(const ImuSeries& s, const LeftOutTimes& left_out) {
  ImuStreamInfo info;
  info.samples = s.size();
  info.records = s.size() + left_out.count;
  info.first_left_out_t_s = left_out.first_t_s;
  if (!s.empty()) {
    info.t_start_s = s.t_s.front();
    info.t_end_s = s.t_s.back();
  }
  const double span = info.t_end_s - info.t_start_s;
  if (s.size() >= 2 && span > 0.0) info.rate_hz = static_cast<double>(s.size() - 1) / span;
  info.has_accel = true;
  info.has_gyro = s.has_gyro();
  return info;
}

std::optional<std::string> DroppedRecordsWarning(const ImuStreamInfo& info) {
  const std::optional<double>& first_t_s = info.first_left_out_t_s;
  if (info.records <= info.samples) return std::nullopt;
  return info.name + " of IMU instance " + std::to_string(info.instance) + ": left out " +
         std::to_string(info.records - info.samples) + " of " + std::to_string(info.records) +
         " records by their time (not finite, not above the last kept one, or a spike above "
         "the next record's: a corrupt or backwards time stamp)" +
         (first_t_s ? "; the first with time " + LeftOutTimeText(*first_t_s) : std::string());
}

std::string LeftOutTimeText(double t_s) {
  return std::isfinite(t_s) ? FixedText(t_s, 6) + " s" : std::string("not a number");
}

std::size_t RegularFileSize(const std::string& path) {
  struct stat st {};
  if (::stat(OpenPath(path).c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return 0;
  return static_cast<std::size_t>(st.st_size);
}

void ReadForward(const std::string& path, const std::string& what, std::size_t lookahead,
                 const ForwardConsumer& consume, std::size_t from) {
  const int fd = ::open(OpenPath(path).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    throw InputError(path, "byte 0",
                     "cannot open the " + what + " for reading: " + std::strerror(errno));
  }
  const FdCloser closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    // A pipe or special file: read it whole (LogFile does), then parse it in one call.
    const LogFile whole(path, what);
    consume(whole.data(), whole.size(), 0, true);
    return;
  }
  ::posix_fadvise(fd, 0, 0, POSIX_FADV_SEQUENTIAL);
  const auto size = static_cast<std::size_t>(st.st_size);
  from = std::min(from, size);
  if (ForwardMapping map(fd, size, from);
      map.Prepare(std::min(size, from + lookahead + kMapSpan)) == 0) {
    ConsumeMapped(map, size, lookahead + kMapSpan, from, path, consume);
    return;
  }
  std::size_t capacity = lookahead + kReadChunk;
  // Not mappable, or no MADV_POPULATE_READ to read a mapping safely: read(2) into a buffer.
  std::vector<std::uint8_t> buffer(capacity);
  std::size_t base = from;  // file offset of buffer[0]
  std::size_t have = 0;  // bytes of the file in buffer
  while (true) {
    const std::size_t want = std::min(capacity - have, size - std::min(size, base + have));
    const std::size_t got = ReadAt(fd, buffer.data() + have, want, base + have, path);
    have += got;
    const bool at_end = got < want || base + have >= size;
    const std::size_t next = consume(buffer.data(), have, base, at_end);
    if (at_end || next == kStopReading) return;
    if (next < base) throw Error("ReadForward: the parser of " + path + " went backwards");
    if (next == base && have == capacity) {  // nothing consumed from a full buffer: grow it
      capacity *= 2;
      buffer.resize(capacity);
      continue;
    }
    if (next < base + have) {
      have = base + have - next;
      std::memmove(buffer.data(), buffer.data() + (next - base), have);
    } else {
      have = 0;
    }
    base = std::min(next, size);
  }
}

RecordStore::RecordStore(std::size_t body_size) : body_size_(body_size) {
  while (shift_ < 30 && (std::size_t{2} << shift_) * std::max<std::size_t>(body_size, 1) <=
                            kBlockBytes) {
    ++shift_;
  }
  mask_ = (std::size_t{1} << shift_) - 1;
}

RecordStore::RecordStore(const RecordStore& other)
    : body_size_(other.body_size_), shift_(other.shift_), mask_(other.mask_) {
  for (std::size_t r = 0; r < other.rows_; ++r) Append(other.Row(r));
}

RecordStore& RecordStore::operator=(const RecordStore& other) {
  if (this != &other) *this = RecordStore(other);
  return *this;
}

bool RecordStore::operator==(const RecordStore& other) const {
  if (rows_ != other.rows_ || body_size_ != other.body_size_) return false;
  for (std::size_t r = 0; r < rows_; ++r) {
    if (std::memcmp(Row(r), other.Row(r), body_size_) != 0) return false;
  }
  return true;
}

void RecordStore::AddBlock() {
  // Whole huge pages: the rows' bytes rounded up to kBlockBytes (the tail is never written).
  const std::size_t rows_bytes = std::max<std::size_t>((mask_ + 1) * body_size_, 1);
  const std::size_t bytes = (rows_bytes + kBlockBytes - 1) / kBlockBytes * kBlockBytes;
  auto* block = static_cast<std::uint8_t*>(
      ::operator new(bytes, std::align_val_t{kBlockBytes}));
  blocks_.emplace_back(block);
  if (blocks_.size() > 1) AdviseHugePages(block, bytes);
}

void RecordStore::FreeBlock::operator()(std::uint8_t* p) const {
  ::operator delete(p, std::align_val_t{kBlockBytes});
}

LogFile::~LogFile() {
  guard_.reset();  // before the range can be mapped again by anything else
  if (mapping_ != nullptr) ::munmap(mapping_, size_);
}

std::optional<SiteInput> MedianSite(std::vector<double> lat_deg, std::vector<double> lon_deg,
                                    std::vector<double> height_m) {
  if (lat_deg.empty() || lon_deg.size() != lat_deg.size() ||
      height_m.size() != lat_deg.size()) {
    return std::nullopt;
  }
  SiteInput site;
  site.lat_deg = Median(std::move(lat_deg));
  site.lon_deg = Median(std::move(lon_deg));
  site.height_m = Median(std::move(height_m));
  site.source = "gps";
  return site;
}

std::string EmptyWindowMessage(const std::optional<double>& from_s,
                               const std::optional<double>& to_s, double t_start_s,
                               double t_end_s) {
  const auto at = [](const std::optional<double>& t, const char* open) {
    return t ? Number(*t) + " s" : std::string(open);
  };
  return "fewer than 2 samples in the time window " + at(from_s, "start") + " .. " +
         at(to_s, "end") + "; the stream spans " + Number(t_start_s) + " .. " +
         Number(t_end_s) + " s (log times, as plumb info shows them)";
}

}  // namespace plumb::io

namespace plumb::io {

std::vector<LogMotion> GpsMotion(std::vector<GpsVelocity> reports, const std::string& source) {
  std::stable_sort(reports.begin(), reports.end(),
                   [](const GpsVelocity& a, const GpsVelocity& b) { return a.t_s < b.t_s; });
  std::vector<LogMotion> out;
  const auto moving = [](const GpsVelocity& r) {
    return r.fix_3d && std::isfinite(r.ground_speed_m_s) && std::isfinite(r.climb_m_s) &&
           (r.ground_speed_m_s > kGpsMovingSpeed || std::abs(r.climb_m_s) > kGpsMovingSpeed);
  };
  std::size_t i = 0;
  while (i < reports.size()) {
    if (!moving(reports[i])) {
      ++i;
      continue;
    }
    std::size_t end = i + 1;  // one past the run of moving reports
    while (end < reports.size() && moving(reports[end])) ++end;
    if (end - i >= 2) {
      LogMotion m;
      m.evidence = LogMotion::Evidence::kGpsMoving;
      m.source = source;
      m.t_begin_s = reports[i].t_s;
      m.t_end_s = reports[end - 1].t_s;
      for (std::size_t k = i; k < end; ++k) {
        m.max_ground_speed_m_s = std::max(m.max_ground_speed_m_s, reports[k].ground_speed_m_s);
        m.max_climb_m_s = std::max(m.max_climb_m_s, std::abs(reports[k].climb_m_s));
        if (k > i) {
          m.ground_distance_m += 0.5 * (reports[k].ground_speed_m_s +
                                        reports[k - 1].ground_speed_m_s) *
                                 (reports[k].t_s - reports[k - 1].t_s);
        }
      }
      if (!out.empty() && m.t_begin_s - out.back().t_end_s < kGpsRunGap_s) {
        LogMotion& last = out.back();
        last.t_end_s = m.t_end_s;
        last.max_ground_speed_m_s = std::max(last.max_ground_speed_m_s, m.max_ground_speed_m_s);
        last.max_climb_m_s = std::max(last.max_climb_m_s, m.max_climb_m_s);
        last.ground_distance_m += m.ground_distance_m;
      } else {
        out.push_back(m);
      }
    }
    i = end;
  }
  return out;
}

std::vector<LogMotion> AirborneIntervals(std::vector<LandedState> events, double t_end_s,
                                         const std::string& source) {
  std::stable_sort(events.begin(), events.end(),
                   [](const LandedState& a, const LandedState& b) { return a.t_s < b.t_s; });
  std::vector<LogMotion> out;
  std::optional<double> since;   // airborne from here
  std::string since_what;
  for (const LandedState& e : events) {
    if (e.airborne && !since) {
      since = e.t_s;
      since_what = e.what;
    } else if (!e.airborne && since) {
      out.push_back({*since, std::max(*since, e.t_s), LogMotion::Evidence::kAirborne,
                     source + " " + since_what + " .. " + e.what});
      since.reset();
    }
  }
  if (since) {
    out.push_back({*since, std::max(*since, t_end_s), LogMotion::Evidence::kAirborne,
                   source + " " + since_what + " .. the log's end"});
  }
  return out;
}

}  // namespace plumb::io

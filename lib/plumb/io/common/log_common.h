// plumb/io/common/log_common.h — pieces every flight-log reader shares: reading the file forward
// in chunks (ReadForward; the DataFlash and ULog readers) or whole (LogFile; the tlog reader,
// whose resync search looks ahead without bound), storing record bodies (RecordStore),
// counting skipped bytes, saturating float conversion, and the site from a log's GPS fixes.
#pragma once

#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "plumb/core/log_motion.h"
#include "plumb/core/session.h"
#include "plumb/core/types.h"
#include "plumb/io/common/flight_log.h"
#include "plumb/io/common/mapping_guard.h"

namespace plumb::io {

/// The whole file at `path`, read-only in memory: mapped (mmap, read ahead sequentially) when
/// the system can, else read into a buffer. `what` names the format in errors ("DataFlash
/// log", "ULog file", ...). The constructor throws plumb::InputError(path, "byte N", ...) when
/// the file cannot be opened, sized or read to its end. A mapping is guarded
/// (detail::MappingGuard): should the file be cut short while it is read, the pages past its
/// new end read as zeros instead of raising SIGBUS, and ThrowIfCut says so. Not copyable.
class LogFile {
 public:
  LogFile(const std::string& path, const std::string& what);
  ~LogFile();
  LogFile(const LogFile&) = delete;
  LogFile& operator=(const LogFile&) = delete;

  const std::uint8_t* data() const { return data_; }
  std::size_t size() const { return size_; }

  /// Throws detail::CutShortError when the mapped file was found cut short (or replaced)
  /// after it was opened: what was parsed from it is not the file. A reader calls it after
  /// its parse, and before reporting an error the parse met (the zeros may have caused it).
  void ThrowIfCut() const;

  /// Says a parser is done with the bytes [from, up_to) for now, so that a mapped file does
  /// not stay resident as it is read: the whole pages inside them are dropped from this
  /// process's memory (madvise MADV_DONTNEED; the mapping is read-only, so reading them again
  /// re-reads the same bytes from the file, slower but identical). A parser calls it every
  /// kReleaseStep bytes or so, with `from` where its last call ended; parsers going through
  /// disjoint ranges at once (a two-part read) may each call it. No-op for a file read into a
  /// buffer.
  void Release(std::size_t from, std::size_t up_to) const;

  /// Bytes a parser reads between two calls of Release (32 MiB).
  static constexpr std::size_t kReleaseStep = std::size_t{32} << 20;

 private:
  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
  std::string path_;                    ///< the file, for errors
  void* mapping_ = nullptr;             ///< the mmap'ed region, or nullptr
  std::unique_ptr<detail::MappingGuard> guard_;  ///< guards mapping_ against a cut
  std::vector<std::uint8_t> buffer_;    ///< the bytes when not mapped
};

/// The value of type T stored at `p` little endian, as every log format plumb reads stores it
/// (on every supported host, little endian too: a plain copy). The one load of the readers.
template <typename T>
T LoadLittleEndian(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

/// What ReadForward hands the bytes to: consume(data, n, offset, at_end), returning the offset
/// it needs the bytes from next (see ReadForward).
using ForwardConsumer = std::function<std::size_t(const std::uint8_t* data, std::size_t n,
                                                 std::size_t offset, bool at_end)>;

/// Reads the file at `path` forward, span by span, for parsers that decide at each position
/// from a bounded look-ahead. A regular file is mapped read-only and each span's pages are
/// read in (madvise MADV_POPULATE_READ) just before the parser gets them (4 MiB at a time),
/// so that a read error, or a file found cut short before a span, is an InputError rather
/// than the SIGBUS touching such a page raises (a cut while the parser is inside a span can
/// still raise one); the pages the parser has passed are dropped from this process's memory
/// every 2 MiB (never held whole, no copy of the page cache). Without MADV_POPULATE_READ
/// (Linux before 5.14), or when the file cannot be mapped, it is read with read(2) into one
/// reusable buffer the same way (256 KiB at a time).
/// `consume(data, n, offset, at_end)` gets the bytes [offset, offset + n)
/// of the file (`at_end`: they reach its end) and returns the file offset it needs the bytes
/// from next, in [offset, offset + n] or beyond (a forward jump: the bytes in between are not
/// read). The bytes from that offset to offset + n are passed again at the start of the next
/// call, followed by the next chunk; a parser returns a position `lookahead` bytes or more
/// before the end of its data unless `at_end`. Reading stops after the call with `at_end` (or
/// when the returned offset is the file size or beyond); a call returning kStopReading ends
/// the reading at once (a parser that reads part of a file). `what` names the format in
/// errors: throws plumb::InputError(path, "byte N", ...) when the file cannot be opened or
/// read. A file that is not a regular file (a pipe) is read whole first. `from`: the file
/// offset of the first call's first byte (0: from the start); the bytes before it are not read
/// (a regular file only: a pipe is read whole and handed over from its start).
void ReadForward(const std::string& path, const std::string& what, std::size_t lookahead,
                 const ForwardConsumer& consume, std::size_t from = 0);

/// What a ReadForward consumer returns to stop the reading there.
inline constexpr std::size_t kStopReading = std::numeric_limits<std::size_t>::max();

/// Asks the system to back the memory [p, p + bytes) of a large buffer that is about to be
/// filled by transparent huge pages (madvise MADV_HUGEPAGE on the whole 2 MiB pages inside it,
/// and on those it fills but for 64 bytes of its allocator's bookkeeping, the first of which is
/// made a huge page at once with MADV_COLLAPSE unless the system's mode is "never"; nothing when
/// it spans none or the system has no such pages): one page fault per 2 MiB instead of per
/// 4 KiB as the buffer is first written. Only a hint: the contents and the results never
/// depend on it.
void AdviseHugePages(const void* p, std::size_t bytes);

/// Capacity for `n` elements of size `element_size`, rounded up so that a buffer of 2 MiB or
/// more, with its allocator's bookkeeping (64 bytes at most), fills whole 2 MiB pages: Linux
/// then places such a mapping on a 2 MiB boundary, and every page of the buffer, its first
/// included, can be a huge page (AdviseHugePages).
std::size_t HugePageCapacity(std::size_t n, std::size_t element_size);

/// Reserves at least `n` elements of `v` (HugePageCapacity) and asks for huge pages on them
/// (AdviseHugePages): a buffer about to be filled, with one page fault per 2 MiB.
template <typename T>
void ReserveHugePages(std::vector<T>& v, std::size_t n) {
  v.reserve(HugePageCapacity(n, sizeof(T)));
  AdviseHugePages(v.data(), v.capacity() * sizeof(T));
}

/// A copy of `s` whose large buffers are reserved first and backed by huge pages
/// (AdviseHugePages): samples a reader decoded in its pass, handed out by value.
ImuSeries CopySeries(const ImuSeries& s);

/// The first sample KeepIncreasingTimes left out, and how many it did.
struct LeftOutTimes {
  std::size_t count = 0;           ///< samples left out
  std::optional<double> first_t_s; ///< the first one's time as read, s (NaN for a bad stamp)
};

/// Keeps the samples of `s` (in record order, every record with its time as read) whose time
/// is finite, above the last kept one and below the next record's: a time above the next
/// record's is a corrupt spike (one ULog stamp of 5e12 s hid 17013 of 17070 samples when
/// only "above the last kept" was asked), so one bad stamp costs one sample. The rule of
/// ImuFromDataflash. Returns what was left out.
LeftOutTimes KeepIncreasingTimes(ImuSeries& s);

/// An IMU stream's counts, first and last times and rate from its samples `s` and what
/// KeepIncreasingTimes left out of them (records = samples + left out); the reader fills in
/// the name, the instance, a temperature and what the firmware applied.
ImuStreamInfo StreamInfoOf(const ImuSeries& s, const LeftOutTimes& left_out);

/// The samples of `all` within the selection's [from_s, to_s] (each bound optional), with
/// their gyroscope, temperature and units: the session a reader hands out.
ImuSeries WindowOf(const ImuSeries& all, const FlightLogSelection& selection);

/// A left-out record's time as warnings say it: "5000000000000.000000 s", or "not a number".
std::string LeftOutTimeText(double t_s);

/// The size of the file at `path` in bytes (0 when it is not a regular file or cannot be
/// read).
std::size_t RegularFileSize(const std::string& path);

/// The record bodies of one message (DataFlash type, ULog topic), in log order: rows of
/// `body_size` bytes each, exactly as in the file, in blocks of a power-of-two number of rows
/// (about kBlockBytes each), so that appending never moves the rows already stored (no
/// counting pass to size the storage, no reallocation copy; the last block's unused rows are
/// never written, so they cost address space, not resident memory). Blocks are aligned on
/// kBlockBytes; from the second block of a store on (a message with many records), they are
/// backed by huge pages (AdviseHugePages: one page fault per block instead of one per 4 KiB).
class RecordStore {
 public:
  /// Bytes per block, about (a block holds at least one row): 2 MiB, a huge page.
  static constexpr std::size_t kBlockBytes = std::size_t{2} << 20;

  RecordStore() = default;
  explicit RecordStore(std::size_t body_size);
  RecordStore(const RecordStore& other);
  RecordStore& operator=(const RecordStore& other);
  RecordStore(RecordStore&&) noexcept = default;
  RecordStore& operator=(RecordStore&&) noexcept = default;

  /// Appends one row: body_size() bytes from `body`.
  void Append(const std::uint8_t* body) {
    if ((rows_ & mask_) == 0 && (rows_ >> shift_) == blocks_.size()) AddBlock();
    std::memcpy(MutableRow(rows_), body, body_size_);
    ++rows_;
  }
  /// Appends every row of `other` (the same body_size()), in order.
  void Append(const RecordStore& other) {
    for (std::size_t r = 0; r < other.rows(); ++r) Append(other.Row(r));
  }
  /// The bytes of row `r` (< rows()).
  const std::uint8_t* Row(std::size_t r) const {
    return blocks_[r >> shift_].get() + (r & mask_) * body_size_;
  }
  std::size_t rows() const { return rows_; }
  std::size_t body_size() const { return body_size_; }
  /// rows() * body_size(): the bytes stored.
  std::size_t size() const { return rows_ * body_size_; }
  /// True when both hold the same rows (sizes and bytes).
  bool operator==(const RecordStore& other) const;

 private:
  std::uint8_t* MutableRow(std::size_t r) {
    return blocks_[r >> shift_].get() + (r & mask_) * body_size_;
  }
  void AddBlock();

  /// Frees a block (allocated aligned on kBlockBytes).
  struct FreeBlock {
    void operator()(std::uint8_t* p) const;
  };

  std::size_t body_size_ = 0;
  std::size_t rows_ = 0;
  unsigned shift_ = 0;      ///< rows per block = 1 << shift_
  std::size_t mask_ = 0;    ///< (1 << shift_) - 1
  std::vector<std::unique_ptr<std::uint8_t[], FreeBlock>> blocks_;
};

/// Which messages (DataFlash types, ULog topics) a binary-log reader keeps the record bodies
/// of: every record is still read, checked and counted (rows, skipped bytes, warnings), but
/// only the bodies of kept messages are stored. Sessions need a few messages of a log (its IMU,
/// parameters, GPS); keeping only those bounds a big log's memory by its IMU samples instead
/// of its size. Default: every message is kept.
struct RecordFilter {
  /// True for the names whose bodies are stored; empty: all.
  std::function<bool(std::string_view name)> keep;
  /// True for the IMU messages whose samples the reader decodes inside its pass, while each
  /// record is in the cache, keeping the decoded samples instead of the bodies (the format's
  /// reader says which messages it can decode so, and what it keeps of them; a message it
  /// cannot decode keeps its bodies when `keep` says so). Empty: none, bodies only.
  std::function<bool(std::string_view name)> decode;

  bool Keeps(std::string_view name) const { return !keep || keep(name); }
  bool Decodes(std::string_view name) const { return decode && decode(name); }
};

/// The message of a time window (FlightLogSelection::from_s/to_s, log times) that holds fewer than 2 samples of a
/// stream spanning [t_start_s, t_end_s]: both in log times, as `plumb info` shows them.
std::string EmptyWindowMessage(const std::optional<double>& from_s,
                               const std::optional<double>& to_s, double t_start_s,
                               double t_end_s);

/// Counts the bytes [from, to) as skipped in a reader's warnings `w` (any struct with
/// bytes_skipped, skip_runs and first_skip_offset): a new run unless `from` is `skip_end`, the
/// end of the previous skipped range, which is then moved to `to` (from <= to).
template <typename Warnings>
void CountSkipped(Warnings& w, std::size_t from, std::size_t to, std::size_t& skip_end) {
  if (w.bytes_skipped == 0) w.first_skip_offset = from;
  if (w.bytes_skipped == 0 || from != skip_end) ++w.skip_runs;
  w.bytes_skipped += to - from;
  skip_end = to;
}

/// double -> float with values beyond the float range as +-infinity (a plain cast is undefined
/// there); NaN stays NaN.
inline float SaturatedFloat(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::infinity();
  if (v < -kMax) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(v);
}

/// The same per component.
inline Vec3f SaturatedFloat(const Vec3& v) {
  return Vec3f(SaturatedFloat(v.x()), SaturatedFloat(v.y()), SaturatedFloat(v.z()));
}

/// The site from a log's GPS fixes with a 3D fix: the median latitude (deg, [-90, 90]),
/// longitude (deg, [-180, 180]) and height (m; logs give the altitude above mean sea level,
/// used as the height: the geoid separation, tens of metres, changes gravity by about 1e-5
/// relative), source "gps". The three vectors have one entry per fix. nullopt when empty.
std::optional<SiteInput> MedianSite(std::vector<double> lat_deg, std::vector<double> lon_deg,
                                    std::vector<double> height_m);

/// One GPS velocity report as a log gives it, time on the samples' clock.
struct GpsVelocity {
  double t_s = 0.0;               ///< s
  bool fix_3d = false;            ///< a 3D fix (or better): the speed means something
  double ground_speed_m_s = 0.0;  ///< horizontal speed, m/s, >= 0
  double climb_m_s = 0.0;         ///< vertical speed, m/s (either sign; 0 where not given)
};

/// The intervals during which `reports` (any order; taken in time order) show the vehicle
/// moving: runs of at
/// least two reports in a row with a 3D fix and a ground speed or climb magnitude above
/// kGpsMovingSpeed, from the first such report to the last, runs less than kGpsRunGap_s apart
/// joined. `source` names the message ("GPS", "vehicle_gps_position", "GPS_RAW_INT").
std::vector<LogMotion> GpsMotion(std::vector<GpsVelocity> reports, const std::string& source);

/// Runs of moving GPS reports closer than this, s, are one interval (a copter's hover between
/// legs, a report or two under the threshold).
inline constexpr double kGpsRunGap_s = 2.0;

/// A land detector's state as a log records it: at t_s the vehicle is (or stops being)
/// airborne.
struct LandedState {
  double t_s = 0.0;       ///< s, on the samples' clock
  bool airborne = false;  ///< not landed from here on
  std::string what;       ///< the event's name in the log ("NOT_LANDED", "LAND_COMPLETE", ...)
};

/// The airborne intervals of `events` (any order; taken in time order): from an event saying
/// airborne to the next saying
/// landed, or to `t_end_s` (the log's last time) when none follows. Before the first event
/// the state is not known and taken as landed: a land detector that publishes on change
/// (PX4) or logs events (ArduPilot) says "landed" first in a log that starts on the ground.
/// `source` names the message ("EV", "vehicle_land_detected").
std::vector<LogMotion> AirborneIntervals(std::vector<LandedState> events, double t_end_s,
                                         const std::string& source);

}  // namespace plumb::io

// plumb/io/common/log_common.h — pieces every flight-log reader shares: reading the whole file,
// counting skipped bytes, saturating float conversion, and the site from a log's GPS fixes.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "plumb/core/session.h"
#include "plumb/core/types.h"

namespace plumb::io {

/// The whole file at `path`, read-only in memory: mapped (mmap, read ahead sequentially) when
/// the system can, else read into a buffer. `what` names the format in errors ("DataFlash
/// log", "ULog file", ...). The constructor throws plumb::InputError(path, "byte N", ...) when
/// the file cannot be opened, sized or read to its end. Not copyable.
class LogFile {
 public:
  LogFile(const std::string& path, const std::string& what);
  ~LogFile();
  LogFile(const LogFile&) = delete;
  LogFile& operator=(const LogFile&) = delete;

  const std::uint8_t* data() const { return data_; }
  std::size_t size() const { return size_; }

  /// Says the parser is done with the bytes [0, up_to) for now, so that a mapped file does not
  /// stay resident as it is read: every kReleaseStep bytes, the whole pages before `up_to`
  /// are dropped from this process's memory (madvise MADV_DONTNEED; the mapping is read-only,
  /// so reading them again re-reads the same bytes from the file, slower but identical).
  /// Cheap when called per record. An `up_to` below the last one starts over (a new pass, or
  /// a jump back). No-op for a file read into a buffer.
  void Release(std::size_t up_to) const {
    if (mapping_ == nullptr) return;
    if (up_to < released_) released_ = 0;
    if (up_to >= released_ + kReleaseStep) DropPages(up_to);
  }

  /// Bytes between two actual releases (32 MiB).
  static constexpr std::size_t kReleaseStep = std::size_t{32} << 20;

 private:
  void DropPages(std::size_t up_to) const;

  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
  void* mapping_ = nullptr;             ///< the mmap'ed region, or nullptr
  std::vector<std::uint8_t> buffer_;    ///< the bytes when not mapped
  mutable std::size_t released_ = 0;    ///< bytes [0, released_) were last released
};

/// Which messages (DataFlash types, ULog topics) a binary-log reader keeps the record bodies
/// of: every record is still read, checked and counted (rows, skipped bytes, warnings), but
/// only the bodies of kept messages are stored. Sessions need a few messages of a log (its IMU,
/// parameters, GPS); keeping only those bounds a big log's memory by its IMU samples instead
/// of its size. Default: every message is kept.
struct RecordFilter {
  /// True for the names whose bodies are stored; empty: all.
  std::function<bool(std::string_view name)> keep;

  bool Keeps(std::string_view name) const { return !keep || keep(name); }
};

/// The message of a time window (--from/--to, log times) that holds fewer than 2 samples of a
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

}  // namespace plumb::io

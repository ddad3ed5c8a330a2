// plumb/io/mavlink/mavlink_tlog.cc — see mavlink_tlog.h for the format and the decoding contract.
#include "plumb/io/mavlink/mavlink_tlog.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/io/common/log_common.h"

namespace plumb::io {
namespace {

constexpr std::uint8_t kStxV1 = 0xFE;
constexpr std::uint8_t kStxV2 = 0xFD;
constexpr std::size_t kTimeBytes = 8;        // big-endian uint64 µs before every frame
constexpr std::size_t kHeaderV1 = 6;         // STX len seq sys comp msgid
constexpr std::size_t kHeaderV2 = 10;        // STX len incompat compat seq sys comp msgid[3]
constexpr std::size_t kCrcBytes = 2;
constexpr std::size_t kSignatureBytes = 13;
constexpr std::uint8_t kIncompatSigned = 0x01;
// Plausible tlog times: 2000-01-01 and 2100-01-01 in µs since the unix epoch.
constexpr std::uint64_t kMinTimeUs = 946684800ull * 1000000ull;
constexpr std::uint64_t kMaxTimeUs = 4102444800ull * 1000000ull;
constexpr std::size_t kMaxPayload = 255;

/// One row of the generated table (mavlink_messages.inc, see MavlinkMessageInfo).
struct MavlinkMessageInfoRow {
  std::uint32_t id;
  const char* name;
  std::uint8_t crc_extra;
  std::uint8_t min_length;
  std::uint8_t max_length;
  std::uint8_t dialect;  // index into kMavlinkDialects
};

// kMavlinkDefinitions, kMavlinkDialects, kMavlinkMessages (sorted by id): generated at build
// time by scripts/gen-mavlink-dialect (lib/plumb/io/mavlink/CMakeLists.txt).
#include "mavlink_messages.inc"

constexpr std::size_t kMessageCount = sizeof(kMavlinkMessages) / sizeof(kMavlinkMessages[0]);

/// The row of `msgid`, or nullptr (binary search: the table is sorted by id).
constexpr const MavlinkMessageInfoRow* FindRow(std::uint32_t msgid) {
  std::size_t lo = 0, hi = kMessageCount;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (kMavlinkMessages[mid].id < msgid) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo < kMessageCount && kMavlinkMessages[lo].id == msgid ? &kMavlinkMessages[lo] : nullptr;
}

constexpr bool SortedById() {
  for (std::size_t k = 1; k < kMessageCount; ++k) {
    if (kMavlinkMessages[k - 1].id >= kMavlinkMessages[k].id) return false;
  }
  return true;
}
static_assert(SortedById(), "the generated MAVLink table must be sorted by id");

/// The messages Decode reads, with the full payload length its offsets assume; each must be
/// the dialect's (checked at compile time against the generated table).
struct DecodedMessage {
  std::uint32_t id;
  std::size_t full_len;
};
constexpr DecodedMessage kDecoded[] = {
    {kMavHeartbeat, 9},  {kMavParamValue, 25}, {kMavGpsRawInt, 52},  {kMavScaledImu, 24},
    {kMavRawImu, 29},    {kMavHighresImu, 63}, {kMavScaledImu2, 24}, {kMavScaledImu3, 24},
};
constexpr bool DecodedLengthsMatchTheDialect() {
  for (const DecodedMessage& d : kDecoded) {
    const MavlinkMessageInfoRow* row = FindRow(d.id);
    if (row == nullptr || row->max_length != d.full_len) return false;
  }
  return true;
}
static_assert(DecodedLengthsMatchTheDialect(),
              "a decoded message's payload length differs from the generated MAVLink table");

/// CRC-16/MCRF4XX tables (reflected polynomial 0x8408) for slicing by 8, built once.
/// t[0] is the classic byte table: crc' = (crc >> 8) ^ t[0][(crc ^ byte) & 0xFF]. t[k][v] is
/// the contribution of byte value v followed by k zero bytes, t[k][v] = (t[k-1][v] >> 8) ^
/// t[0][t[k-1][v] & 0xFF], so that 8 bytes b0..b7 advance the 16-bit state c as
///   c' = t[7][(c ^ b0) & 0xFF] ^ t[6][((c >> 8) ^ b1) & 0xFF] ^ t[5][b2] ^ ... ^ t[0][b7]
/// (the CRC is linear over GF(2); the state holds only two bytes).
struct CrcTable {
  std::array<std::array<std::uint16_t, 256>, 8> t{};
  CrcTable() {
    for (unsigned b = 0; b < 256; ++b) {
      std::uint16_t crc = static_cast<std::uint16_t>(b);
      for (int k = 0; k < 8; ++k) {
        crc = static_cast<std::uint16_t>((crc & 1u) ? (crc >> 1) ^ 0x8408u : crc >> 1);
      }
      t[0][b] = crc;
    }
    for (std::size_t k = 1; k < 8; ++k) {
      for (unsigned b = 0; b < 256; ++b) {
        const std::uint16_t prev = t[k - 1][b];
        t[k][b] = static_cast<std::uint16_t>((prev >> 8) ^ t[0][prev & 0xFFu]);
      }
    }
  }
};
const CrcTable kCrcTable;

/// One byte into the CRC state.
inline std::uint16_t CrcByte(std::uint16_t crc, std::uint8_t byte) {
  return static_cast<std::uint16_t>((crc >> 8) ^ kCrcTable.t[0][(crc ^ byte) & 0xFFu]);
}

/// X.25 CRC of `size` bytes from state `crc`, sliced by 8 (see CrcTable). Each step is one
/// link of a chain of dependent lookups, so the last 0-7 bytes go in at most three (slices of
/// 4, 2 and 1 bytes) instead of one per byte: frames are short (a RAW_IMU's CRC covers 31).
inline std::uint16_t Crc(const std::uint8_t* data, std::size_t size, std::uint16_t crc) {
  const auto& t = kCrcTable.t;
  std::size_t k = 0;
  for (; k + 8 <= size; k += 8) {
    const std::uint8_t* b = data + k;
    crc = static_cast<std::uint16_t>(
        t[7][(crc ^ b[0]) & 0xFFu] ^ t[6][((crc >> 8) ^ b[1]) & 0xFFu] ^ t[5][b[2]] ^
        t[4][b[3]] ^ t[3][b[4]] ^ t[2][b[5]] ^ t[1][b[6]] ^ t[0][b[7]]);
  }
  if (size - k >= 4) {
    const std::uint8_t* b = data + k;
    crc = static_cast<std::uint16_t>(t[3][(crc ^ b[0]) & 0xFFu] ^
                                     t[2][((crc >> 8) ^ b[1]) & 0xFFu] ^ t[1][b[2]] ^ t[0][b[3]]);
    k += 4;
  }
  if (size - k >= 2) {
    const std::uint8_t* b = data + k;
    crc = static_cast<std::uint16_t>(t[1][(crc ^ b[0]) & 0xFFu] ^
                                     t[0][((crc >> 8) ^ b[1]) & 0xFFu]);
    k += 2;
  }
  if (k < size) crc = CrcByte(crc, data[k]);
  return crc;
}

/// Per low id (< 256), for the byte-by-byte scan: CRC_EXTRA (-1 unknown) and full decoded
/// length (0 not decoded). Higher ids are looked up in the table (FindRow).
struct IdTable {
  std::array<std::int16_t, 256> crc_extra{};
  std::array<std::uint8_t, 256> full_len{};
  IdTable() {
    crc_extra.fill(-1);
    for (const MavlinkMessageInfoRow& m : kMavlinkMessages) {
      if (m.id < 256) crc_extra[m.id] = m.crc_extra;
    }
    for (const DecodedMessage& d : kDecoded) full_len[d.id] = static_cast<std::uint8_t>(d.full_len);
  }
};
const IdTable kIds;

/// CRC_EXTRA of any id, -1 when unknown.
inline int CrcExtraOf(std::uint32_t msgid) {
  if (msgid < 256) return kIds.crc_extra[msgid];
  const MavlinkMessageInfoRow* row = FindRow(msgid);
  return row ? row->crc_extra : -1;
}

std::uint64_t LoadBigEndian64(const std::uint8_t* p) {
  return __builtin_bswap64(LoadLittleEndian<std::uint64_t>(p));  // little-endian host
}

std::array<std::int16_t, 3> Int16Triad(const std::uint8_t* p) {
  return {LoadLittleEndian<std::int16_t>(p), LoadLittleEndian<std::int16_t>(p + 2),
          LoadLittleEndian<std::int16_t>(p + 4)};
}

std::array<float, 3> FloatTriad(const std::uint8_t* p) {
  return {LoadLittleEndian<float>(p), LoadLittleEndian<float>(p + 4),
          LoadLittleEndian<float>(p + 8)};
}

/// A frame located in the input.
struct Frame {
  std::size_t record_bytes = 0;  // 8-byte time + the whole frame (signature included)
  std::uint64_t time_us = 0;
  std::uint32_t msgid = 0;
  const std::uint8_t* payload = nullptr;
  std::size_t len = 0;
  std::uint8_t system_id = 0;
  std::uint8_t component_id = 0;
  bool v2 = false;
  bool is_signed = false;
};

enum class Verdict { kNotStart, kIncomplete, kCrcFailed, kChecked, kUnchecked };

bool PlausibleTime(std::uint64_t t_us) { return t_us >= kMinTimeUs && t_us < kMaxTimeUs; }

/// Whether a record can start at `pos` (pure: no side effects).
Verdict Examine(const std::uint8_t* data, std::size_t size, std::size_t pos, Frame* f) {
  const std::size_t left = size - pos;
  if (left < kTimeBytes + 1) return Verdict::kIncomplete;
  const std::uint8_t* p = data + pos;
  f->time_us = LoadBigEndian64(p);
  if (!PlausibleTime(f->time_us)) return Verdict::kNotStart;
  const std::uint8_t* frame = p + kTimeBytes;
  const std::size_t frame_left = left - kTimeBytes;
  std::size_t header = 0;
  std::size_t extra = 0;
  if (frame[0] == kStxV1) {
    header = kHeaderV1;
    if (frame_left < header) return Verdict::kIncomplete;
    f->v2 = false;
    f->is_signed = false;
    f->len = frame[1];
    f->system_id = frame[3];
    f->component_id = frame[4];
    f->msgid = frame[5];
  } else if (frame[0] == kStxV2) {
    header = kHeaderV2;
    if (frame_left < 3) return Verdict::kIncomplete;
    const std::uint8_t incompat = frame[2];
    if ((incompat & ~kIncompatSigned) != 0) return Verdict::kNotStart;
    if (frame_left < header) return Verdict::kIncomplete;
    f->v2 = true;
    f->is_signed = (incompat & kIncompatSigned) != 0;
    extra = f->is_signed ? kSignatureBytes : 0;
    f->len = frame[1];
    f->system_id = frame[5];
    f->component_id = frame[6];
    f->msgid = static_cast<std::uint32_t>(frame[7]) | (static_cast<std::uint32_t>(frame[8]) << 8) |
               (static_cast<std::uint32_t>(frame[9]) << 16);
  } else {
    return Verdict::kNotStart;
  }
  const std::size_t frame_bytes = header + f->len + kCrcBytes + extra;
  if (frame_left < frame_bytes) return Verdict::kIncomplete;
  f->record_bytes = kTimeBytes + frame_bytes;
  f->payload = frame + header;
  const int crc_extra = CrcExtraOf(f->msgid);
  if (crc_extra < 0) return Verdict::kUnchecked;
  const std::uint16_t crc = CrcByte(Crc(frame + 1, header - 1 + f->len, 0xFFFF),
                                    static_cast<std::uint8_t>(crc_extra));
  const std::uint16_t sent = LoadLittleEndian<std::uint16_t>(f->payload + f->len);
  return crc == sent ? Verdict::kChecked : Verdict::kCrcFailed;
}

/// A record of any id could start at `pos`: the end of the data, a tail too short for a
/// record header, or a plausible time followed by a start byte.
bool NextLooksLikeRecord(const std::uint8_t* data, std::size_t size, std::size_t pos) {
  return size - pos < kTimeBytes + 1 || LooksLikeTlogRecord(data + pos, size - pos);
}

/// The one-pass decoder. What it does at a position depends only on the bytes from there on
/// (Examine, NextLooksLikeRecord, FindRecord look ahead, never back) and on whether a record
/// ended there, so a parser started at a record another one accepts goes on exactly as that one
/// would: the read in parts (ReadInParts) rests on it.
class Parser {
 public:
  /// Decodes `data` (`size` bytes) into `log`. `file`: the mapped file `data` is, told what has
  /// been read (LogFile::Release) from byte `from` on, or nullptr.
  Parser(const std::uint8_t* data, std::size_t size, MavlinkLog* log, const LogFile* file,
         std::size_t from = 0)
      : data_(data), size_(size), log_(log), file_(file), released_(from), last_end_(from) {
    low_counts_.fill(0);
  }

  /// Decodes the records starting in [from, until); returns the position reached: `until` when
  /// a record ends there (or a skipped byte does), past it when a record starting before it
  /// runs on, size_ when the data end. Called again with what it returned, it goes on.
  std::size_t Run(std::size_t from, std::size_t until) {
    std::size_t pos = from;
    Frame f;
    while (pos < until) {
      if (file_ != nullptr && pos >= released_ + LogFile::kReleaseStep) {
        file_->Release(released_, pos);
        released_ = pos;
      }
      const Verdict v = Examine(data_, size_, pos, &f);
      if (Accepted(v, f, pos)) {
        Accept(f, v == Verdict::kChecked);
        pos += f.record_bytes;
        last_end_ = pos;
        continue;
      }
      if (v == Verdict::kCrcFailed) {
        MavlinkWarnings& w = log_->warnings;
        if (w.crc_failures == 0) w.first_crc_failure_offset = pos;
        ++w.crc_failures;
      }
      if (v == Verdict::kIncomplete) {
        if (size_ - pos < kTimeBytes + 1 && pos != last_end_) {
          SkipTo(pos, size_);
          return size_;
        }
        const std::size_t next = FindRecord(pos + 1);
        if (next == size_) {
          log_->warnings.truncated_records = 1;
          log_->warnings.truncated_bytes = size_ - pos;
          return size_;
        }
        SkipTo(pos, next);
        pos = next;
        continue;
      }
      SkipTo(pos, pos + 1);
      ++pos;
    }
    return pos;
  }

  /// Adds the frames counted per id below 256 to the log's message_counts: once, after the
  /// last Run.
  void Finish() {
    for (std::uint32_t id = 0; id < 256; ++id) {
      if (low_counts_[id] > 0) log_->message_counts[id] += low_counts_[id];
    }
    low_counts_.fill(0);
  }

  /// Takes over where `part` (a parser of the same data whose log was joined to this one's)
  /// got to: the next Run goes on as `part` would have.
  void GoOnFrom(const Parser& part) {
    last_end_ = part.last_end_;
    skip_end_ = part.skip_end_;
  }

  /// First position in [from, to) where `records` records this parser would accept follow one
  /// another; `to` when there is none: where a later part may start.
  std::size_t FindRecordChain(std::size_t from, std::size_t to, int records) const {
    Frame f;
    for (std::size_t p = from; p < to; ++p) {
      std::size_t at = p;
      int found = 0;
      while (found < records && at < size_ && Accepted(Examine(data_, size_, at, &f), f, at)) {
        at += f.record_bytes;
        ++found;
      }
      if (found == records) return p;
    }
    return to;
  }

 private:
  /// Whether the record Examine found at `pos` (verdict `v`, frame `f`) is accepted: its CRC
  /// checked, or of an id it cannot check and followed by what looks like a record.
  bool Accepted(Verdict v, const Frame& f, std::size_t pos) const {
    return v == Verdict::kChecked ||
           (v == Verdict::kUnchecked && NextLooksLikeRecord(data_, size_, pos + f.record_bytes));
  }

  /// First position >= from where a record is accepted, or size_.
  std::size_t FindRecord(std::size_t from) const {
    Frame f;
    for (std::size_t p = from; p < size_; ++p) {
      if (Accepted(Examine(data_, size_, p, &f), f, p)) return p;
    }
    return size_;
  }

  /// Counts bytes [from, to) as skipped.
  void SkipTo(std::size_t from, std::size_t to) {
    CountSkipped(log_->warnings, from, to, skip_end_);
  }

  void Accept(const Frame& f, bool checked) {
    if (f.v2) {
      ++log_->frames_v2;
      if (f.is_signed) ++log_->frames_signed;
    } else {
      ++log_->frames_v1;
    }
    log_->record_bytes += f.record_bytes;
    if (checked) {
      ++log_->checked_frames;
    } else {
      ++log_->warnings.unchecked_frames;
    }
    if (f.msgid >= 256) {
      ++log_->message_counts[f.msgid];
      return;
    }
    ++low_counts_[f.msgid];
    const std::size_t full = kIds.full_len[f.msgid];
    if (full == 0 || !checked) return;
    // Zero-extend a truncated payload (MAVLink 2) to the full length.
    const std::uint8_t* p = f.payload;
    if (f.len < full) {
      std::memset(buffer_.data(), 0, full);
      std::memcpy(buffer_.data(), f.payload, f.len);
      p = buffer_.data();
    }
    Decode(f, p);
  }

  void Decode(const Frame& f, const std::uint8_t* p) {
    const double log_time_s = static_cast<double>(f.time_us) * 1e-6;
    switch (f.msgid) {
      case kMavHeartbeat: {
        MavlinkHeartbeat& h = log_->heartbeat.emplace_back();
        h.log_time_s = log_time_s;
        h.system_id = f.system_id;
        h.component_id = f.component_id;
        h.custom_mode = LoadLittleEndian<std::uint32_t>(p);
        h.type = p[4];
        h.autopilot = p[5];
        h.base_mode = p[6];
        h.system_status = p[7];
        h.mavlink_version = p[8];
        break;
      }
      case kMavParamValue: {
        MavlinkParamValue& v = log_->param_value.emplace_back();
        v.log_time_s = log_time_s;
        v.system_id = f.system_id;
        v.component_id = f.component_id;
        v.value = LoadLittleEndian<float>(p);
        v.count = LoadLittleEndian<std::uint16_t>(p + 4);
        v.index = LoadLittleEndian<std::uint16_t>(p + 6);
        std::memcpy(v.id.data(), p + 8, 16);
        v.type = p[24];
        break;
      }
      case kMavGpsRawInt: {
        MavlinkGpsRawInt& g = log_->gps_raw_int.emplace_back();
        g.log_time_s = log_time_s;
        g.system_id = f.system_id;
        g.component_id = f.component_id;
        g.time_us = LoadLittleEndian<std::uint64_t>(p);
        g.lat_e7 = LoadLittleEndian<std::int32_t>(p + 8);
        g.lon_e7 = LoadLittleEndian<std::int32_t>(p + 12);
        g.alt_mm = LoadLittleEndian<std::int32_t>(p + 16);
        g.eph = LoadLittleEndian<std::uint16_t>(p + 20);
        g.epv = LoadLittleEndian<std::uint16_t>(p + 22);
        g.vel_cm_s = LoadLittleEndian<std::uint16_t>(p + 24);
        g.cog_cdeg = LoadLittleEndian<std::uint16_t>(p + 26);
        g.fix_type = p[28];
        g.satellites_visible = p[29];
        g.alt_ellipsoid_mm = LoadLittleEndian<std::int32_t>(p + 30);
        g.h_acc_mm = LoadLittleEndian<std::uint32_t>(p + 34);
        g.v_acc_mm = LoadLittleEndian<std::uint32_t>(p + 38);
        g.vel_acc_mm_s = LoadLittleEndian<std::uint32_t>(p + 42);
        g.hdg_acc_degE5 = LoadLittleEndian<std::uint32_t>(p + 46);
        g.yaw_cdeg = LoadLittleEndian<std::uint16_t>(p + 50);
        break;
      }
      case kMavRawImu: {
        // time_usec u64, 9 x int16, extensions id u8 (26), temperature int16 (27).
        MavlinkInt16Imu& s = log_->raw_imu.emplace_back();
        FillInt16Imu(f, log_time_s, LoadLittleEndian<std::uint64_t>(p), p + 8, &s);
        s.id = p[26];
        s.temperature_cdegc = LoadLittleEndian<std::int16_t>(p + 27);
        break;
      }
      case kMavScaledImu:
      case kMavScaledImu2:
      case kMavScaledImu3: {
        // time_boot_ms u32, 9 x int16, extension temperature int16 (22).
        std::vector<MavlinkInt16Imu>& out = f.msgid == kMavScaledImu    ? log_->scaled_imu
                                            : f.msgid == kMavScaledImu2 ? log_->scaled_imu2
                                                                        : log_->scaled_imu3;
        MavlinkInt16Imu& s = out.emplace_back();
        FillInt16Imu(f, log_time_s, std::uint64_t{LoadLittleEndian<std::uint32_t>(p)} * 1000u,
                     p + 4, &s);
        s.temperature_cdegc = LoadLittleEndian<std::int16_t>(p + 22);
        break;
      }
      case kMavHighresImu: {
        // time_usec u64, 13 floats, fields_updated u16 (60), extension id u8 (62).
        MavlinkHighresImu& h = log_->highres_imu.emplace_back();
        h.log_time_s = log_time_s;
        h.system_id = f.system_id;
        h.component_id = f.component_id;
        h.time_us = LoadLittleEndian<std::uint64_t>(p);
        h.acc = FloatTriad(p + 8);
        h.gyr = FloatTriad(p + 20);
        h.mag = FloatTriad(p + 32);
        h.abs_pressure_hpa = LoadLittleEndian<float>(p + 44);
        h.diff_pressure_hpa = LoadLittleEndian<float>(p + 48);
        h.pressure_alt = LoadLittleEndian<float>(p + 52);
        h.temperature_degc = LoadLittleEndian<float>(p + 56);
        h.fields_updated = LoadLittleEndian<std::uint16_t>(p + 60);
        h.id = p[62];
        break;
      }
      default:
        break;
    }
  }

  static void FillInt16Imu(const Frame& f, double log_time_s, std::uint64_t time_us,
                           const std::uint8_t* triads, MavlinkInt16Imu* s) {
    s->log_time_s = log_time_s;
    s->time_us = time_us;
    s->system_id = f.system_id;
    s->component_id = f.component_id;
    s->acc = Int16Triad(triads);
    s->gyr = Int16Triad(triads + 6);
    s->mag = Int16Triad(triads + 12);
  }

  const std::uint8_t* data_;
  std::size_t size_;
  MavlinkLog* log_;
  const LogFile* file_;
  std::size_t released_;   // the file is released up to here (LogFile::Release)
  std::size_t last_end_;   // end of the last accepted record
  std::array<std::size_t, 256> low_counts_;
  std::array<std::uint8_t, kMaxPayload + 1> buffer_{};
  std::size_t skip_end_ = 0;
};

}  // namespace

std::uint16_t MavlinkCrc(const std::uint8_t* data, std::size_t size, std::uint16_t crc) {
  return Crc(data, size, crc);
}

bool LooksLikeTlogRecord(const std::uint8_t* data, std::size_t size) {
  if (size < kTimeBytes + 1) return false;
  const std::uint8_t stx = data[kTimeBytes];
  return PlausibleTime(LoadBigEndian64(data)) && (stx == kStxV1 || stx == kStxV2);
}

const std::vector<MavlinkMessageInfo>& MavlinkMessages() {
  static const std::vector<MavlinkMessageInfo> all = [] {
    std::vector<MavlinkMessageInfo> out;
    out.reserve(kMessageCount);
    for (const MavlinkMessageInfoRow& m : kMavlinkMessages) {
      out.push_back({m.id, m.name, m.crc_extra, m.min_length, m.max_length,
                     kMavlinkDialects[m.dialect]});
    }
    return out;
  }();
  return all;
}

const MavlinkMessageInfo* FindMavlinkMessage(std::uint32_t msgid) {
  const MavlinkMessageInfoRow* row = FindRow(msgid);
  return row ? &MavlinkMessages()[static_cast<std::size_t>(row - kMavlinkMessages)] : nullptr;
}

std::string MavlinkDefinitionsSource() {
  std::string dialects;
  for (const char* d : kMavlinkDialects) {
    dialects += (dialects.empty() ? "" : ", ") + std::string(d);
  }
  return dialects + " (" + kMavlinkDefinitions + ")";
}

std::string MavlinkMessageName(std::uint32_t msgid) {
  const MavlinkMessageInfoRow* row = FindRow(msgid);
  return row ? std::string(row->name) : "MSG" + std::to_string(msgid);
}

int MavlinkCrcExtra(std::uint32_t msgid) { return CrcExtraOf(msgid); }

std::string_view MavlinkParamValue::NameView() const {
  return {id.data(), strnlen(id.data(), id.size())};
}

std::vector<std::string> MavlinkWarnings::Describe(
    const std::map<std::uint32_t, std::size_t>& counts) const {
  std::vector<std::string> out;
  if (bytes_skipped) {
    out.push_back("skipped " + std::to_string(bytes_skipped) + " bytes in " +
                  std::to_string(skip_runs) +
                  " run(s) not forming a valid tlog record (first at byte " +
                  std::to_string(first_skip_offset) + ")");
  }
  if (crc_failures) {
    out.push_back(std::to_string(crc_failures) + " frame(s) failed their CRC and were dropped " +
                  "(first at byte " + std::to_string(first_crc_failure_offset) + ")");
  }
  if (truncated_records) {
    out.push_back("dropped the truncated last record (" + std::to_string(truncated_bytes) +
                  " bytes)");
  }
  if (unchecked_frames) {
    std::string ids;
    for (const auto& [id, n] : counts) {
      if (MavlinkCrcExtra(id) >= 0) continue;
      ids += (ids.empty() ? "" : ", ") + MavlinkMessageName(id) + " (id " + std::to_string(id) +
             ") x" + std::to_string(n);
    }
    out.push_back(std::to_string(unchecked_frames) +
                  " frame(s) of messages outside the known MAVLink dialects (" +
                  MavlinkDefinitionsSource() + "), so without a CRC_EXTRA, kept unchecked and "
                  "not decoded: " + ids);
  }
  return out;
}

std::vector<std::pair<std::string, std::size_t>> MavlinkLog::MessageCounts() const {
  std::vector<std::pair<std::string, std::size_t>> out;
  for (const auto& [id, n] : message_counts) out.emplace_back(MavlinkMessageName(id), n);
  return out;
}

namespace {

/// Appends `later`'s warnings, those of the bytes after `w`'s, to `w`.
void AddWarnings(MavlinkWarnings& w, const MavlinkWarnings& later) {
  if (w.bytes_skipped == 0) w.first_skip_offset = later.first_skip_offset;
  if (w.crc_failures == 0) w.first_crc_failure_offset = later.first_crc_failure_offset;
  w.bytes_skipped += later.bytes_skipped;
  w.skip_runs += later.skip_runs;
  w.crc_failures += later.crc_failures;
  w.truncated_records += later.truncated_records;
  w.truncated_bytes += later.truncated_bytes;
  w.unchecked_frames += later.unchecked_frames;
}

/// Appends `later`, decoded from the bytes right after `log`'s (a later part starting on a
/// record the log so far reached), to `log`: as one parser going through both would have it.
/// The message vectors are appended as jobs through `run_jobs`.
void Join(MavlinkLog& log, const MavlinkLog& later, const JobRunner& run_jobs) {
  log.frames_v1 += later.frames_v1;
  log.frames_v2 += later.frames_v2;
  log.frames_signed += later.frames_signed;
  log.checked_frames += later.checked_frames;
  log.record_bytes += later.record_bytes;
  for (const auto& [id, n] : later.message_counts) log.message_counts[id] += n;
  AddWarnings(log.warnings, later.warnings);
  const auto append = [](auto& out, const auto& in) {
    out.insert(out.end(), in.begin(), in.end());
  };
  RunJobs(run_jobs, 8, [&](int job) {  // each job appends its own vector
    switch (job) {
      case 0: append(log.heartbeat, later.heartbeat); break;
      case 1: append(log.raw_imu, later.raw_imu); break;
      case 2: append(log.scaled_imu, later.scaled_imu); break;
      case 3: append(log.scaled_imu2, later.scaled_imu2); break;
      case 4: append(log.scaled_imu3, later.scaled_imu3); break;
      case 5: append(log.highres_imu, later.highres_imu); break;
      case 6: append(log.gps_raw_int, later.gps_raw_int); break;
      default: append(log.param_value, later.param_value); break;
    }
  });
}

/// Decodes `data` (`size` bytes) into `first`, which writes `log`, in parts at once through
/// options.run_jobs: each part after the first starts at a chain of records
/// (detail::kBoundaryRecords) looked for near its nominal start (detail::PartStarts; no lead
/// is read alone: a tlog has no definitions) and reads to the next part's start, the last to
/// the end; the first reads to the second's start. Then, in order, a part's log is joined when
/// the log so far ends exactly on its start; else `first` reads the part's bytes itself. Either
/// way the log is the one a single pass makes.
void ReadInParts(const std::uint8_t* data, std::size_t size, Parser& first, MavlinkLog& log,
                 const LogFile* file, const SplitReadOptions& options) {
  const std::size_t lead = std::min(options.lead_bytes, size);
  const std::vector<std::size_t> starts =
      detail::PartStarts(size, lead, options, [&](std::size_t from) -> std::optional<std::size_t> {
        const std::size_t end = std::min(size, from + detail::kBoundaryWindow);
        const std::size_t at = first.FindRecordChain(from, end, detail::kBoundaryRecords);
        if (at == end) return std::nullopt;
        return at;
      });
  if (starts.empty()) {
    first.Run(0, size);
    return;
  }
  const std::size_t later = starts.size();  // parts after the first
  std::vector<MavlinkLog> logs(later);
  std::vector<Parser> parts;
  parts.reserve(later);
  for (std::size_t i = 0; i < later; ++i) parts.emplace_back(data, size, &logs[i], file, starts[i]);
  // parts[i] reads part i + 1 (part 0: `first`'s), from starts[i] to end_of(i).
  const auto end_of = [&](std::size_t i) { return i + 1 < later ? starts[i + 1] : size; };
  std::size_t reached = 0;
  std::vector<std::size_t> stops(later, 0);
  RunJobs(options.run_jobs, static_cast<int>(later + 1), [&](int job) {
    if (job == 0) {
      reached = first.Run(0, starts[0]);
      return;
    }
    const auto i = static_cast<std::size_t>(job - 1);
    stops[i] = parts[i].Run(starts[i], end_of(i));
    parts[i].Finish();
  });
  for (std::size_t i = 0; i < later; ++i) {
    if (reached == starts[i]) {
      Join(log, logs[i], options.run_jobs);
      first.GoOnFrom(parts[i]);
      reached = stops[i];
    } else {
      reached = first.Run(reached, end_of(i));
    }
  }
}

/// ParseTlog, telling `file` (nullptr: none) what the parser has read.
MavlinkLog ParseTlogFrom(const std::uint8_t* data, std::size_t size, const std::string& source,
                         const LogFile* file, const TlogReadOptions& options) {
  MavlinkLog log;
  log.source = source;
  log.size_bytes = size;
  Parser parser(data, size, &log, file);
  if (options.run_jobs && size > 0 && size >= options.split_bytes) {
    ReadInParts(data, size, parser, log, file, options);
  } else {
    parser.Run(0, size);
  }
  parser.Finish();
  if (log.frames_v1 + log.frames_v2 == 0) {
    throw InputError(source, "byte 0",
                     "no MAVLink frame ([8-byte big-endian unix time in µs][0xFE or 0xFD "
                     "frame] with a valid CRC) in " + std::to_string(size) +
                         " bytes: not a MAVLink .tlog");
  }
  return log;
}

}  // namespace

MavlinkLog ParseTlog(const std::uint8_t* data, std::size_t size, const std::string& source,
                     const TlogReadOptions& options) {
  return ParseTlogFrom(data, size, source, nullptr, options);
}

MavlinkLog ReadTlog(const std::string& path, const TlogReadOptions& options) {
  const LogFile file(path, "MAVLink tlog");
  try {
    MavlinkLog log = ParseTlogFrom(file.data(), file.size(), path, &file, options);
    file.ThrowIfCut();
    return log;
  } catch (const Error&) {
    file.ThrowIfCut();  // the zeros of a cut may have caused it
    throw;
  }
}

}  // namespace plumb::io

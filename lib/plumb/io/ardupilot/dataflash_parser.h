// plumb/io/ardupilot/dataflash_parser.h — INTERNAL to plumb::io_ardupilot: the binary .bin
// reader's one-pass decoder (ReadDataflash and ParseDataflash in dataflash.cc are its users):
// the walk from record to record, the IMU samples decoded inside it (DataflashImuDecoder), and
// the pieces of the read in parts: a parser started further on in the same file, run beside
// the first (DataflashParser::Ahead), and the join of what it decoded to what the first one
// did (DataflashParser::Absorb), exactly as one parser going through both parts would have
// decoded them. Not part of the public interface.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "plumb/core/jobs.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/ardupilot/dataflash_format.h"
#include "plumb/io/common/log_common.h"

namespace plumb::io::detail {

/// The time column of an IMU message: TimeUS or TimeMS (`scale` 1e-6 or 1e-3 s per unit).
struct DataflashTimeColumn {
  int col = -1;  ///< -1: none
  double scale = 0.0;
};
DataflashTimeColumn FindDataflashTime(const DataflashType& t);
/// The column T, else Temp, of `t`; -1 when it has neither.
int DataflashTemperatureColumn(const DataflashType& t);

/// ImuFromDataflash's rule for times, as the reader applies it record by record to the samples
/// it has kept so far (`kept`: BackTime(), PopBack(), Empty()): the last kept sample is on
/// trial (`on_trial`) until the next record, and goes out again when that record's time `t_s`
/// is not above it (a spike); a record's sample is kept, for now, when `t_s` is finite and
/// above the last kept sample's. Returns whether it is (the caller appends it); `on_trial`
/// becomes the same. The one statement of the rule: the reader and the join of two parts
/// (DataflashImuDecoder::PlanJoin) both use it.
template <typename Kept>
[[gnu::always_inline]] inline bool ApplyDataflashTimeRule(Kept& kept, bool& on_trial, double t_s) {
  if (on_trial && !(kept.BackTime() < t_s)) kept.PopBack();
  on_trial = std::isfinite(t_s) && (kept.Empty() || t_s > kept.BackTime());
  return on_trial;
}

/// One IMU record of an instance as decoded, before the rule for times: what a parser started
/// further on (DataflashParser::Ahead) keeps of each instance's first records, to join its
/// samples to those decoded before its first record.
struct DataflashImuRecord {
  double t_s = 0.0;
  Vec3f acc = Vec3f::Zero();
  Vec3f gyr = Vec3f::Zero();
  float temp_c = 0.0F;
};

/// Such records of each instance of one message, by instance.
using DataflashImuHeads = std::vector<std::vector<DataflashImuRecord>>;

/// How the samples of one instance decoded by a parser started at a record (b) join those
/// decoded before that record (a), as one parser would have kept them (PlanJoin): a's first
/// `a_kept` samples, then the records `from_head` of b's head, then b's samples from `from_b`
/// on; the joined state's last sample is on trial when `on_trial`.
struct DataflashImuSeam {
  std::size_t a_kept = 0;
  std::vector<std::size_t> from_head;
  std::size_t from_b = 0;
  bool on_trial = false;
  /// The time of a's last record when the joined rule takes it out again (it was on trial
  /// when a ended), else nullopt.
  std::optional<double> a_last_dropped_t_s;
  /// The first of b's records the joined rule leaves out (its place among b's records);
  /// nullopt when none is.
  std::optional<DataflashDroppedRecord> first_dropped_in_b;
};

/// Decodes the IMU samples of one message inside the reader's pass (RecordFilter::decode):
/// the columns ImuFromDataflash reads, and its rule for times applied record by record. Its
/// per-record functions are inlined into the parser's loop ([[gnu::always_inline]]: the loop
/// is instantiated twice, DataflashParser::Walk, and the compiler would otherwise call them).
class DataflashImuDecoder {
 public:
  /// Records of each instance a parser started further on keeps as they were decoded
  /// (DataflashImuHeads): the rule for times settles the join of two parts within the first
  /// two records unless times go back right at the seam.
  static constexpr std::size_t kHeadRecords = 16;

  /// The decoder of `t`, or nullopt when `t` lacks a time or AccX/Y/Z column (its bodies are
  /// then kept, and ImuFromDataflash says what is missing). `rows_bound`: at most this many
  /// records are coming (0: unknown), to reserve each instance's samples once.
  static std::optional<DataflashImuDecoder> For(const DataflashType& t, std::size_t rows_bound);

  /// Reserves samples (Reserve, at an instance's first record) for at most `rows_bound`
  /// records from now on (kMaxReserve at most): a parser of part of the input (Ahead).
  void BoundRows(std::size_t rows_bound) { rows_bound_ = std::min(rows_bound, kMaxReserve); }

  /// Decodes the record body `body` of `t` (the type this decoder was made for). `heads`
  /// (nullptr: none): where each instance's first kHeadRecords records are kept as decoded.
  [[gnu::always_inline]] void Add(DataflashType& t, const std::uint8_t* body,
                                  DataflashImuHeads* heads) const {
    if (usual_layout_) {
      AddWith(t, body, UsualColumns{*this}, heads);
    } else {
      AddWith(t, body, AnyColumns{*this}, heads);
    }
  }

  /// After the last record: every instance's last sample stays (no record follows it).
  void Finish(DataflashType& t) const {
    for (DataflashImuDecoded& d : t.imu) d.last_on_trial = false;
  }

  /// How `b`, one instance's samples decoded by a parser started at a record (with `head`, its
  /// first records as decoded), joins `a`, the same instance's samples decoded before that
  /// record: the rule for times replayed over b's head from a's state and from none, until
  /// both meet the records after in the same state. nullopt when b's head does not settle it.
  static std::optional<DataflashImuSeam> PlanJoin(const DataflashImuDecoded& a,
                                                  const DataflashImuDecoded& b,
                                                  const std::vector<DataflashImuRecord>& head);
  /// Makes `a` the joined samples of `a` and `b` (`seam` from PlanJoin); `b` is left empty.
  /// The copies of b's time, accelerometer, gyroscope and temperature columns are four jobs
  /// run through `run_jobs` (core/jobs.h; empty: one after another).
  void Join(const DataflashImuSeam& seam, DataflashImuDecoded& a, DataflashImuDecoded& b,
            const std::vector<DataflashImuRecord>& head, const JobRunner& run_jobs) const;

 private:
  /// Reserved samples per instance at most (beyond, the series grow by doubling).
  static constexpr std::size_t kMaxReserve = std::size_t{1} << 24;

  /// The columns read through their readers (DataflashColumnReader::Read, any format
  /// character), the values cast to the series' types.
  struct AnyColumns {
    const DataflashImuDecoder& d;
    /// The record's instance 0..255, or -1 when its I value names none.
    int Instance(const std::uint8_t* body) const {
      const double v = d.instance_.Read(body);
      return v >= 0 && v < 256 && v == std::floor(v) ? static_cast<int>(v) : -1;
    }
    double RawTime(const std::uint8_t* body) const { return d.time_.Read(body); }
    Vec3f Axes(const std::uint8_t* body, const DataflashColumnReader* c) const {
      return Vec3f(static_cast<float>(c[0].Read(body)), static_cast<float>(c[1].Read(body)),
                   static_cast<float>(c[2].Read(body)));
    }
    float Temperature(const std::uint8_t* body) const {
      return static_cast<float>(d.temp_.Read(body));
    }
  };

  /// The columns of the layout ArduPilot writes (usual_layout_: TimeUS 'Q', I 'B', the axes
  /// and T 'f'): the stored values loaded as they are, which are AnyColumns' values without
  /// its switch on the format character.
  struct UsualColumns {
    const DataflashImuDecoder& d;
    int Instance(const std::uint8_t* body) const { return body[d.instance_.offset]; }
    double RawTime(const std::uint8_t* body) const {
      return static_cast<double>(LoadLittleEndian<std::uint64_t>(body + d.time_.offset));
    }
    Vec3f Axes(const std::uint8_t* body, const DataflashColumnReader* c) const {
      return Vec3f(LoadLittleEndian<float>(body + c[0].offset),
                   LoadLittleEndian<float>(body + c[1].offset),
                   LoadLittleEndian<float>(body + c[2].offset));
    }
    float Temperature(const std::uint8_t* body) const {
      return LoadLittleEndian<float>(body + d.temp_.offset);
    }
  };

  /// The samples of `decoded` as the rule for times sees them (ApplyDataflashTimeRule); a
  /// sample taken out again (the record before the one being added) is noted as dropped.
  struct SeriesKept {
    const DataflashImuDecoder& d;
    DataflashImuDecoded& decoded;
    double BackTime() const { return decoded.series.t_s.back(); }
    void PopBack() const {
      NoteDropped(decoded, decoded.records - 2, decoded.series.t_s.back());
      d.PopBack(decoded.series);
    }
    bool Empty() const { return decoded.series.t_s.empty(); }
  };

  /// Notes record `record` (time `t_s`) of `d` as left out by the rule while its latest
  /// record is added (a rare path). "After the head": while a record after the first
  /// kHeadRecords is added.
  static void NoteDropped(DataflashImuDecoded& d, std::size_t record, double t_s) {
    if (!d.first_dropped) d.first_dropped = DataflashDroppedRecord{record, t_s};
    if (d.records > kHeadRecords && !d.first_dropped_after_head) {
      d.first_dropped_after_head = DataflashDroppedRecord{record, t_s};
    }
  }

  /// Add with the columns read by `columns` (AnyColumns or UsualColumns).
  template <typename Columns>
  [[gnu::always_inline]] void AddWith(DataflashType& t, const std::uint8_t* body,
                                      const Columns& columns, DataflashImuHeads* heads) const {
    std::size_t k = 0;
    if (has_instance_) {
      const int instance = columns.Instance(body);
      if (instance < 0) return;  // no instance's record
      k = static_cast<std::size_t>(instance);
    }
    if (k >= t.imu.size()) t.imu.resize(k + 1);
    DataflashImuDecoded& d = t.imu[k];
    const double raw_t = columns.RawTime(body);
    const double t_s = raw_t * time_scale_;
    if (d.records == 0) {
      d.first_time = raw_t;
      Reserve(d.series);
    }
    d.last_time = raw_t;
    ++d.records;
    if (heads != nullptr && d.records <= kHeadRecords) {
      if (k >= heads->size()) heads->resize(k + 1);
      (*heads)[k].push_back(Record(t_s, body, columns));
    }
    SeriesKept kept{*this, d};
    if (!ApplyDataflashTimeRule(kept, d.last_on_trial, t_s)) {
      NoteDropped(d, d.records - 1, t_s);
      return;
    }
    ImuSeries& s = d.series;
    s.t_s.push_back(t_s);
    s.acc.push_back(columns.Axes(body, acc_));
    if (has_gyr_) s.gyr.push_back(columns.Axes(body, gyr_));
    if (has_temp_) s.temp_c.push_back(columns.Temperature(body));
  }

  /// The record `body` (time `t_s`) as decoded.
  template <typename Columns>
  DataflashImuRecord Record(double t_s, const std::uint8_t* body, const Columns& columns) const {
    DataflashImuRecord r;
    r.t_s = t_s;
    r.acc = columns.Axes(body, acc_);
    if (has_gyr_) r.gyr = columns.Axes(body, gyr_);
    if (has_temp_) r.temp_c = columns.Temperature(body);
    return r;
  }

  void Reserve(ImuSeries& s) const;
  /// Takes the last sample out of `s`.
  void PopBack(ImuSeries& s) const {
    s.t_s.pop_back();
    s.acc.pop_back();
    if (has_gyr_) s.gyr.pop_back();
    if (has_temp_) s.temp_c.pop_back();
  }

  DataflashColumnReader time_, acc_[3], gyr_[3], temp_, instance_;
  double time_scale_ = 0.0;
  bool has_gyr_ = false;
  bool has_temp_ = false;
  bool has_instance_ = false;
  /// The time column is 'Q', the instance column 'B', the axes and temperature 'f' (scale 1):
  /// Add reads them with UsualColumns.
  bool usual_layout_ = false;
  std::size_t rows_bound_ = 0;
};

/// The one-pass decoder state: fed the file's bytes in order, in one piece (ParseDataflash) or
/// in chunks (ReadDataflash, through ReadForward).
class DataflashParser {
 public:
  /// The longest record: its length is one byte, header included.
  static constexpr std::size_t kMaxRecord = 255;
  /// Bytes past a position Feed must be given to decode every record starting before it (and
  /// none after): its look-ahead less one (split_read.h).
  static constexpr std::size_t kUntilSlack = kMaxRecord - 1;

  /// `filter`: the types whose bodies are kept or samples decoded; `size_hint`: the input's
  /// size in bytes (0: unknown), to reserve decoded samples once.
  DataflashParser(DataflashLog* log, const RecordFilter& filter, std::size_t size_hint);

  /// After the last Feed: the record counts go to the types, and the decoded IMU messages'
  /// waiting records are decided.
  void Finish();

  /// Decodes the records starting in the bytes [offset, offset + n) of the input held at
  /// `data`; returns the offset to go on from (unless `at_end`, at least kMaxRecord bytes
  /// before offset + n, so that every record starting before it is whole). `at_end`: the bytes
  /// end the input (the truncated last record and trailing bytes are counted).
  std::size_t Feed(const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
    return Walk<false>(data, n, offset, at_end);
  }

  /// A parser for the records from a later byte of the same input on, to run beside this one
  /// (the read in parts, split_read.h): it knows the types this one knows now, decodes into
  /// `out` (which gets their definitions, no records), keeps each IMU instance's first records
  /// as decoded (DataflashImuHeads), reserves samples for the records of about `bytes` bytes,
  /// and is fed with FeedAhead.
  DataflashParser Ahead(DataflashLog* out, std::size_t bytes) const;

  /// Feed for a parser made by Ahead: the same, but it stops (stopped()) at the first byte it
  /// cannot decide as this parser's maker would there: a record header whose type it does not
  /// know (the type may have been defined since), or an FMT defining a new type; and it leaves
  /// the input's last kMaxRecord bytes. Returns the offset it reached.
  std::size_t FeedAhead(const std::uint8_t* data, std::size_t n, std::size_t offset) {
    return Walk<true>(data, n, offset, false);
  }
  /// True once FeedAhead stopped.
  bool stopped() const { return stopped_; }

  /// The first position in [0, n) of `data` from which `records` records of the types this
  /// parser knows follow one another inside the n bytes; n when there is none. A guess at a
  /// record boundary in the middle of a log.
  std::size_t FindRecordChain(const std::uint8_t* data, std::size_t n, int records) const;

  /// Adds what `ahead` (made by this parser's Ahead, decoding into `ahead_log`) decoded to
  /// this parser's log, as if this parser had gone on through the same records, from where it
  /// is now (the byte `ahead` started at): the records counted, bodies kept, IMU samples
  /// joined (PlanJoin), FMT warnings. False, with nothing changed, when an instance's samples
  /// cannot be joined from the records `ahead` kept of it.
  /// The samples' copies are jobs run through `run_jobs` (DataflashImuDecoder::Join).
  bool Absorb(const DataflashParser& ahead, DataflashLog& ahead_log, const JobRunner& run_jobs);

 private:
  /// What the loop does with a record of a type besides counting it.
  enum class Action : std::uint8_t { kCount, kKeep, kDecode, kFmt };
  /// A type's entry in the loop's table, by type byte.
  struct Entry {
    std::uint8_t length = 0;  ///< record length with the header; 0: no type has this byte
    Action action = Action::kCount;
  };

  /// Feed (kAhead false) and FeedAhead (kAhead true).
  template <bool kAhead>
  std::size_t Walk(const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end) {
    // The loop reads one table per record (length and action by type byte) and touches a
    // type only for the records it keeps or decodes: the walk from record to record is the
    // chain of loads byte -> length -> next byte, nothing more.
    const std::size_t room = at_end ? kDataflashHeaderSize : kMaxRecord;  // bytes a record may need
    std::size_t i = 0;
    while (n - i >= room) {
      const std::uint8_t* p = data + i;
      const Entry e = table_[p[2]];
      if (p[0] == kDataflashHead1 && p[1] == kDataflashHead2 && e.length != 0) {
        if constexpr (kAhead) {
          const std::uint8_t* body = p + kDataflashHeaderSize;
          if (e.action == Action::kFmt && index_[body[kFmtTypeOffset]] < 0) break;
        }
        if (e.length > n - i) {  // never with kMaxRecord bytes of room
          Truncated(n - i);
          return offset + n;
        }
        ++rows_[p[2]];
        i += e.length;
        if (e.action != Action::kCount) {
          Act<kAhead>(e.action, p[2], p + kDataflashHeaderSize, offset + i);
        }
        continue;
      }
      if constexpr (kAhead) {
        // A header with a type this parser does not know may be one defined since it was made.
        if (p[0] == kDataflashHead1 && p[1] == kDataflashHead2) break;
      }
      Skip(offset + i);
      ++i;
    }
    if constexpr (kAhead) {
      stopped_ = n - i >= room;
      return offset + i;
    } else {
      return FeedTail(data, n, offset, at_end, i);
    }
  }

  /// The rest of Feed from `i`, where fewer bytes than a record may need are left: counted
  /// when `at_end`.
  std::size_t FeedTail(const std::uint8_t* data, std::size_t n, std::size_t offset, bool at_end,
                       std::size_t i);

  /// Keeps (kKeep, kFmt) or decodes (kDecode) the record body `body` of type `id`; an FMT
  /// (kFmt, its record ending at byte `end`) defines a type. `kAhead`: a parser made by Ahead,
  /// which keeps each instance's first records (heads_).
  template <bool kAhead>
  [[gnu::always_inline]] void Act(Action action, std::uint8_t id, const std::uint8_t* body,
                                  std::size_t end) {
    DataflashType& t = log_->types[static_cast<std::size_t>(index_[id])];
    if (action == Action::kDecode) {
      const auto decoder = static_cast<std::size_t>(decoder_of_[id]);
      decoders_[decoder].Add(t, body, kAhead ? &heads_[decoder] : nullptr);
      return;
    }
    t.bodies.Append(body);
    if (action == Action::kFmt) HandleFmt(body, t.body_size, end);
  }

  /// Adds the warnings `w` of a parser made by Ahead (its skipped range ending at `skip_end`)
  /// to this parser's, as if this one had counted them (Absorb).
  void AbsorbWarnings(const DataflashWarnings& w, std::size_t skip_end);
  /// Adds a type from its FMT, found at byte `offset`.
  void AddType(DataflashType t, std::size_t offset = 0);
  void Skip(std::size_t pos) { CountSkipped(log_->warnings, pos, pos + 1, skip_end_); }
  void Truncated(std::size_t bytes) {
    ++log_->warnings.truncated_records;
    log_->warnings.truncated_bytes += bytes;
  }
  // FMT body: Type (B), Length (B), Name (n), Format (N), Columns (Z) = 86 bytes.
  void HandleFmt(const std::uint8_t* body, std::size_t body_size, std::size_t offset);

  DataflashLog* log_;
  const RecordFilter* filter_;
  std::size_t size_hint_ = 0;   ///< the input's size, bytes (0: unknown)
  std::array<int, 256> index_;
  std::array<int, 256> decoder_of_;  ///< index in decoders_ by type id, -1: not decoded
  std::array<Entry, 256> table_{};    ///< the loop's table by type id
  std::array<std::size_t, 256> rows_;  ///< records counted by type id
  std::vector<DataflashImuDecoder> decoders_;
  /// A parser made by Ahead: each decoder's instances' first records (by index in
  /// decoders_); empty otherwise.
  std::vector<DataflashImuHeads> heads_;
  std::size_t skip_end_ = 0;  ///< end of the last skipped range (CountSkipped)
  bool stopped_ = false;      ///< FeedAhead stopped
};

}  // namespace plumb::io::detail

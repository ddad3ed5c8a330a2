// plumb/io/ardupilot/dataflash_parser.cc — see dataflash_parser.h.
#include "plumb/io/ardupilot/dataflash_parser.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <utility>

#include "plumb/io/common/split_read.h"

namespace plumb::io::detail {
namespace {

/// Text of a fixed-width char field up to its first NUL.
std::string FixedText(const std::uint8_t* p, std::size_t n) {
  const auto* c = reinterpret_cast<const char*>(p);
  return std::string(c, strnlen(c, n));
}

/// The samples the rule for times has kept in a replay of a seam (PlanJoin): the first
/// `a_kept` of a's samples (times `a_t_s`; none for a replay from no samples), then the
/// records `pushed` of b's head.
struct ReplayKept {
  const std::vector<double>* a_t_s = nullptr;
  std::size_t a_kept = 0;
  const std::vector<DataflashImuRecord>* head = nullptr;
  std::vector<std::size_t> pushed;

  /// The time of the sample `depth` places below the last (0: the last); nullopt past the
  /// first.
  std::optional<double> TimeFromBack(std::size_t depth) const {
    if (depth < pushed.size()) return (*head)[pushed[pushed.size() - 1 - depth]].t_s;
    depth -= pushed.size();
    if (depth < a_kept) return (*a_t_s)[a_kept - 1 - depth];
    return std::nullopt;
  }
  double BackTime() const { return *TimeFromBack(0); }
  void PopBack() {
    if (!pushed.empty()) {
      pushed.pop_back();
    } else {
      --a_kept;
    }
  }
  bool Empty() const { return pushed.empty() && a_kept == 0; }
  std::size_t Size() const { return a_kept + pushed.size(); }
};

/// A ReplayKept that notes what the rule leaves out, in order: a's last sample taken out again,
/// and head records (by their place in the head) taken out or refused.
struct NotingReplay : ReplayKept {
  std::optional<double> a_last_dropped_t_s;
  std::optional<DataflashDroppedRecord> first_dropped;

  void PopBack() {
    if (pushed.empty()) {
      if (!first_dropped && !a_last_dropped_t_s) a_last_dropped_t_s = BackTime();
    } else if (!first_dropped && !a_last_dropped_t_s) {
      first_dropped = DataflashDroppedRecord{pushed.back(), (*head)[pushed.back()].t_s};
    }
    ReplayKept::PopBack();
  }
  void Refused(std::size_t j) {
    if (!first_dropped && !a_last_dropped_t_s) {
      first_dropped = DataflashDroppedRecord{j, (*head)[j].t_s};
    }
  }
  bool Dropped() const { return first_dropped || a_last_dropped_t_s; }
  /// Applies the rule to head record `j`, noting what it leaves out.
  void Apply(bool& on_trial, std::size_t j) {
    if (ApplyDataflashTimeRule(*this, on_trial, (*head)[j].t_s)) {
      pushed.push_back(j);
    } else {
      Refused(j);
    }
  }
};

/// Whether the rule for times meets every later record in the same way after `s` (its last
/// sample on trial when `s_on_trial`) as after `r`: it reads only the last sample, on trial or
/// not, and below an on-trial one the sample it would bring back.
bool SameState(const ReplayKept& s, bool s_on_trial, const ReplayKept& r, bool r_on_trial) {
  return s_on_trial == r_on_trial && s.TimeFromBack(0) == r.TimeFromBack(0) &&
         (!s_on_trial || s.TimeFromBack(1) == r.TimeFromBack(1));
}

}  // namespace

DataflashTimeColumn FindDataflashTime(const DataflashType& t) {
  if (const int c = t.ColumnIndex("TimeUS"); c >= 0) return {c, 1e-6};
  if (const int c = t.ColumnIndex("TimeMS"); c >= 0) return {c, 1e-3};
  return {};
}

int DataflashTemperatureColumn(const DataflashType& t) {
  const int c = t.ColumnIndex("T");
  return c >= 0 ? c : t.ColumnIndex("Temp");
}

std::optional<DataflashImuDecoder> DataflashImuDecoder::For(const DataflashType& t,
                                                            std::size_t rows_bound) {
  using Reader = DataflashColumnReader;
  const DataflashTimeColumn time = FindDataflashTime(t);
  const int acc[3] = {t.ColumnIndex("AccX"), t.ColumnIndex("AccY"), t.ColumnIndex("AccZ")};
  if (time.col < 0 || acc[0] < 0 || acc[1] < 0 || acc[2] < 0) return std::nullopt;
  const int gyr[3] = {t.ColumnIndex("GyrX"), t.ColumnIndex("GyrY"), t.ColumnIndex("GyrZ")};
  DataflashImuDecoder d;
  d.time_ = Reader::Of(t, time.col);
  d.time_scale_ = time.scale;
  for (int k = 0; k < 3; ++k) d.acc_[k] = Reader::Of(t, acc[k]);
  d.has_gyr_ = gyr[0] >= 0 && gyr[1] >= 0 && gyr[2] >= 0;
  if (d.has_gyr_) {
    for (int k = 0; k < 3; ++k) d.gyr_[k] = Reader::Of(t, gyr[k]);
  }
  const int temp = DataflashTemperatureColumn(t);
  d.has_temp_ = temp >= 0;
  if (d.has_temp_) d.temp_ = Reader::Of(t, temp);
  // As ImuFromDataflash finds its instances (DataflashInstanceMessage): the I column of
  // "IMU"; any other message (IMU2, ...) is one instance.
  const int instance = t.name == "IMU" ? t.ColumnIndex("I") : -1;
  d.has_instance_ = instance >= 0;
  if (d.has_instance_) d.instance_ = Reader::Of(t, instance);
  const auto plain_float = [](const Reader& r) {
    return r.storage == DataflashStorage::kFloat && r.scale == 1.0;
  };
  bool usual = d.time_.storage == DataflashStorage::kUInt64 && d.time_.scale == 1.0;
  usual = usual && (!d.has_instance_ || d.instance_.storage == DataflashStorage::kUInt8);
  usual = usual && (!d.has_temp_ || plain_float(d.temp_));
  for (int k = 0; k < 3; ++k) {
    usual = usual && plain_float(d.acc_[k]) && (!d.has_gyr_ || plain_float(d.gyr_[k]));
  }
  d.usual_layout_ = usual;
  d.rows_bound_ = std::min(rows_bound, kMaxReserve);
  return d;
}

void DataflashImuDecoder::Reserve(ImuSeries& s) const {
  if (rows_bound_ == 0) return;
  ReserveHugePages(s.t_s, rows_bound_);
  ReserveHugePages(s.acc, rows_bound_);
  if (has_gyr_) ReserveHugePages(s.gyr, rows_bound_);
  if (has_temp_) ReserveHugePages(s.temp_c, rows_bound_);
}

std::optional<DataflashImuSeam> DataflashImuDecoder::PlanJoin(
    const DataflashImuDecoded& a, const DataflashImuDecoded& b,
    const std::vector<DataflashImuRecord>& head) {
  // The rule replayed over b's first records twice: from a's state (s, what one parser going
  // through both parts keeps) and from no samples (r, what b's parser kept). Once both meet
  // the next record in the same state, they keep the same samples from then on: the samples
  // settled in s, then b's from where r's settled ones end.
  NotingReplay s{{&a.series.t_s, a.series.size(), &head, {}}, {}, {}};
  NotingReplay r{{nullptr, 0, &head, {}}, {}, {}};
  bool s_on_trial = a.last_on_trial;
  bool r_on_trial = false;
  for (std::size_t j = 0; j < head.size(); ++j) {
    s.Apply(s_on_trial, j);
    r.Apply(r_on_trial, j);
    if (!SameState(s, s_on_trial, r, r_on_trial)) continue;
    const std::size_t trial = s_on_trial ? 1 : 0;  // the last sample, still undecided
    DataflashImuSeam seam;
    seam.a_kept = s.a_kept;
    seam.from_head.assign(s.pushed.begin(), s.pushed.end() - static_cast<std::ptrdiff_t>(trial));
    seam.from_b = r.Size() - trial;
    seam.on_trial = b.last_on_trial;
    // What the joined rule leaves out first: up to here what the replay from a's state did;
    // from here on what b's own parser did (the states are the same), found by replaying the
    // rest of the head and then from what b noted after its head.
    seam.a_last_dropped_t_s = s.a_last_dropped_t_s;
    seam.first_dropped_in_b = s.first_dropped;
    if (!s.Dropped()) {
      NotingReplay rest{{r.a_t_s, r.a_kept, &head, r.pushed}, {}, {}};
      for (std::size_t k = j + 1; k < head.size() && !rest.Dropped(); ++k) rest.Apply(r_on_trial, k);
      seam.first_dropped_in_b = rest.first_dropped ? rest.first_dropped : b.first_dropped_after_head;
    }
    return seam;
  }
  if (head.size() < b.records) return std::nullopt;
  // The head is every record of b: the replay from a's state is the joined samples.
  DataflashImuSeam seam;
  seam.a_kept = s.a_kept;
  seam.from_head = s.pushed;
  seam.from_b = b.series.size();
  seam.on_trial = s_on_trial;
  seam.a_last_dropped_t_s = s.a_last_dropped_t_s;
  seam.first_dropped_in_b = s.first_dropped;
  return seam;
}

void DataflashImuDecoder::Join(const DataflashImuSeam& seam, DataflashImuDecoded& a,
                               DataflashImuDecoded& b, const std::vector<DataflashImuRecord>& head,
                               const JobRunner& run_jobs) const {
  if (a.records == 0) {  // nothing before: b's samples as they are
    a = std::move(b);
    b = DataflashImuDecoded{};
    return;
  }
  ImuSeries& s = a.series;
  while (s.size() > seam.a_kept) PopBack(s);
  for (const std::size_t j : seam.from_head) {
    const DataflashImuRecord& r = head[j];
    s.t_s.push_back(r.t_s);
    s.acc.push_back(r.acc);
    if (has_gyr_) s.gyr.push_back(r.gyr);
    if (has_temp_) s.temp_c.push_back(r.temp_c);
  }
  AppendSamples(s, b.series, seam.from_b, run_jobs);  // b lacks the columns a lacks
  if (!a.first_dropped && seam.a_last_dropped_t_s) {
    a.first_dropped = DataflashDroppedRecord{a.records - 1, *seam.a_last_dropped_t_s};
  } else if (!a.first_dropped && seam.first_dropped_in_b) {
    a.first_dropped = DataflashDroppedRecord{a.records + seam.first_dropped_in_b->record,
                                             seam.first_dropped_in_b->t_s};
  }
  a.records += b.records;
  a.last_time = b.last_time;
  a.last_on_trial = seam.on_trial;
  b = DataflashImuDecoded{};
}

DataflashParser::DataflashParser(DataflashLog* log, const RecordFilter& filter,
                                 std::size_t size_hint)
    : log_(log), filter_(&filter), size_hint_(size_hint) {
  index_.fill(-1);
  decoder_of_.fill(-1);
  rows_.fill(0);
  AddType(DataflashFmtType(&log_->warnings));
}

void DataflashParser::Finish() {
  for (DataflashType& t : log_->types) t.rows = rows_[t.id];
  for (std::size_t id = 0; id < decoder_of_.size(); ++id) {
    if (decoder_of_[id] < 0) continue;
    decoders_[static_cast<std::size_t>(decoder_of_[id])].Finish(
        log_->types[static_cast<std::size_t>(index_[id])]);
  }
}

std::size_t DataflashParser::FeedTail(const std::uint8_t* data, std::size_t n,
                                      std::size_t offset, bool at_end, std::size_t i) {
  if (!at_end) return offset + i;
  const std::size_t tail = n - i;
  if (tail == 0) return offset + n;
  const bool header_prefix =
      data[i] == kDataflashHead1 && (tail == 1 || data[i + 1] == kDataflashHead2);
  if (header_prefix) {
    Truncated(tail);
  } else {
    for (std::size_t k = 0; k < tail; ++k) Skip(offset + i + k);
  }
  return offset + n;
}

DataflashParser DataflashParser::Ahead(DataflashLog* out, std::size_t bytes) const {
  DataflashParser ahead = *this;
  ahead.log_ = out;
  for (std::size_t id = 0; id < decoder_of_.size(); ++id) {  // samples of its bytes only
    if (decoder_of_[id] < 0) continue;
    const std::size_t length = std::max<std::size_t>(table_[id].length, 1);
    ahead.decoders_[static_cast<std::size_t>(decoder_of_[id])].BoundRows(bytes / length + 1);
  }
  ahead.rows_.fill(0);
  ahead.skip_end_ = 0;
  ahead.stopped_ = false;
  ahead.heads_.assign(decoders_.size(), DataflashImuHeads{});
  out->source = log_->source;
  out->types.clear();
  out->types.reserve(log_->types.size());
  for (const DataflashType& t : log_->types) {  // the definitions, without their records
    DataflashType d = t;
    d.rows = 0;
    d.bodies = RecordStore(t.body_size);
    d.imu.clear();
    out->types.push_back(std::move(d));
  }
  return ahead;
}

std::size_t DataflashParser::FindRecordChain(const std::uint8_t* data, std::size_t n,
                                             int records) const {
  for (std::size_t start = 0; start + kDataflashHeaderSize <= n; ++start) {
    std::size_t i = start;
    int found = 0;
    while (found < records && n - i >= kDataflashHeaderSize && data[i] == kDataflashHead1 &&
           data[i + 1] == kDataflashHead2) {
      const std::size_t length = table_[data[i + 2]].length;
      if (length == 0 || length > n - i) break;
      i += length;
      ++found;
    }
    if (found == records) return start;
  }
  return n;
}

bool DataflashParser::Absorb(const DataflashParser& ahead, DataflashLog& ahead_log,
                             const JobRunner& run_jobs) {
  // Every instance's seam first, so that one that cannot be joined changes nothing.
  struct Planned {
    std::size_t type = 0;      ///< index in the logs' types
    std::size_t decoder = 0;   ///< index in decoders_
    std::size_t instance = 0;
    DataflashImuSeam seam;
  };
  std::vector<Planned> planned;
  const DataflashImuDecoded none;
  for (std::size_t id = 0; id < decoder_of_.size(); ++id) {
    if (decoder_of_[id] < 0 || ahead.decoder_of_[id] < 0) continue;
    const auto type = static_cast<std::size_t>(index_[id]);
    const auto decoder = static_cast<std::size_t>(decoder_of_[id]);
    const DataflashType& a = log_->types[type];
    const DataflashType& b = ahead_log.types[type];
    for (std::size_t k = 0; k < b.imu.size(); ++k) {
      if (b.imu[k].records == 0) continue;
      const std::optional<DataflashImuSeam> seam = DataflashImuDecoder::PlanJoin(
          k < a.imu.size() ? a.imu[k] : none, b.imu[k], ahead.heads_[decoder][k]);
      if (!seam) return false;
      planned.push_back({type, decoder, k, *seam});
    }
  }
  for (const Planned& p : planned) {
    DataflashType& a = log_->types[p.type];
    if (p.instance >= a.imu.size()) a.imu.resize(p.instance + 1);
    decoders_[p.decoder].Join(p.seam, a.imu[p.instance], ahead_log.types[p.type].imu[p.instance],
                              ahead.heads_[p.decoder][p.instance], run_jobs);
  }
  for (std::size_t type = 0; type < ahead_log.types.size(); ++type) {
    log_->types[type].bodies.Append(ahead_log.types[type].bodies);
  }
  for (std::size_t id = 0; id < rows_.size(); ++id) rows_[id] += ahead.rows_[id];
  AbsorbWarnings(ahead_log.warnings, ahead.skip_end_);
  return true;
}

void DataflashParser::AbsorbWarnings(const DataflashWarnings& w, std::size_t skip_end) {
  // A parser made by Ahead counts skipped bytes and FMTs of the types it knows; it meets no
  // cut record and makes no type.
  DataflashWarnings& mine = log_->warnings;
  if (w.bytes_skipped > 0) {
    // Its first run goes on this parser's last when it starts where that one ended.
    const bool continued = mine.bytes_skipped > 0 && w.first_skip_offset == skip_end_;
    if (mine.bytes_skipped == 0) mine.first_skip_offset = w.first_skip_offset;
    mine.bytes_skipped += w.bytes_skipped;
    mine.skip_runs += w.skip_runs - (continued ? 1 : 0);
    skip_end_ = skip_end;
  }
  mine.fmt_conflicts += w.fmt_conflicts;
  mine.fmt_invalid += w.fmt_invalid;
}

void DataflashParser::AddType(DataflashType t, std::size_t offset) {
  t.bodies_kept = t.id == kDataflashFmtType || filter_->Keeps(t.name);
  if (t.id != kDataflashFmtType && filter_->Decodes(t.name) && t.length > 0) {
    const std::size_t rest = size_hint_ > offset ? size_hint_ - offset : 0;
    if (std::optional<DataflashImuDecoder> d = DataflashImuDecoder::For(t, rest / t.length + 1)) {
      t.imu_decoded = true;
      t.bodies_kept = false;
      decoder_of_[t.id] = static_cast<int>(decoders_.size());
      decoders_.push_back(*d);
    }
  }
  Entry& e = table_[t.id];
  e.length = static_cast<std::uint8_t>(t.length);  // 3..255 (AcceptFmt, one byte)
  e.action = t.id == kDataflashFmtType ? Action::kFmt
             : t.imu_decoded           ? Action::kDecode
             : t.bodies_kept           ? Action::kKeep
                                       : Action::kCount;
  index_[t.id] = static_cast<int>(log_->types.size());
  log_->types.push_back(std::move(t));
}

void DataflashParser::HandleFmt(const std::uint8_t* body, std::size_t body_size,
                                std::size_t offset) {
  if (body_size < kFmtBodySize) return;  // cannot happen with the built-in FMT
  const std::uint8_t id = body[kFmtTypeOffset];
  const std::size_t length = body[kFmtLengthOffset];
  const std::string name = FixedText(body + kFmtNameOffset, kFmtNameSize);
  const std::string format = FixedText(body + kFmtFormatOffset, kFmtFormatSize);
  const std::string columns = FixedText(body + kFmtColumnsOffset, kFmtColumnsSize);
  const int existing = index_[id];
  const DataflashType* known =
      existing >= 0 ? &log_->types[static_cast<std::size_t>(existing)] : nullptr;
  if (!AcceptFmt(known, length, name, format, &log_->warnings)) return;
  AddType(MakeDataflashType(id, length, name, format, columns, &log_->warnings), offset);
}

}  // namespace plumb::io::detail

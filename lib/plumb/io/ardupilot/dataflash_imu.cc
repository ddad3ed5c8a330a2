// plumb/io/ardupilot/dataflash_imu.cc — the IMU streams of a DataFlash log (IMU, ACC/GYR,
// ISBH/ISBD); see DataflashImuStreams in dataflash.h.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "plumb/core/error.h"
#include "plumb/io/ardupilot/ardupilot_correction.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/ardupilot/dataflash_format.h"

namespace plumb::io {
namespace {

using detail::DataflashInstanceMessage;

constexpr std::size_t kIsbdSamplesPerRecord = 32;  // ISBD x/y/z are int16[32] ('a')
constexpr int kIsbAccel = 0;                        // ISBH type: IMU_SENSOR_TYPE_ACCEL
constexpr int kIsbGyro = 1;                         // ISBH type: IMU_SENSOR_TYPE_GYRO
constexpr int kMaxInstances = 16;                   // instances probed by message name
constexpr double kIsbMaxCount = 65535;              // ISBH smp_cnt is a uint16

enum class Kind { kImu, kAccGyr, kAcc, kGyr, kIsbdAcc, kIsbdGyr };

/// A stream before its samples are read.
struct StreamRef {
  Kind kind = Kind::kImu;
  std::string name;  ///< stream name as listed
  int instance = 0;
};

std::string KindName(Kind kind) {
  switch (kind) {
    case Kind::kImu: return "IMU";
    case Kind::kAccGyr: return "ACC+GYR";
    case Kind::kAcc: return "ACC";
    case Kind::kGyr: return "GYR";
    case Kind::kIsbdAcc: return "ISBD_ACC";
    case Kind::kIsbdGyr: return "ISBD_GYR";
  }
  return "";
}

/// Column index or -1, without throwing.
int Col(const DataflashType& t, std::string_view name) { return t.ColumnIndex(name); }

double ValueAt(const DataflashType& t, std::size_t row, int col) {
  return t.Value(row, static_cast<std::size_t>(col));
}

/// Instances of a per-instance message: the distinct values of its I column (0..255), or
/// {0} / {} when it has no I column (defined / not defined).
std::vector<int> InstancesOf(const DataflashType& t, int instance_col) {
  std::array<bool, 256> seen{};
  if (t.imu_decoded) {  // the reader's instances: the same whole I values in 0..255
    std::vector<int> out;
    for (std::size_t k = 0; k < t.imu.size(); ++k) {
      if (t.imu[k].records > 0) out.push_back(static_cast<int>(k));
    }
    return out;
  }
  if (t.rows > 0 && !t.bodies_kept) ValueAt(t, 0, instance_col);  // throws: not kept
  const auto column = detail::DataflashColumnReader::Of(t, instance_col);
  for (std::size_t r = 0; r < t.rows; ++r) {
    const double v = column.Read(t.bodies.Row(r));
    if (v >= 0 && v < 256 && v == std::floor(v)) seen[static_cast<std::size_t>(v)] = true;
  }
  std::vector<int> out;
  for (int k = 0; k < 256; ++k) {
    if (seen[static_cast<std::size_t>(k)]) out.push_back(k);
  }
  return out;
}

/// Instances present for a per-instance kind (see DataflashInstanceMessage); `with_rows`
/// skips empty ones.
std::vector<int> InstancesFor(const DataflashLog& log, const std::string& base,
                              bool numbered_from_one, bool with_rows) {
  int col = -1;
  const DataflashType* t = DataflashInstanceMessage(log, base, 0, numbered_from_one, &col);
  if (t != nullptr && col >= 0) {
    std::vector<int> found = InstancesOf(*t, col);
    if (found.empty() && !with_rows) found.push_back(0);
    return found;
  }
  std::vector<int> out;
  for (int k = 0; k < kMaxInstances; ++k) {
    const DataflashType* m = DataflashInstanceMessage(log, base, k, numbered_from_one, &col);
    if (m != nullptr && (!with_rows || m->rows > 0)) out.push_back(k);
  }
  return out;
}

/// Indices of `times` kept by the reader's rule: finite, above the last kept time and below
/// the next time (one corrupted time stamp costs one sample).
std::vector<std::size_t> IncreasingIndices(const std::vector<double>& times) {
  std::vector<std::size_t> kept;
  kept.reserve(times.size());
  for (std::size_t i = 0; i < times.size(); ++i) {
    const double t = times[i];
    if (!std::isfinite(t) || (!kept.empty() && !(t > times[kept.back()]))) continue;
    if (i + 1 < times.size() && !(t < times[i + 1])) continue;
    kept.push_back(i);
  }
  return kept;
}

/// Samples of an ACC (`vector_prefix` "Acc") or GYR ("Gyr") message for one instance: time
/// from SampleUS (the sensor's sample time) when present, else TimeUS; empty when absent.
ImuSeries ReadRawMessage(const DataflashLog& log, const std::string& base, int instance,
                         const std::string& vector_prefix) {
  ImuSeries s;
  int instance_col = -1;
  const DataflashType* t = DataflashInstanceMessage(log, base, instance, true, &instance_col);
  if (t == nullptr) return s;
  int time = Col(*t, "SampleUS");
  if (time < 0) time = Col(*t, "TimeUS");
  const int axes[3] = {Col(*t, vector_prefix + "X"), Col(*t, vector_prefix + "Y"),
                       Col(*t, vector_prefix + "Z")};
  if (time < 0 || axes[0] < 0 || axes[1] < 0 || axes[2] < 0) return s;
  if (t->rows > 0 && !t->bodies_kept) ValueAt(*t, 0, time);  // throws: not kept
  using Reader = detail::DataflashColumnReader;
  const Reader inst = instance_col >= 0 ? Reader::Of(*t, instance_col) : Reader{};
  const Reader time_col = Reader::Of(*t, time);
  const Reader a[3] = {Reader::Of(*t, axes[0]), Reader::Of(*t, axes[1]), Reader::Of(*t, axes[2])};
  std::vector<const std::uint8_t*> rows;
  std::vector<double> times;
  for (std::size_t r = 0; r < t->rows; ++r) {
    const std::uint8_t* body = t->bodies.Row(r);
    if (instance_col >= 0 && inst.Read(body) != instance) continue;
    rows.push_back(body);
    times.push_back(time_col.Read(body) * 1e-6);
  }
  std::vector<Vec3f>& out = vector_prefix == "Acc" ? s.acc : s.gyr;
  for (std::size_t i : IncreasingIndices(times)) {
    s.t_s.push_back(times[i]);
    out.emplace_back(static_cast<float>(a[0].Read(rows[i])), static_cast<float>(a[1].Read(rows[i])),
                     static_cast<float>(a[2].Read(rows[i])));
  }
  return s;
}

/// ACC and GYR of one instance paired sample by sample (see DataflashImuStreams), or empty.
ImuSeries PairAccGyr(const ImuSeries& acc, const ImuSeries& gyr) {
  ImuSeries s;
  if (acc.size() < 2 || acc.size() != gyr.size()) return s;
  const double half_dt_s = 0.5 * gyr.median_dt_s();
  for (std::size_t i = 0; i < acc.size(); ++i) {
    if (!(std::abs(acc.t_s[i] - gyr.t_s[i]) < half_dt_s)) return s;
  }
  s.t_s = acc.t_s;
  s.acc = acc.acc;
  s.gyr = gyr.gyr;
  return s;
}

/// One ISBH batch header.
struct IsbHeader {
  double n = 0;            ///< batch sequence number (ISBH.N = ISBD.N)
  double time_us = 0;      ///< when the header was written, us
  int sensor = -1;         ///< 0 accelerometer, 1 gyroscope
  int instance = 0;        ///< sensor instance
  double multiplier = 0;   ///< stored int16 = value * multiplier
  std::size_t count = 0;   ///< samples in the batch
  double sample_us = 0;    ///< time of the batch's first sample, us
  double rate_hz = 0;      ///< sample rate, Hz
};

std::vector<IsbHeader> ReadIsbHeaders(const DataflashLog& log) {
  std::vector<IsbHeader> out;
  const DataflashType* h = log.Find("ISBH");
  if (h == nullptr) return out;
  const int c_n = Col(*h, "N"), c_time = Col(*h, "TimeUS"), c_type = Col(*h, "type"),
            c_inst = Col(*h, "instance"), c_mul = Col(*h, "mul"), c_cnt = Col(*h, "smp_cnt"),
            c_us = Col(*h, "SampleUS"), c_rate = Col(*h, "smp_rate");
  if (std::min({c_n, c_time, c_type, c_inst, c_mul, c_cnt, c_us, c_rate}) < 0) return out;
  for (std::size_t r = 0; r < h->rows; ++r) {
    IsbHeader b;
    b.n = ValueAt(*h, r, c_n);
    b.time_us = ValueAt(*h, r, c_time);
    const double sensor = ValueAt(*h, r, c_type);
    const double instance = ValueAt(*h, r, c_inst);
    const double count = ValueAt(*h, r, c_cnt);
    b.multiplier = ValueAt(*h, r, c_mul);
    b.sample_us = ValueAt(*h, r, c_us);
    b.rate_hz = ValueAt(*h, r, c_rate);
    const bool usable = (sensor == kIsbAccel || sensor == kIsbGyro) && instance >= 0 &&
                        instance < 256 && instance == std::floor(instance) && count >= 1 &&
                        count <= kIsbMaxCount && b.multiplier > 0 && std::isfinite(b.rate_hz) &&
                        b.rate_hz > 0 && std::isfinite(b.sample_us) && std::isfinite(b.n) &&
                        std::isfinite(b.time_us);
    if (!usable) continue;
    b.sensor = static_cast<int>(sensor);
    b.instance = static_cast<int>(instance);
    b.count = static_cast<std::size_t>(count);
    out.push_back(b);
  }
  return out;
}

/// The samples of every ISBH batch of (sensor, instance), from the ISBD records: a record
/// belongs to the latest header with its N written at or before it.
ImuSeries ReadIsbd(const DataflashLog& log, int sensor, int instance) {
  ImuSeries s;
  const std::vector<IsbHeader> headers = ReadIsbHeaders(log);
  const DataflashType* d = log.Find("ISBD");
  if (headers.empty() || d == nullptr) return s;
  const int c_n = Col(*d, "N"), c_time = Col(*d, "TimeUS"), c_seq = Col(*d, "seqno"),
            c_x = Col(*d, "x"), c_y = Col(*d, "y"), c_z = Col(*d, "z");
  if (std::min({c_n, c_time, c_seq, c_x, c_y, c_z}) < 0) return s;
  std::map<double, std::vector<std::size_t>> by_n;  // batch number -> headers, log order
  for (std::size_t h = 0; h < headers.size(); ++h) by_n[headers[h].n].push_back(h);
  // Per header: the samples by index in the batch (absent ones stay missing).
  std::vector<std::map<std::size_t, Vec3f>> batches(headers.size());
  for (std::size_t r = 0; r < d->rows; ++r) {
    const double n = ValueAt(*d, r, c_n);
    if (!std::isfinite(n)) continue;
    const auto candidates = by_n.find(n);
    if (candidates == by_n.end()) continue;
    const double time_us = ValueAt(*d, r, c_time);
    std::size_t best = headers.size();
    for (std::size_t h : candidates->second) {
      if (headers[h].time_us <= time_us) best = h;
    }
    if (best == headers.size()) continue;
    const IsbHeader& head = headers[best];
    if (head.sensor != sensor || head.instance != instance) continue;
    const double seq = ValueAt(*d, r, c_seq);
    if (!(seq >= 0) || seq * kIsbdSamplesPerRecord >= static_cast<double>(head.count)) continue;
    const auto x = d->Array(r, static_cast<std::size_t>(c_x));
    const auto y = d->Array(r, static_cast<std::size_t>(c_y));
    const auto z = d->Array(r, static_cast<std::size_t>(c_z));
    const auto first = static_cast<std::size_t>(seq) * kIsbdSamplesPerRecord;
    const auto m = static_cast<float>(head.multiplier);
    for (std::size_t k = 0; k < kIsbdSamplesPerRecord && first + k < head.count; ++k) {
      batches[best][first + k] = Vec3f(x[k] / m, y[k] / m, z[k] / m);
    }
  }
  std::vector<double> times;
  std::vector<Vec3f> values;
  for (std::size_t h = 0; h < headers.size(); ++h) {
    for (const auto& [j, value] : batches[h]) {
      times.push_back(headers[h].sample_us * 1e-6 + static_cast<double>(j) / headers[h].rate_hz);
      values.push_back(value);
    }
  }
  std::vector<Vec3f>& out = sensor == kIsbAccel ? s.acc : s.gyr;
  for (std::size_t i : IncreasingIndices(times)) {
    s.t_s.push_back(times[i]);
    out.push_back(values[i]);
  }
  return s;
}

/// The samples of a stream as logged (gyroscope-only streams have an empty acc).
ImuSeries ReadStream(const DataflashLog& log, const StreamRef& ref) {
  switch (ref.kind) {
    case Kind::kImu: return ImuFromDataflash(log, ref.instance);
    case Kind::kAcc: return ReadRawMessage(log, "ACC", ref.instance, "Acc");
    case Kind::kGyr: return ReadRawMessage(log, "GYR", ref.instance, "Gyr");
    case Kind::kAccGyr:
      return PairAccGyr(ReadRawMessage(log, "ACC", ref.instance, "Acc"),
                        ReadRawMessage(log, "GYR", ref.instance, "Gyr"));
    case Kind::kIsbdAcc: return ReadIsbd(log, kIsbAccel, ref.instance);
    case Kind::kIsbdGyr: return ReadIsbd(log, kIsbGyro, ref.instance);
  }
  return {};
}

/// Every stream of the log, before reading samples, in listing order.
std::vector<StreamRef> StreamRefs(const DataflashLog& log) {
  std::map<int, std::vector<StreamRef>> by_instance;
  const auto add = [&](Kind kind, int instance, const std::string& name) {
    by_instance[instance].push_back({kind, name, instance});
  };
  for (int k : InstancesFor(log, "IMU", false, false)) {
    int col = -1;
    const DataflashType* t = DataflashInstanceMessage(log, "IMU", k, false, &col);
    add(Kind::kImu, k, t != nullptr ? t->name : "IMU");
  }
  const std::vector<int> acc = InstancesFor(log, "ACC", true, true);
  const std::vector<int> gyr = InstancesFor(log, "GYR", true, true);
  for (int k : acc) {
    const bool both = std::find(gyr.begin(), gyr.end(), k) != gyr.end();
    if (both && !ReadStream(log, {Kind::kAccGyr, "ACC+GYR", k}).empty()) {
      add(Kind::kAccGyr, k, "ACC+GYR");
    }
    add(Kind::kAcc, k, "ACC");
  }
  for (int k : gyr) add(Kind::kGyr, k, "GYR");
  std::set<std::pair<int, int>> batches;  // (instance, sensor)
  for (const IsbHeader& h : ReadIsbHeaders(log)) {
    if (h.sensor == kIsbAccel || h.sensor == kIsbGyro) batches.insert({h.instance, h.sensor});
  }
  for (const auto& [instance, sensor] : batches) {
    add(sensor == kIsbAccel ? Kind::kIsbdAcc : Kind::kIsbdGyr, instance,
        sensor == kIsbAccel ? "ISBD_ACC" : "ISBD_GYR");
  }
  std::vector<StreamRef> out;
  for (auto& [instance, refs] : by_instance) {
    std::stable_sort(refs.begin(), refs.end(),
                     [](const StreamRef& a, const StreamRef& b) { return a.kind < b.kind; });
    out.insert(out.end(), refs.begin(), refs.end());
  }
  return out;
}

/// The nominal rate of the batches of an ISBD stream (median of their smp_rate), Hz.
double IsbdRate(const DataflashLog& log, int sensor, int instance) {
  std::vector<double> rates;
  for (const IsbHeader& h : ReadIsbHeaders(log)) {
    if (h.sensor == sensor && h.instance == instance) rates.push_back(h.rate_hz);
  }
  if (rates.empty()) return 0.0;
  std::nth_element(rates.begin(), rates.begin() + static_cast<std::ptrdiff_t>(rates.size() / 2),
                   rates.end());
  return rates[rates.size() / 2];
}

/// The description of the stream `ref` whose samples are `s` (as ReadStream gives them).
ImuStreamInfo Describe(const DataflashLog& log, const StreamRef& ref, const ImuSeries& s) {
  ImuStreamInfo info;
  info.name = ref.name;
  info.instance = ref.instance;
  info.samples = s.size();
  // An IMU message's records left out by their times (ImuFromDataflash); the other streams
  // are paired or batched, and say nothing of it.
  info.records = ref.kind == Kind::kImu ? std::max(s.size(), DataflashImuRecords(log, ref.instance))
                                        : s.size();
  if (info.records > info.samples) {
    info.first_left_out_t_s = DataflashImuFirstDropped(log, ref.instance);
  }
  if (!s.empty()) {
    info.t_start_s = s.t_s.front();
    info.t_end_s = s.t_s.back();
  }
  if (ref.kind == Kind::kIsbdAcc || ref.kind == Kind::kIsbdGyr) {
    info.rate_hz = IsbdRate(log, ref.kind == Kind::kIsbdAcc ? kIsbAccel : kIsbGyro, ref.instance);
  } else if (s.size() >= 2 && s.duration_s() > 0.0) {
    info.rate_hz = static_cast<double>(s.size() - 1) / s.duration_s();
  }
  info.has_accel = ref.kind != Kind::kGyr && ref.kind != Kind::kIsbdGyr;
  info.has_gyro = ref.kind == Kind::kImu ? s.has_gyro() || s.empty()
                                         : ref.kind != Kind::kAcc && ref.kind != Kind::kIsbdAcc;
  info.has_temperature = s.has_temperature();
  const ArdupilotCorrection correction = ArdupilotCorrectionFor(log.params, ref.instance);
  info.applied = correction.Describe(info.has_accel, info.has_gyro);
  info.undoable = correction.Undoable(info.has_accel, info.has_gyro, info.has_temperature);
  return info;
}

/// The samples the reader decoded for IMU stream `ref` (DataflashType::imu), or nullptr when
/// it did not (they are then read from bodies).
const ImuSeries* DecodedImu(const DataflashLog& log, const StreamRef& ref) {
  return ref.kind == Kind::kImu ? DecodedDataflashImu(log, ref.instance) : nullptr;
}

ImuStreamInfo Describe(const DataflashLog& log, const StreamRef& ref) {
  if (const ImuSeries* decoded = DecodedImu(log, ref)) return Describe(log, ref, *decoded);
  ImuSeries s;
  try {
    s = ReadStream(log, ref);
  } catch (const InputError&) {
    // An IMU FMT without rows (or without time/Acc columns): listed with 0 samples.
  }
  return Describe(log, ref, s);
}

/// True when the stream `ref` has samples; they are then in `*samples`.
bool HasSamples(const DataflashLog& log, const StreamRef& ref, ImuSeries* samples) {
  try {
    *samples = ReadStream(log, ref);
    return !samples->empty();
  } catch (const InputError&) {
    return false;  // e.g. an IMU FMT without rows
  }
}

/// The stream `selection` names, or nullopt (see DataflashStream for the default). When the
/// choice read the stream's samples, they are in `*samples` and `*read` is true.
std::optional<StreamRef> Select(const DataflashLog& log, const FlightLogSelection& selection,
                                ImuSeries* samples, bool* read) {
  *read = false;
  const std::vector<StreamRef> refs = StreamRefs(log);
  if (selection.stream.empty()) {
    std::optional<StreamRef> first;
    for (const StreamRef& r : refs) {
      if (r.instance != selection.imu || r.kind == Kind::kGyr || r.kind == Kind::kIsbdGyr) {
        continue;
      }
      if (!first) first = r;
      if (HasSamples(log, r, samples)) {
        *read = true;
        return r;
      }
    }
    return first;
  }
  std::vector<StreamRef> by_name;
  for (const StreamRef& r : refs) {
    if (r.name != selection.stream && KindName(r.kind) != selection.stream) continue;
    if (r.instance == selection.imu) return r;
    by_name.push_back(r);
  }
  // "IMU2" names its instance by itself.
  if (by_name.size() == 1 && by_name.front().name != KindName(by_name.front().kind)) {
    return by_name.front();
  }
  return std::nullopt;
}

std::string StreamLabel(const FlightLogSelection& selection) {
  return (selection.stream.empty() ? std::string("default stream") : selection.stream) +
         " of IMU instance " + std::to_string(selection.imu);
}

}  // namespace

std::vector<ImuStreamInfo> DataflashImuStreams(const DataflashLog& log) {
  std::vector<ImuStreamInfo> out;
  for (const StreamRef& ref : StreamRefs(log)) out.push_back(Describe(log, ref));
  return out;
}

std::optional<ImuStreamInfo> FindDataflashStream(const DataflashLog& log,
                                                 const FlightLogSelection& selection) {
  ImuSeries samples;
  bool read = false;
  const std::optional<StreamRef> ref = Select(log, selection, &samples, &read);
  if (!ref) return std::nullopt;
  return read ? Describe(log, *ref, samples) : Describe(log, *ref);
}

ImuSeries DataflashStream(const DataflashLog& log, const FlightLogSelection& selection,
                          ImuStreamInfo* info) {
  ImuSeries all;
  bool read = false;
  const std::optional<StreamRef> ref = Select(log, selection, &all, &read);
  const std::string label = StreamLabel(selection);
  if (!ref) {
    std::string known;
    for (const StreamRef& r : StreamRefs(log)) {
      known += (known.empty() ? "" : ", ") + r.name + "/" + std::to_string(r.instance);
    }
    throw InputError(log.source, "", "no " + label + " (streams/instances in the log: " +
                                         (known.empty() ? "none" : known) + ")");
  }
  if (ref->kind == Kind::kGyr || ref->kind == Kind::kIsbdGyr) {
    throw InputError(log.source, "",
                     ref->name + " of IMU instance " + std::to_string(ref->instance) +
                         " carries gyroscope samples only; plumb needs accelerometer samples: "
                         "select IMU, ACC+GYR or ACC of that instance");
  }
  if (!read) all = ReadStream(log, *ref);  // the samples once, for the session and `info`
  if (all.empty()) {
    throw InputError(log.source, "", ref->name + " of IMU instance " +
                                         std::to_string(ref->instance) + " has no samples");
  }
  if (info != nullptr) *info = Describe(log, *ref, all);
  ImuSeries s = WindowOf(all, selection);
  if (s.empty()) {
    throw InputError(log.source, "", "no samples of " + ref->name + " of IMU instance " +
                                         std::to_string(ref->instance) +
                                         " in the time window");
  }
  return s;
}

}  // namespace plumb::io

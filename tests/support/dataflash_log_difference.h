// tests/support/dataflash_log_difference.h — the first difference between two decoded DataFlash
// logs, or none: every type's definition, record count, kept bodies and decoded IMU samples
// (with the reader's state), the parameters, the warnings. For tests and the differential fuzz
// target of the two-part read (tests/fuzz/dataflash_two_part_fuzz.cc), which must find the log
// read in two parts the same as read in one.
#pragma once

#include <string>

#include "plumb/io/ardupilot/dataflash.h"
#include "imu_series_difference.h"

namespace plumb::testing {

inline std::string DataflashWarningsDifference(const io::DataflashWarnings& a,
                                               const io::DataflashWarnings& b) {
  if (a.Describe() != b.Describe()) return "warnings' text";
  if (a.bytes_skipped != b.bytes_skipped || a.skip_runs != b.skip_runs ||
      a.first_skip_offset != b.first_skip_offset) {
    return "skipped bytes";
  }
  if (a.truncated_records != b.truncated_records || a.truncated_bytes != b.truncated_bytes) {
    return "truncated record";
  }
  if (a.fmt_conflicts != b.fmt_conflicts || a.fmt_invalid != b.fmt_invalid ||
      a.fmt_length_mismatches != b.fmt_length_mismatches ||
      a.fmt_unknown_chars != b.fmt_unknown_chars) {
    return "FMT warnings";
  }
  return "";
}

/// "" when `a` and `b` are the same log; else what differs first.
inline std::string DataflashLogDifference(const io::DataflashLog& a, const io::DataflashLog& b) {
  if (a.size_bytes != b.size_bytes) return "size";
  if (a.types.size() != b.types.size()) return "number of types";
  for (std::size_t k = 0; k < a.types.size(); ++k) {
    const io::DataflashType& s = a.types[k];
    const io::DataflashType& t = b.types[k];
    const std::string where = "type " + s.name + ": ";
    if (s.id != t.id || s.name != t.name || s.length != t.length || s.format != t.format) {
      return where + "definition";
    }
    if (s.rows != t.rows) {
      return where + "rows " + std::to_string(s.rows) + " != " + std::to_string(t.rows);
    }
    if (!(s.bodies == t.bodies)) return where + "bodies";
    if (s.bodies_kept != t.bodies_kept || s.imu_decoded != t.imu_decoded) return where + "kept";
    if (s.imu.size() != t.imu.size()) return where + "IMU instances";
    for (std::size_t i = 0; i < s.imu.size(); ++i) {
      const io::DataflashImuDecoded& x = s.imu[i];
      const io::DataflashImuDecoded& y = t.imu[i];
      const std::string instance = where + "instance " + std::to_string(i) + ": ";
      if (x.records != y.records) return instance + "records";
      if (!SameDoubles(x.first_time, y.first_time) || !SameDoubles(x.last_time, y.last_time)) {
        return instance + "first or last time";
      }
      if (x.last_on_trial != y.last_on_trial) return instance + "last sample's state";
      if (x.first_dropped.has_value() != y.first_dropped.has_value() ||
          (x.first_dropped && (x.first_dropped->record != y.first_dropped->record ||
                               !SameDoubles(x.first_dropped->t_s, y.first_dropped->t_s)))) {
        return instance + "first record left out";
      }
      if (const std::string d = ImuSeriesDifference(x.series, y.series); !d.empty()) {
        return instance + d;
      }
    }
  }
  if (a.params.size() != b.params.size()) return "number of parameters";
  for (const auto& [name, value] : a.params) {
    const auto other = b.params.find(name);
    if (other == b.params.end()) return "parameter " + name;
    if (!SameDoubles(value, other->second)) return "value of parameter " + name;
  }
  return DataflashWarningsDifference(a.warnings, b.warnings);
}

}  // namespace plumb::testing

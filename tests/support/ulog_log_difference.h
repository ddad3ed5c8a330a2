// tests/support/ulog_log_difference.h — the first difference between two decoded ULogs, or
// none: the header and flags, formats, every subscription's definition, message count, last
// timestamp, kept bodies and decoded IMU samples, info, parameters and their changes, texts,
// sync and dropout counts, the warnings. For tests and the differential fuzz target of the
// two-part read (tests/fuzz/ulog_two_part_fuzz.cc), which must find the log read in two parts
// the same as read in one.
#pragma once

#include <cstring>
#include <string>

#include "plumb/io/px4/ulog.h"
#include "imu_series_difference.h"

namespace plumb::testing {

inline std::string ULogWarningsDifference(const io::ULogWarnings& a, const io::ULogWarnings& b) {
  if (a.Describe() != b.Describe()) return "warnings' text";
  if (a.bytes_skipped != b.bytes_skipped || a.skip_runs != b.skip_runs ||
      a.first_skip_offset != b.first_skip_offset) {
    return "skipped bytes";
  }
  if (a.truncated_records != b.truncated_records || a.truncated_bytes != b.truncated_bytes) {
    return "truncated messages";
  }
  if (a.unknown_msg_id_messages != b.unknown_msg_id_messages ||
      a.unknown_type_messages != b.unknown_type_messages ||
      a.malformed_messages != b.malformed_messages ||
      a.unresolved_subscriptions != b.unresolved_subscriptions ||
      a.bad_appended_offsets != b.bad_appended_offsets || a.unknown_version != b.unknown_version) {
    return "message warnings";
  }
  return "";
}

/// "" when the subscriptions `s` and `t` are the same, with the same messages; else what
/// differs first.
inline std::string ULogTopicDifference(const io::ULogTopic& s, const io::ULogTopic& t) {
  const std::string where = "topic " + s.name + "/" + std::to_string(s.multi_id) + ": ";
  if (s.name != t.name || s.multi_id != t.multi_id || s.msg_id != t.msg_id ||
      s.body_size != t.body_size || s.full_size != t.full_size ||
      s.timestamp_col != t.timestamp_col || s.columns.size() != t.columns.size()) {
    return where + "definition";
  }
  for (std::size_t c = 0; c < s.columns.size(); ++c) {
    if (s.columns[c].name != t.columns[c].name || s.columns[c].type != t.columns[c].type ||
        s.columns[c].offset != t.columns[c].offset) {
      return where + "column " + s.columns[c].name;
    }
  }
  if (s.rows != t.rows) {
    return where + "rows " + std::to_string(s.rows) + " != " + std::to_string(t.rows);
  }
  if (s.last_timestamp_us != t.last_timestamp_us) return where + "last timestamp";
  if (s.bodies_kept != t.bodies_kept || s.imu_decoded != t.imu_decoded) return where + "kept";
  if (!(s.bodies == t.bodies)) return where + "bodies";
  if (const std::string d = ImuSeriesDifference(s.imu, t.imu); !d.empty()) return where + d;
  return "";
}

/// "" when `a` and `b` are the same log; else what differs first.
inline std::string ULogDifference(const io::ULog& a, const io::ULog& b) {
  if (a.size_bytes != b.size_bytes) return "size";
  if (a.version != b.version || a.start_timestamp_us != b.start_timestamp_us) return "header";
  if (a.compat_flags != b.compat_flags || a.incompat_flags != b.incompat_flags ||
      a.data_appended != b.data_appended || a.appended_offsets != b.appended_offsets) {
    return "flag bits";
  }
  if (a.formats.size() != b.formats.size()) return "number of formats";
  for (const auto& [name, fields] : a.formats) {
    const auto other = b.formats.find(name);
    if (other == b.formats.end() || other->second.size() != fields.size()) {
      return "format " + name;
    }
    for (std::size_t k = 0; k < fields.size(); ++k) {
      const io::ULogFormatField& f = fields[k];
      const io::ULogFormatField& g = other->second[k];
      if (f.type != g.type || f.count != g.count || f.is_array != g.is_array || f.name != g.name) {
        return "format " + name + " field " + f.name;
      }
    }
  }
  if (a.topics.size() != b.topics.size()) return "number of topics";
  for (std::size_t k = 0; k < a.topics.size(); ++k) {
    if (std::string d = ULogTopicDifference(a.topics[k], b.topics[k]); !d.empty()) return d;
  }
  if (a.info != b.info || a.info_multiple != b.info_multiple) return "info";
  if (a.params.size() != b.params.size()) return "number of parameters";
  for (const auto& [name, value] : a.params) {
    const auto other = b.params.find(name);
    if (other == b.params.end() || !SameDoubles(value, other->second)) return "parameter " + name;
  }
  if (a.param_changes.size() != b.param_changes.size()) return "number of parameter changes";
  for (std::size_t k = 0; k < a.param_changes.size(); ++k) {
    const io::ULogParamChange& p = a.param_changes[k];
    const io::ULogParamChange& q = b.param_changes[k];
    if (p.timestamp_us != q.timestamp_us || p.name != q.name || !SameDoubles(p.value, q.value)) {
      return "parameter change " + std::to_string(k);
    }
  }
  if (a.default_params.size() != b.default_params.size()) return "number of default parameters";
  for (std::size_t k = 0; k < a.default_params.size(); ++k) {
    const io::ULogDefaultParam& p = a.default_params[k];
    const io::ULogDefaultParam& q = b.default_params[k];
    if (p.name != q.name || !SameDoubles(p.value, q.value) || p.default_types != q.default_types) {
      return "default parameter " + std::to_string(k);
    }
  }
  if (a.texts.size() != b.texts.size()) return "number of texts";
  for (std::size_t k = 0; k < a.texts.size(); ++k) {
    const io::ULogText& p = a.texts[k];
    const io::ULogText& q = b.texts[k];
    if (p.level != q.level || p.tag != q.tag || p.timestamp_us != q.timestamp_us ||
        p.text != q.text) {
      return "text " + std::to_string(k);
    }
  }
  if (a.dropouts != b.dropouts || a.dropout_total_ms != b.dropout_total_ms) return "dropouts";
  if (a.sync_messages != b.sync_messages) return "sync messages";
  return ULogWarningsDifference(a.warnings, b.warnings);
}

}  // namespace plumb::testing

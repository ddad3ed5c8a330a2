// plumb/io/px4/ulog_combined.h — INTERNAL to plumb::io_px4: sensor_combined's IMU samples
// decoded inside the ULog parser's pass (ULogCombinedDecoder; the parser, ulog_parser.h, is its
// user), as the PX4 session reads them from kept bodies. Not part of the public interface.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "plumb/core/imu_series.h"
#include "plumb/io/common/log_common.h"
#include "plumb/io/px4/ulog.h"

namespace plumb::io::detail {

/// Decodes sensor_combined's IMU samples inside the reader's pass (RecordFilter::decode), as
/// the PX4 session reads them from bodies (px4_session.cc, FromCombined): t_s = timestamp *
/// 1e-6, accelerometer_m_s2[0..2] and gyro_rad[0..2] (or gyro_rad_s) saturated to float,
/// every message's sample in order (KeepIncreasingTimes leaves out bad times once the whole
/// log is read: a spike is told only by the message after it).
class ULogCombinedDecoder {
 public:
  /// The decoder of `t`, or nullopt when `t` is not sensor_combined or lacks a column.
  static std::optional<ULogCombinedDecoder> For(const ULogTopic& t) {
    if (t.name != "sensor_combined" || t.timestamp_col < 0) return std::nullopt;
    ULogCombinedDecoder d;
    d.time_ = t.columns[static_cast<std::size_t>(t.timestamp_col)];
    if (!Triad(t, "accelerometer_m_s2", d.acc_) ||
        (!Triad(t, "gyro_rad", d.gyr_) && !Triad(t, "gyro_rad_s", d.gyr_))) {
      return std::nullopt;
    }
    const auto is_float = [](const ULogColumn* c) {
      return c[0].type == ULogType::kFloat && c[1].type == ULogType::kFloat &&
             c[2].type == ULogType::kFloat;
    };
    d.float_triads_ = is_float(d.acc_) && is_float(d.gyr_);
    return d;
  }

  /// Decodes the message body `body` (after the msg_id) into `s`.
  void Add(ImuSeries& s, const std::uint8_t* body) const {
    s.t_s.push_back(DecodeULogValue(body + time_.offset, time_.type) * 1e-6);
    s.acc.push_back(Triad3(body, acc_));
    s.gyr.push_back(Triad3(body, gyr_));
  }

  /// Reserves `rows` samples of `s`, backed by huge pages where large.
  static void Reserve(ImuSeries& s, std::size_t rows) {
    ReserveHugePages(s.t_s, rows);
    ReserveHugePages(s.acc, rows);
    ReserveHugePages(s.gyr, rows);
  }

 private:
  static bool Triad(const ULogTopic& t, const std::string& base, ULogColumn* out) {
    for (int i = 0; i < 3; ++i) {
      const int c = t.ColumnIndex(base + "[" + std::to_string(i) + "]");
      if (c < 0) return false;
      out[i] = t.columns[static_cast<std::size_t>(c)];
    }
    return true;
  }

  static Vec3f Read3(const std::uint8_t* body, const ULogColumn* c) {
    return SaturatedFloat(Vec3(DecodeULogValue(body + c[0].offset, c[0].type),
                               DecodeULogValue(body + c[1].offset, c[1].type),
                               DecodeULogValue(body + c[2].offset, c[2].type)));
  }

  /// Read3, or (float_triads_, the usual float[3] fields) the stored floats themselves: the
  /// same values without the decoding switch and the round trip through double.
  Vec3f Triad3(const std::uint8_t* body, const ULogColumn* c) const {
    if (!float_triads_) return Read3(body, c);
    return Vec3f(LoadLittleEndian<float>(body + c[0].offset),
                 LoadLittleEndian<float>(body + c[1].offset),
                 LoadLittleEndian<float>(body + c[2].offset));
  }

  ULogColumn time_, acc_[3], gyr_[3];
  bool float_triads_ = false;  ///< every accelerometer and gyroscope field is a float
};

}  // namespace plumb::io::detail

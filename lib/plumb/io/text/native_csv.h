// plumb/io/text/native_csv.h — plumb's native CSV (SPEC section 6).
//
// Layout: one header line, then one sample per line, comma-separated, SI units, body frame FRD:
//
//   time_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z[,temp_c]     (accelerometer and gyroscope)
//   time_s,acc_x,acc_y,acc_z[,temp_c]                       (accelerometer only)
//
// time_s in seconds (any origin, strictly increasing), acc_* in m/s^2, gyr_* in rad/s, temp_c
// in degC. The board's other IMUs (SPEC 6, "Several IMUs of one board") follow on the same time
// column, IMU k (k = 1, 2, ...) as acc{k}_x,acc{k}_y,acc{k}_z[,gyr{k}_x,gyr{k}_y,gyr{k}_z]
// [,temp{k}_c]. The reader finds the columns by name (order free; other columns are ignored, '#'
// comment lines and blank lines skipped). The writer prints times with the shortest text
// that reads back as the same double and samples with 9 significant digits (%.9g), which
// reads back as the same float: a written session reads back bit for bit.
#pragma once

#include <string>

#include "plumb/core/session.h"
#include "plumb/io/text/text_table.h"

namespace plumb::io {

/// The TextTableOptions that describe the native layout, e.g. to read it with
/// `allow_nan_rows` set: `auto o = NativeCsvOptions(); o.allow_nan_rows = true;
/// ReadTextTable(path, o);`.
TextTableOptions NativeCsvOptions();

/// Reads a native CSV, with the board's other IMUs in Session::other_imus (instance k, name
/// "acc{k}_x..") when the header has their columns (k from 1 up, until one is missing). Errors
/// (plumb::InputError) name the file, the line and what was expected: missing or empty file,
/// wrong header, non-numeric, NaN or infinite fields, short rows, times that do not increase.
Session ReadNativeCsv(const std::string& path);

/// Writes `session.series` as native CSV, atomically (temporary file, then rename), and the
/// board's other IMUs after it (other_imus[i] as IMU i + 1). Writes the gyroscope and
/// temperature columns when a series has them. Throws plumb::Error naming `path` when a series
/// is inconsistent (array sizes differ), another IMU's stamps are not IMU 0's (the format has one
/// time column) or the file cannot be written. Segments, site and warnings are not part of the
/// format.
void WriteNativeCsv(const std::string& path, const Session& session);

}  // namespace plumb::io

// plumb/io/text/native_csv.h — plumb's native CSV (SPEC section 6).
//
// Layout: one header line, then one sample per line, comma-separated, SI units, body frame FRD:
//
//   time_s,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z[,temp_c]     (accelerometer and gyroscope)
//   time_s,acc_x,acc_y,acc_z[,temp_c]                       (accelerometer only)
//
// time_s in seconds (any origin, strictly increasing), acc_* in m/s^2, gyr_* in rad/s, temp_c
// in degC. The reader finds the columns by name (order free; other columns are ignored, '#'
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

/// Reads a native CSV. Errors (plumb::InputError) name the file, the line and what was
/// expected: missing or empty file, wrong header, non-numeric, NaN or infinite fields,
/// short rows, times that do not increase.
Session ReadNativeCsv(const std::string& path);

/// Writes `session.series` as native CSV, atomically (temporary file, then rename). Writes the
/// gyroscope and temperature columns when the series has them. Throws plumb::Error naming
/// `path` when the series is inconsistent (array sizes differ) or the file cannot be written.
/// Segments, site and warnings are not part of the format.
void WriteNativeCsv(const std::string& path, const Session& session);

}  // namespace plumb::io

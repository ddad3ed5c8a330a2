// plumb/io/input/array_session.h — a session from samples a program already holds (arrays of
// numbers, a data frame's columns) instead of a file: the same checks a reader makes (finite
// values, strictly increasing times, at least two samples), the units turned into SI as a text
// table's are, NaN rows dropped on request with the reader's warning. The front end names the
// arguments (the Python module its keywords) and says how it counts rows, so that an error
// reads in its words: "arrays:acc row 3: NaN or infinite value ... (to skip such rows:
// drop_nan=True)".
//
//   ArraySamples a;  a.n = n;  a.time = t;  a.acc = acc;  a.gyr = gyr;  // row-major n x 3
//   Session s = SessionFromArrays(a, ArrayNames{});
#pragma once

#include <cstddef>
#include <string>

#include "plumb/core/session.h"
#include "plumb/io/input/open_inputs.h"

namespace plumb::io {

/// The samples, each array row-major, n rows; the front end keeps them alive for the call.
struct ArraySamples {
  std::size_t n = 0;
  const double* time = nullptr;  ///< n times, s
  const double* acc = nullptr;   ///< n x 3 accelerometer values, in acc_unit
  const double* gyr = nullptr;   ///< n x 3 gyroscope values, in gyr_unit; nullptr: none
  const double* temp = nullptr;  ///< n temperatures, degC; nullptr: none
  AccUnit acc_unit = AccUnit::kMetersPerSecond2;
  GyrUnit gyr_unit = GyrUnit::kRadiansPerSecond;
  /// Drop rows holding NaN or infinite values (said in a nan_rows_skipped warning) instead of
  /// failing (InputOptions::drop_nan_rows).
  bool drop_nan_rows = false;
  /// The session's source, as errors and reports name it (e.g. "arrays").
  std::string source = "arrays";
};

/// How the front end names the arrays and counts their rows in messages.
struct ArrayNames {
  std::string time = "time", acc = "acc", gyr = "gyr", temp = "temp";
  std::size_t first_row = 0;  ///< the number of the first row (0 in Python, 1 for a table)
};

/// The session of `samples` (series, source, warnings). Throws InputError (file: the source;
/// where: "<name> row R") for a NaN or infinite value (unless drop_nan_rows), a time that does
/// not increase, or fewer than two samples left.
Session SessionFromArrays(const ArraySamples& samples, const ArrayNames& names);

}  // namespace plumb::io

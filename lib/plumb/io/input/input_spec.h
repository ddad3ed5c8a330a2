// plumb/io/input/input_spec.h — the text forms a user writes to describe a text table (the
// column description, the axis map, the delimiter, the sensors' scales and units, as the command
// line's flags and the Python module's keywords give them), turned into the fields of InputOptions
// (open_inputs.h). One parser for every front end: each throws plumb::Error with a message
// that quotes the text and names the option as the caller spells it (the command line its flag,
// the Python module its keyword).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "plumb/io/input/open_inputs.h"

namespace plumb::io {

/// `text` split at `sep`, each item with its blanks (space, tab) trimmed; empty items kept.
std::vector<std::string> SplitList(const std::string& text, char sep);

/// How a front end names the column description and the sample rate in the errors of
/// ParseTableColumns and ParseTwoTableColumns.
struct ColumnOptionNames {
  std::string columns;  ///< the column description, as the front end names it
  std::string rate;     ///< how to give a sample rate, as the front end names it
};

/// A one-file table's columns by position, e.g. "t,ax,ay,az,gx,gy,gz" or "-,ax,ay,az": t (or
/// time), ax ay az (all three needed), gx gy gz (all or none), temp (or temp_c), '-' or empty
/// to skip. Without t, `rate_hz` must be > 0 (time = row / rate).
TableColumns ParseTableColumns(const std::string& spec, double rate_hz,
                               const ColumnOptionNames& names);

/// Each file's columns of the two-file form: t, x, y, z (all three needed), '-' to skip.
TwoTableColumns ParseTwoTableColumns(const std::string& spec, double rate_hz,
                                     const ColumnOptionNames& names);

/// A signed permutation "1,-2,-3" (body axis i = sign * sensor axis |m_i|); `option` names it
/// in the error (likewise below).
std::array<int, 3> ParseAxisMap(const std::string& text, const std::string& option);

/// , ; tab space (or their names comma, semicolon, \t); "" = 0 (detect from the first row).
char ParseDelimiter(const std::string& name, const std::string& option);

/// A non-zero finite number or fraction "a/b" (e.g. "9.80665/16384"); `option` names it in
/// the error.
double ParseScale(const std::string& text, const std::string& option);

/// m/s^2 (or m/s2), g, counts; `option` names it in the error.
AccUnit ParseAccUnit(const std::string& name, const std::string& option);
/// rad/s, deg/s, counts; `option` names it in the error.
GyrUnit ParseGyrUnit(const std::string& name, const std::string& option);

}  // namespace plumb::io

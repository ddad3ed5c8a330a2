// plumb/core/number_text.h — numbers as the library's messages write them: printf's fixed and
// significant-digit forms behind one name each, so that no module keeps its own buffer.
#pragma once

#include <string>

namespace plumb {

/// `value` with `decimals` digits after the point ("%.*f"): times and speeds as a user reads
/// them, 1710773367.1 (a unix time) as well as 228.1.
std::string FixedText(double value, int decimals);

/// `value` to `digits` significant digits ("%.*g"): 1.07e+03, 0.0004.
std::string SignificantText(double value, int digits);

/// `value` through the one printf conversion of `format` ("%.3f", "%+.2e", "%8.4g", and text
/// around it: "%.1f s"): the forms a report's columns take. `format` is a literal of the
/// caller's with exactly one conversion of a double.
std::string FormattedText(const char* format, double value);

}  // namespace plumb

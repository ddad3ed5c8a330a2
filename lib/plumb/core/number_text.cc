// See number_text.h.
#include "plumb/core/number_text.h"

#include <cstdio>

namespace plumb {

std::string FixedText(double value, int decimals) {
  char buf[352];  // DBL_MAX in fixed form is 309 digits
  std::snprintf(buf, sizeof buf, "%.*f", decimals, value);
  return buf;
}

std::string SignificantText(double value, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, value);
  return buf;
}

std::string FormattedText(const char* format, double value) {
  char buf[352];
  std::snprintf(buf, sizeof buf, format, value);
  return buf;
}

}  // namespace plumb

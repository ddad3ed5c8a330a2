// See input_spec.h.
#include "plumb/io/input/input_spec.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <sstream>

#include "plumb/core/error.h"

namespace plumb::io {
namespace {

bool ParseDouble(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return errno == 0 && end == text.c_str() + text.size() && std::isfinite(value);
}

}  // namespace

std::vector<std::string> SplitList(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, sep)) {
    const auto b = item.find_first_not_of(" \t");
    const auto e = item.find_last_not_of(" \t");
    out.push_back(b == std::string::npos ? "" : item.substr(b, e - b + 1));
  }
  return out;
}

char ParseDelimiter(const std::string& name, const std::string& option) {
  if (name.empty()) return 0;
  if (name == "," || name == "comma") return ',';
  if (name == ";" || name == "semicolon") return ';';
  if (name == "tab" || name == "\\t" || name == "\t") return '\t';
  if (name == "space" || name == " ") return ' ';
  throw Error(option + " must be one of , ; tab space (got '" + name + "')");
}

std::array<int, 3> ParseAxisMap(const std::string& text, const std::string& option) {
  const auto items = SplitList(text, ',');
  std::array<int, 3> map{};
  bool ok = items.size() == 3;
  for (std::size_t i = 0; ok && i < 3; ++i) {
    double v = 0;
    ok = ParseDouble(items[i], v) && v == std::round(v) && std::abs(v) >= 1 && std::abs(v) <= 3;
    map[i] = static_cast<int>(v);
  }
  if (!ok) throw Error(option + " must be three signed axes such as 1,-2,-3 (got '" + text + "')");
  return map;
}

namespace {

/// The columns `spec` names by position into `time` (t or time) and the slots `slot` finds
/// for the other names (nullptr: not a column of this form, refused with `known`, the list of
/// the form's names); '-' or empty skips a column, a name given twice is refused. Then checks
/// that the three columns `needed` are named (as `needed_names`) and, without a time column,
/// that `rate_hz` > 0.
void AssignColumns(const std::string& spec, const ColumnOptionNames& names, const char* known,
                   int& time, const std::function<int*(const std::string&)>& slot,
                   const std::array<int, 3>& needed, const char* needed_names) {
  const auto tokens = SplitList(spec, ',');
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string& tok = tokens[i];
    if (tok == "-" || tok.empty()) continue;
    int* column = tok == "t" || tok == "time" ? &time : slot(tok);
    if (column == nullptr) {
      throw Error(names.columns + ": unknown column '" + tok + "' in '" + spec + "'; use " +
                  known + " or - to skip a column");
    }
    if (*column >= 0) throw Error(names.columns + " names '" + tok + "' twice in '" + spec + "'");
    *column = static_cast<int>(i);
  }
  if (needed[0] < 0 || needed[1] < 0 || needed[2] < 0) {
    throw Error(names.columns + " '" + spec + "' must name all three accelerometer columns (" +
                needed_names + ")");
  }
}

void CheckTime(const std::string& spec, const ColumnOptionNames& names, int time, double rate_hz) {
  if (time < 0 && !(rate_hz > 0)) {
    throw Error(names.columns + " '" + spec + "' has no time column (t): give " + names.rate);
  }
}

}  // namespace

TableColumns ParseTableColumns(const std::string& spec, double rate_hz,
                               const ColumnOptionNames& names) {
  TableColumns c;
  const auto slot = [&c](const std::string& tok) -> int* {
    if (tok == "temp" || tok == "temp_c") return &c.temp;
    if (tok.size() == 2 && (tok[0] == 'a' || tok[0] == 'g') && tok[1] >= 'x' && tok[1] <= 'z') {
      return &(tok[0] == 'a' ? c.acc : c.gyr)[static_cast<std::size_t>(tok[1] - 'x')];
    }
    return nullptr;
  };
  AssignColumns(spec, names, "t, ax, ay, az, gx, gy, gz, temp", c.time, slot, c.acc, "ax,ay,az");
  const bool any_gyro = c.gyr[0] >= 0 || c.gyr[1] >= 0 || c.gyr[2] >= 0;
  if (any_gyro && !(c.gyr[0] >= 0 && c.gyr[1] >= 0 && c.gyr[2] >= 0)) {
    throw Error(names.columns + " '" + spec + "' names only part of the gyroscope (gx,gy,gz)");
  }
  CheckTime(spec, names, c.time, rate_hz);
  return c;
}

TwoTableColumns ParseTwoTableColumns(const std::string& spec, double rate_hz,
                                     const ColumnOptionNames& names) {
  TwoTableColumns c;
  c.time = -1;
  c.xyz = {-1, -1, -1};
  const auto slot = [&c](const std::string& tok) -> int* {
    if (tok.size() == 1 && tok[0] >= 'x' && tok[0] <= 'z') {
      return &c.xyz[static_cast<std::size_t>(tok[0] - 'x')];
    }
    return nullptr;
  };
  AssignColumns(spec, names, "t, x, y, z", c.time, slot, c.xyz, "x,y,z");
  CheckTime(spec, names, c.time, rate_hz);
  return c;
}

double ParseScale(const std::string& text, const std::string& option) {
  const auto parts = SplitList(text, '/');
  double num = 0, den = 1;
  const bool ok = (parts.size() == 1 || parts.size() == 2) && ParseDouble(parts[0], num) &&
                  (parts.size() == 1 || ParseDouble(parts[1], den)) && den != 0.0 && num != 0.0;
  if (!ok) {
    throw Error(option + " must be a non-zero number or a fraction such as 9.80665/16384 (got '" +
                text + "')");
  }
  return num / den;
}

AccUnit ParseAccUnit(const std::string& name, const std::string& option) {
  if (name == "m/s^2" || name == "m/s2") return AccUnit::kMetersPerSecond2;
  if (name == "g") return AccUnit::kStandardGravity;
  if (name == "counts") return AccUnit::kCounts;
  throw Error(option + " must be m/s^2, g or counts (got '" + name + "')");
}

GyrUnit ParseGyrUnit(const std::string& name, const std::string& option) {
  if (name == "rad/s") return GyrUnit::kRadiansPerSecond;
  if (name == "deg/s") return GyrUnit::kDegreesPerSecond;
  if (name == "counts") return GyrUnit::kCounts;
  throw Error(option + " must be rad/s, deg/s or counts (got '" + name + "')");
}

}  // namespace plumb::io

// See input_spec.h.
#include "plumb/io/input/input_spec.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
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

char ParseDelimiter(const std::string& name) {
  if (name.empty()) return 0;
  if (name == "," || name == "comma") return ',';
  if (name == ";" || name == "semicolon") return ';';
  if (name == "tab" || name == "\\t" || name == "\t") return '\t';
  if (name == "space" || name == " ") return ' ';
  throw Error("--delimiter must be one of , ; tab space (got '" + name + "')");
}

std::array<int, 3> ParseAxisMap(const std::string& text) {
  const auto items = SplitList(text, ',');
  std::array<int, 3> map{};
  bool ok = items.size() == 3;
  for (std::size_t i = 0; ok && i < 3; ++i) {
    double v = 0;
    ok = ParseDouble(items[i], v) && v == std::round(v) && std::abs(v) >= 1 && std::abs(v) <= 3;
    map[i] = static_cast<int>(v);
  }
  if (!ok) throw Error("--axis-map must be three signed axes such as 1,-2,-3 (got '" + text + "')");
  return map;
}

TableColumns ParseTableColumns(const std::string& spec, double rate_hz) {
  TableColumns c;
  const auto tokens = SplitList(spec, ',');
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string& tok = tokens[i];
    const auto set_once = [&](int& column) {
      if (column >= 0) throw Error("--columns names '" + tok + "' twice in '" + spec + "'");
      column = static_cast<int>(i);
    };
    if (tok == "-" || tok.empty()) continue;
    if (tok == "t" || tok == "time") {
      set_once(c.time);
    } else if (tok == "temp" || tok == "temp_c") {
      set_once(c.temp);
    } else if (tok.size() == 2 && (tok[0] == 'a' || tok[0] == 'g') && tok[1] >= 'x' &&
               tok[1] <= 'z') {
      auto& triad = tok[0] == 'a' ? c.acc : c.gyr;
      set_once(triad[static_cast<std::size_t>(tok[1] - 'x')]);
    } else {
      throw Error("--columns: unknown column '" + tok + "' in '" + spec +
                  "'; use t, ax, ay, az, gx, gy, gz, temp or - to skip a column");
    }
  }
  const auto given = [](const std::array<int, 3>& t, bool all) {
    return all ? t[0] >= 0 && t[1] >= 0 && t[2] >= 0 : t[0] >= 0 || t[1] >= 0 || t[2] >= 0;
  };
  if (!given(c.acc, true)) {
    throw Error("--columns '" + spec + "' must name all three accelerometer columns (ax,ay,az)");
  }
  if (given(c.gyr, false) && !given(c.gyr, true)) {
    throw Error("--columns '" + spec + "' names only part of the gyroscope (gx,gy,gz)");
  }
  if (c.time < 0 && !(rate_hz > 0)) {
    throw Error("--columns '" + spec + "' has no time column (t): give --rate HZ");
  }
  return c;
}

TwoTableColumns ParseTwoTableColumns(const std::string& spec, double rate_hz) {
  TwoTableColumns c;
  c.time = -1;
  c.xyz = {-1, -1, -1};
  const auto tokens = SplitList(spec, ',');
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string& tok = tokens[i];
    const auto set_once = [&](int& column) {
      if (column >= 0) throw Error("--columns names '" + tok + "' twice in '" + spec + "'");
      column = static_cast<int>(i);
    };
    if (tok == "-" || tok.empty()) continue;
    if (tok == "t" || tok == "time") {
      set_once(c.time);
    } else if (tok.size() == 1 && tok[0] >= 'x' && tok[0] <= 'z') {
      set_once(c.xyz[static_cast<std::size_t>(tok[0] - 'x')]);
    } else {
      throw Error("--columns: unknown column '" + tok + "' in '" + spec +
                  "'; use t, x, y, z or - to skip a column");
    }
  }
  if (c.xyz[0] < 0 || c.xyz[1] < 0 || c.xyz[2] < 0) {
    throw Error("--columns '" + spec + "' must name all three accelerometer columns (x,y,z)");
  }
  if (c.time < 0 && !(rate_hz > 0)) {
    throw Error("--columns '" + spec + "' has no time column (t): give --rate HZ");
  }
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

AccUnit ParseAccUnit(const std::string& name) {
  if (name == "m/s^2" || name == "m/s2") return AccUnit::kMetersPerSecond2;
  if (name == "g") return AccUnit::kStandardGravity;
  if (name == "counts") return AccUnit::kCounts;
  throw Error("--acc-unit must be m/s^2, g or counts (got '" + name + "')");
}

GyrUnit ParseGyrUnit(const std::string& name) {
  if (name == "rad/s") return GyrUnit::kRadiansPerSecond;
  if (name == "deg/s") return GyrUnit::kDegreesPerSecond;
  if (name == "counts") return GyrUnit::kCounts;
  throw Error("--gyr-unit must be rad/s, deg/s or counts (got '" + name + "')");
}

}  // namespace plumb::io

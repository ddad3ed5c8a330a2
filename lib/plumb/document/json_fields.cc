#include "plumb/document/json_fields.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "plumb/core/error.h"

namespace plumb::document::detail {

using nlohmann::json;

namespace {

/// The value as JSON text, shortened for an error message.
std::string Shown(const json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

}  // namespace

json ParseJsonFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return ParseJsonText(path, [&] { return json::parse(text.str()); });
}

const json& Field(const json& object, const std::string& key, const std::string& path,
                  const std::string& where, const std::string& expected) {
  if (!object.is_object() || !object.contains(key)) {
    throw InputError(path, KeyPlace(where), "missing; expected " + expected);
  }
  return object.at(key);
}

double FiniteNumber(const json& value, const std::string& path, const std::string& where) {
  if (!value.is_number() || !std::isfinite(value.get<double>())) {
    throw InputError(path, KeyPlace(where), "expected a finite number, found " + Shown(value));
  }
  return value.get<double>();
}

Vec3 Vector3(const json& value, const std::string& path, const std::string& where) {
  if (!value.is_array() || value.size() != 3) {
    throw InputError(path, KeyPlace(where), "expected [x, y, z], found " + Shown(value));
  }
  Vec3 out;
  for (std::size_t i = 0; i < 3; ++i) {
    out(static_cast<int>(i)) = FiniteNumber(value[i], path, where + "[" + std::to_string(i) + "]");
  }
  return out;
}

Mat3 Matrix3(const json& value, const std::string& path, const std::string& where) {
  if (!value.is_array() || value.size() != 3) {
    throw InputError(path, KeyPlace(where), "expected 3 rows of 3 numbers, found " + Shown(value));
  }
  Mat3 out;
  for (std::size_t r = 0; r < 3; ++r) {
    out.row(static_cast<int>(r)) =
        Vector3(value[r], path, where + "[" + std::to_string(r) + "]").transpose();
  }
  return out;
}

}  // namespace plumb::document::detail

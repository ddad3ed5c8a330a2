// plumb/document/json_fields.h — INTERNAL to plumb::document (its calibration reader; also
// peers' readers of other tools' files): reading a JSON file and its numeric fields with errors
// that name the file and the key (SPEC section 8).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "plumb/core/types.h"

namespace plumb::document::detail {

/// The file parsed as JSON; plumb::InputError naming it (and the byte offset) otherwise.
nlohmann::json ParseJsonFile(const std::string& path);

/// `object[key]`; plumb::InputError "key '<where>': missing; expected <expected>" otherwise.
/// `where` names the key in messages (e.g. "accel.matrix"), `key` is looked up in `object`.
const nlohmann::json& Field(const nlohmann::json& object, const std::string& key,
                            const std::string& path, const std::string& where,
                            const std::string& expected);

/// A finite number; plumb::InputError at `where` otherwise.
double FiniteNumber(const nlohmann::json& value, const std::string& path, const std::string& where);

/// [x, y, z] of finite numbers.
Vec3 Vector3(const nlohmann::json& value, const std::string& path, const std::string& where);

/// [[row x], [row y], [row z]] of finite numbers.
Mat3 Matrix3(const nlohmann::json& value, const std::string& path, const std::string& where);

/// "key 'name'", the place of a key in error messages.
inline std::string KeyPlace(const std::string& name) { return "key '" + name + "'"; }

}  // namespace plumb::document::detail

// plumb/io/text/json_file.h — a JSON file read whole (a calibration, a study, a study point).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace plumb::io {

/// The JSON document in the file at `path`. Throws plumb::InputError naming the file when it is
/// a folder, cannot be read, or is not valid JSON (with the byte of the syntax error).
nlohmann::json ReadJsonFile(const std::string& path);

}  // namespace plumb::io

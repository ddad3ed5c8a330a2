// See json_file.h.
#include "plumb/io/text/json_file.h"

#include <filesystem>
#include <fstream>

#include "plumb/core/error.h"

namespace plumb::io {

nlohmann::json ReadJsonFile(const std::string& path) {
  if (std::filesystem::is_directory(path)) throw InputError(path, "", "is a folder, not a JSON file");
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "cannot be read");
  return ParseJsonText(path, [&] { return nlohmann::json::parse(in); });
}

}  // namespace plumb::io

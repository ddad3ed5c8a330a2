// plumb/study/study_file.cc — see study_file.h.
#include "plumb/study/study_file.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/io/text/json_file.h"

namespace plumb::study {
namespace {

using nlohmann::json;

/// A YAML node as JSON (StudyYamlToJson). Each node taken (an alias each time it is used)
/// costs one of `budget`; past it, InputError naming `path`.
json FromYaml(const YAML::Node& node, std::size_t& budget, const std::string& path) {
  if (budget == 0) {
    throw InputError(path, "",
                     "more than " + std::to_string(kMaxStudyValues) +
                         " values once its aliases are expanded (nested YAML aliases, an "
                         "\"alias bomb\"?): a study holds far fewer; refused");
  }
  --budget;
  switch (node.Type()) {
    case YAML::NodeType::Map: {
      json out = json::object();
      for (const auto& item : node) {
        out[item.first.as<std::string>()] = FromYaml(item.second, budget, path);
      }
      return out;
    }
    case YAML::NodeType::Sequence: {
      json out = json::array();
      for (const auto& item : node) out.push_back(FromYaml(item, budget, path));
      return out;
    }
    case YAML::NodeType::Scalar: {
      long long i = 0;
      double d = 0.0;
      bool b = false;
      if (YAML::convert<long long>::decode(node, i)) return i;
      if (YAML::convert<double>::decode(node, d)) return d;
      if (YAML::convert<bool>::decode(node, b)) return b;
      return node.as<std::string>();
    }
    default:
      return nullptr;
  }
}

}  // namespace

nlohmann::json StudyYamlToJson(std::string_view text, const std::string& path) {
  try {
    std::size_t budget = kMaxStudyValues;
    return FromYaml(YAML::Load(std::string(text)), budget, path);
  } catch (const YAML::Exception& e) {
    throw InputError(path, "line " + std::to_string(e.mark.line + 1), "not valid YAML: " + e.msg);
  }
}

nlohmann::json ReadStudyFile(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext != ".yaml" && ext != ".yml") return io::ReadJsonFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return StudyYamlToJson(text.str(), path);
}

}  // namespace plumb::study

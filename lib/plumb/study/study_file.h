// plumb/study/study_file.h — a study file as the JSON document study::ParseStudy takes: JSON,
// or YAML turned into the same JSON (`plumb sweep STUDY.yaml`), with YAML's aliases bounded.
// A wander level written with its unit (`gyro_bi: 4 deg/h`) stays text here; ParseStudy reads
// it (study.h), so a study given as a Python dict takes the same.
//
//   const study::Study s = study::ParseStudy(study::ReadStudyFile(path), path);
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace plumb::study {

/// The most values a study file may hold once its YAML aliases are expanded: a study is tens
/// to a few thousand values (factors, levels, options); nested aliases ("billion laughs")
/// expand to billions from a few lines.
inline constexpr std::size_t kMaxStudyValues = 100000;

/// The YAML text `text` (of the file `path`, for errors) as JSON: mappings, sequences, and
/// scalars as integers, numbers, true/false, null or text, in that order of trial. Throws
/// plumb::InputError naming `path` (and the line) when it is not valid YAML, or when it holds
/// more than kMaxStudyValues values once its aliases are expanded (refused before expanding
/// further).
nlohmann::json StudyYamlToJson(std::string_view text, const std::string& path);

/// The study file at `path`: YAML (StudyYamlToJson) when its name ends in .yaml or .yml, else
/// JSON. Throws plumb::InputError naming `path` when it cannot be read or parsed.
nlohmann::json ReadStudyFile(const std::string& path);

}  // namespace plumb::study

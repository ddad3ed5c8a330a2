// See study_template.h.
#include "plumb/pipeline/study_template.h"

#include <filesystem>

#include "plumb/io/text/json_file.h"

namespace plumb::pipeline {

void ReadSessionTemplate(study::Study& study, const std::string& folder) {
  if (study.base.template_path.empty()) return;
  std::filesystem::path t = study.base.template_path;
  if (t.is_relative()) t = std::filesystem::path(folder) / t;
  study.template_document = io::ReadJsonFile(t.string());
  study.base.template_path = t.string();
}

}  // namespace plumb::pipeline

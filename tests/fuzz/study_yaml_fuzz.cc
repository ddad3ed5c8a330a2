// libFuzzer target for YAML study files (study/study_file.h StudyYamlToJson, what `plumb sweep
// STUDY.yaml` reads, then study::ParseStudy): any byte sequence must give a study or a
// plumb::Error naming the file, never a crash, a hang (an alias bomb is refused at
// kMaxStudyValues values) or a huge allocation.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <nlohmann/json.hpp>

#include "plumb/core/error.h"
#include "plumb/study/study.h"
#include "plumb/study/study_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const nlohmann::json doc = plumb::study::StudyYamlToJson(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    (void)plumb::study::ParseStudy(doc, "fuzz.yaml");
  } catch (const plumb::Error&) {
  }
  return 0;
}

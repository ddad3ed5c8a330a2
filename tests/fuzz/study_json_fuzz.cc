// libFuzzer target for the study reader (study/study.h ParseStudy, what `plumb sweep` and
// Python's studies read; a YAML study is turned into the same JSON first): any byte sequence
// must give a study, a plumb::Error naming the key, or nlohmann's parse error, never a crash,
// a hang or a huge allocation.
#include <cstddef>
#include <cstdint>

#include <nlohmann/json.hpp>

#include "plumb/core/error.h"
#include "plumb/study/study.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(data, data + size);
  } catch (const nlohmann::json::exception&) {
    return 0;
  }
  try {
    (void)plumb::study::ParseStudy(doc, "fuzz.json");
  } catch (const plumb::Error&) {
  }
  return 0;
}

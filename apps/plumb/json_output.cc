// See json_output.h.
#include "json_output.h"

#include <cstdio>

#include "plumb/report/json_report.h"

namespace plumb::cli {

TextAsideForJson::TextAsideForJson(const std::string& json_path) {
  if (json_path == "-") saved_ = std::cout.rdbuf(std::cerr.rdbuf());
}

TextAsideForJson::~TextAsideForJson() {
  if (saved_ != nullptr) {
    std::cout.flush();
    std::cout.rdbuf(saved_);
  }
}

void WriteJsonOutput(const std::string& path, const nlohmann::json& doc) {
  if (path != "-") {
    report::WriteJson(path, doc);
    std::cout << "wrote " << path << "\n";
    return;
  }
  std::cout.flush();
  const std::string text =
      doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fflush(stdout);
}

}  // namespace plumb::cli

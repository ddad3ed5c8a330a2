// --json FILE or - for every command that writes JSON (SPEC section 6: "--json - writes to
// stdout"; warnings and progress go to stderr). With "-", the command's text report goes to
// stderr so that stdout carries the JSON document alone, ready for a pipe (`| jq ...`).
#pragma once

#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

namespace plumb::cli {

/// While alive, and only when `json_path` is "-": std::cout writes to stderr (restored on
/// destruction, also when the command throws).
class TextAsideForJson {
 public:
  explicit TextAsideForJson(const std::string& json_path);
  ~TextAsideForJson();
  TextAsideForJson(const TextAsideForJson&) = delete;
  TextAsideForJson& operator=(const TextAsideForJson&) = delete;

 private:
  std::streambuf* saved_ = nullptr;
};

/// Writes `doc` to `path` atomically (report::WriteJson) and says "wrote PATH" on std::cout,
/// or, for "-", to the process's standard output.
void WriteJsonOutput(const std::string& path, const nlohmann::json& doc);

}  // namespace plumb::cli

#include "file_roles.h"

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "commands.h"

namespace plumb::cli {
namespace fs = std::filesystem;
namespace {

bool Exists(const std::string& path) {
  std::error_code ec;
  return !path.empty() && path != "-" && fs::exists(path, ec);
}

bool SameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  return Exists(a) && Exists(b) && fs::equivalent(a, b, ec) && !ec;
}

/// `inner` is `outer` or lies below it (both resolved, symlinks followed).
bool Within(const std::string& inner, const std::string& outer) {
  if (!Exists(inner) || !Exists(outer)) return false;
  std::error_code ec;
  const fs::path in = fs::canonical(inner, ec), out = fs::canonical(outer, ec);
  if (ec) return false;
  auto i = in.begin();
  for (auto o = out.begin(); o != out.end(); ++o, ++i) {
    if (i == in.end() || *i != *o) return false;
  }
  return true;
}

std::string Said(const NamedPath& p) { return p.option + " " + p.path; }

[[noreturn]] void Refuse(const NamedPath& output, const NamedPath& input, const std::string& how) {
  throw UsageError(Said(output) + " " + how + " " + Said(input) +
                   ": refused, so that no input is overwritten; nothing was read or written. "
                   "Choose another output");
}

}  // namespace

std::vector<std::string> InputFiles(const std::string& input) {
  if (Exists(input) || input.find(',') == std::string::npos) return {input};
  std::vector<std::string> files;
  std::stringstream parts(input);
  std::string file;
  while (std::getline(parts, file, ',')) {
    if (!file.empty()) files.push_back(file);
  }
  return files;
}

void RefuseOverwritingInputs(const FileRoles& roles) {
  // Every output file's folder exists: found after the work, a missing one would leave the
  // outputs written before it (a command that fails writes none of its outputs).
  for (const NamedPath& out : roles.output_files) {
    if (out.path.empty() || out.path == "-") continue;
    std::error_code ec;
    const std::filesystem::path path(out.path);
    if (std::filesystem::is_directory(path, ec)) {
      throw UsageError(Said(out) + " is a folder, not a file; nothing was written");
    }
    const std::filesystem::path folder = path.parent_path();
    if (!folder.empty() && !std::filesystem::is_directory(folder, ec)) {
      throw UsageError(Said(out) + ": its folder " + folder.string() +
                       " does not exist (make it first); nothing was written");
    }
  }
  for (const NamedPath& out : roles.output_files) {
    for (const NamedPath& in : roles.inputs) {
      if (SameFile(out.path, in.path)) Refuse(out, in, "is the same file as the input");
    }
  }
  for (std::size_t i = 0; i < roles.output_files.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const NamedPath &a = roles.output_files[j], &b = roles.output_files[i];
      const bool same = SameFile(a.path, b.path) ||
                        (!a.path.empty() && a.path != "-" && a.path == b.path);
      if (same) {
        throw UsageError(Said(a) + " and " + Said(b) +
                         " are one file: one would overwrite the other; nothing was written");
      }
    }
  }
  for (const NamedPath& folder : roles.output_folders) {
    for (const NamedPath& in : roles.inputs) {
      if (Within(in.path, folder.path)) Refuse(folder, in, "is or holds the input");
    }
  }
}

std::string WithInputsNamed(const std::string& message, const FileRoles& roles) {
  // A message about an output ("cannot write OUT: ...") names its file already.
  for (const auto* outputs : {&roles.output_files, &roles.output_folders}) {
    for (const NamedPath& p : *outputs) {
      if (!p.path.empty() && p.path != "-" && message.find(p.path) != std::string::npos) {
        return message;
      }
    }
  }
  std::vector<std::string> named;
  for (const NamedPath& p : roles.inputs) {
    if (p.path.empty() || p.path == "-") continue;
    if (message.find(p.path) != std::string::npos) return message;
    if (p.option == "INPUT") named.push_back(p.path);
  }
  if (named.empty()) {
    for (const NamedPath& p : roles.inputs) {
      if (!p.path.empty() && p.path != "-") named.push_back(p.path);
    }
  }
  if (named.empty()) return message;
  constexpr std::size_t kListed = 3;
  std::string prefix;
  for (std::size_t i = 0; i < std::min(named.size(), kListed); ++i) {
    prefix += (i == 0 ? "" : ", ") + named[i];
  }
  if (named.size() > kListed) prefix += " and " + std::to_string(named.size() - kListed) + " more";
  return prefix + ": " + message;
}

}  // namespace plumb::cli

// apps/plumb/file_roles.h — the files a command reads and writes, checked before it runs: no
// output may be one of the inputs, and no two outputs one file (an input is never
// overwritten, nothing is lost). Every command lists its files (Command::Files) and main
// refuses the command line before any reading or writing when they collide.
//
// "The same file" is the same device and inode (std::filesystem::equivalent: symlinks
// followed, hard links and other spellings of a path caught). An output folder (report,
// paper, sweep --out DIR) is written as a whole: it may neither be an input folder nor hold
// an input file or folder at any depth.
#pragma once

#include <string>
#include <vector>

namespace plumb::cli {

/// One path and the option that named it, for the message ("--json out/x.json").
struct NamedPath {
  std::string option;  ///< e.g. "--json", "INPUT", "--export ardupilot"
  std::string path;
};

struct FileRoles {
  std::vector<NamedPath> inputs;          ///< files and folders read
  std::vector<NamedPath> output_files;    ///< files written ("-" and "" are skipped)
  std::vector<NamedPath> output_folders;  ///< folders written as a whole
};

/// The files of an INPUT argument: itself, or the two of an `acc,gyr` pair when no file has
/// the whole name.
std::vector<std::string> InputFiles(const std::string& input);

/// Throws UsageError (exit 2) naming both options and paths when an output is an input,
/// two outputs are one file, or an output folder is or holds an input; and naming the option
/// when an output file is a folder or its folder does not exist (found only after the work,
/// that would leave the outputs written before it).
void RefuseOverwritingInputs(const FileRoles& roles);

/// `message` (an error of the run) as the user reads it: when it names none of the command's
/// input files -- an error of a stage after reading, such as still detection or the fit --
/// it is prefixed with the INPUT files (the first three and how many more), so every error
/// says which input it is about.
std::string WithInputsNamed(const std::string& message, const FileRoles& roles);

}  // namespace plumb::cli

// plumb/report/gnuplot.h — draw figures with gnuplot (the stack's plotting tool): write the data
// files and the script into a folder, run `gnuplot SCRIPT` there as a child process, and say
// what came out. plumb never draws a plot itself.
//
// The child gets no shell (posix_spawnp: the program is looked up on PATH; the working folder
// is set with posix_spawn_file_actions_addchdir_np, glibc 2.29 or later), its working folder
// is the output folder, its stdin is /dev/null and its stdout and stderr go to LOG in that
// folder (the library never prints). Data and script files are written atomically
// (plumb/io/common/atomic_file.h); the images are gnuplot's own. plumb's pages draw with the
// svg terminal (SvgTerminal) and put the SVGs inside the page (inline_svg.h).
//
// A missing gnuplot is not an error: the outcome says so (`ran` false, `message` naming the
// program and how to install it), the data and the script stay in the folder so that the
// figures can be drawn later with `gnuplot SCRIPT`, and the caller decides (plumb report makes
// the page without figures and warns). Only a folder that cannot be written throws.
//
// Example:
//   GnuplotJob job;
//   job.data.push_back({"line.csv", "0,0\n1,1\n"});
//   job.script = SvgTerminal(640, 480) + "set output 'line.svg'\n"
//                "set datafile separator ','\nplot 'line.csv' using 1:2 with lines\n";
//   job.outputs = {"line.svg"};
//   GnuplotOutcome out = RunGnuplot("out", job);
//   if (!out.ran) warn(out.message);
#pragma once

#include <string>
#include <vector>

namespace plumb::report {

/// A file the script reads, written into the output folder.
struct GnuplotFile {
  std::string name;     ///< file name relative to the folder, e.g. "series.csv"
  std::string content;  ///< its bytes
};

/// What to draw: the data files, the script, and the images the script writes.
struct GnuplotJob {
  std::vector<GnuplotFile> data;
  std::string script_name = "figures.gp";  ///< relative to the folder
  std::string script;                      ///< gnuplot commands; paths relative to the folder
  std::vector<std::string> outputs;        ///< image names the script writes, relative
  std::string log_name = "figures.log";    ///< gnuplot's stdout and stderr, relative
};

struct GnuplotOutcome {
  bool ran = false;      ///< gnuplot was started and exited with status 0
  int exit_code = -1;    ///< its exit status; -1 when it did not start or was killed
  /// Empty when every output was written; otherwise why not, in words (program not found,
  /// the exit status and the first lines of gnuplot's messages, outputs missing or empty).
  std::string message;
  std::vector<std::string> written;  ///< outputs that exist and are non-empty afterwards
};

/// gnuplot commands that select the svg terminal (every gnuplot has it, gnuplot-nox too) for a
/// drawing of `width_px` x `height_px` (> 0; the SVG's viewBox, it scales), no enhanced-text
/// markup, the generic 'sans' font (no font file is named or fetched), a white background.
std::string SvgTerminal(int width_px, int height_px);

/// A string as a gnuplot single-quoted literal: 'text', with ' doubled.
std::string GnuplotQuote(const std::string& text);

/// How long gnuplot may draw a job, s: a report's figures take a second or two; a program
/// that has not finished in this is stuck (a --gnuplot that waits for input, a hung X
/// terminal) and is stopped, so that the report is written without its figures.
inline constexpr double kGnuplotLimit_s = 120.0;

/// Writes job.data and job.script into `folder` (which must exist), runs `program
/// job.script_name` there (program looked up on PATH unless it contains '/'), stops it
/// (SIGKILL) when it has not finished within `limit_s`, and checks job.outputs. Throws
/// plumb::Error naming the file when a data or script file cannot be written; everything else
/// is reported in the outcome.
GnuplotOutcome RunGnuplot(const std::string& folder, const GnuplotJob& job,
                          const std::string& program = "gnuplot",
                          double limit_s = kGnuplotLimit_s);

}  // namespace plumb::report

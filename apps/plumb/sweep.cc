// plumb sweep STUDY.json|yaml --out DIR [--shard K/N] [--jobs N]
// plumb sweep merge DIR... --out DIR
//
// Runs a sensitivity study (plumb/study): every point of its design, its Monte Carlo runs in
// parallel (OpenMP), each point written to DIR/points/point-NNNNN.json as soon as its runs
// are done (a rerun resumes: points already written are kept), then DIR/results.csv and
// DIR/results.json from the point files. With --shard K/N only the points whose index is K-1
// modulo N are run and the results are left to `sweep merge`, which joins the shards' points
// into the same files, byte for byte, as one unsharded run. With the results, DIR/index.html
// and its figures (plumb/report/study_page.h, drawn by gnuplot).
#include <omp.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>


#include "validators.h"
#include "progress.h"
#include "commands.h"
#include "jobs.h"
#include "study_files.h"
#include "plumb/core/error.h"
#include "plumb/io/common/atomic_file.h"
#include "plumb/pipeline/study_template.h"
#include "plumb/report/json_report.h"
#include "plumb/study/run.h"
#include "plumb/study/study_file.h"
#include "plumb/study/summary.h"

namespace plumb::cli {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct SweepArgs {
  std::string study_path;  ///< STUDY.json
  std::string out;         ///< --out DIR
  std::string shard;       ///< --shard K/N
  int jobs = 0;            ///< --jobs N (0: every core)
  std::vector<std::string> merge_dirs;  ///< merge DIR...
  std::string merge_out;                ///< merge --out DIR
};

/// `sweep merge --out DIR` replaces DIR whole: it must be new, empty, or a study folder plumb
/// wrote (its study.json), never a folder of the user's other files.
void CheckMergeFolder(const std::string& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return;
  if (!fs::is_directory(dir, ec)) throw UsageError("merge --out " + dir + " exists and is not a folder");
  if (fs::is_empty(dir, ec) || fs::is_regular_file(fs::path(dir) / "study.json", ec)) return;
  throw UsageError("merge --out " + dir + " holds files that are not a plumb study's, and a "
                   "merge replaces its folder whole: give a new or empty folder; nothing was "
                   "written");
}

/// --shard K/N as {K, N}; {1, 1} when empty.
std::pair<int, int> ParseShard(const std::string& text) {
  if (text.empty()) return {1, 1};
  int k = 0, n = 0;
  char slash = 0;
  std::istringstream is(text);
  if (!(is >> k >> slash >> n) || slash != '/' || !is.eof() || n < 1 || k < 1 || k > n) {
    throw UsageError("--shard takes K/N with 1 <= K <= N (e.g. 2/8), got '" + text + "'");
  }
  return {k, n};
}

/// The results of every design point from the point files of `dir` (all must be there),
/// and the page.
void WriteResults(const study::Study& s, const std::vector<study::Point>& points,
                  const std::string& dir) {
  const std::vector<study::PointSummary> summaries = ReadStudyPoints(s, points, dir);
  io::WriteFileAtomic((fs::path(dir) / "results.csv").string(), study::ResultsCsv(s, summaries));
  report::WriteJson((fs::path(dir) / "results.json").string(), study::ResultsJson(s, summaries));
  const std::string why = WriteStudyPage(s, summaries, dir);
  if (!why.empty()) std::cerr << "warning: no figures: " << why << "\n";
}

std::string PointLine(const study::Study& s, const study::PointSummary& p) {
  std::ostringstream os;
  os << "point " << p.point.index << ":";
  for (std::size_t f = 0; f < s.factors.size(); ++f) {
    os << " " << s.factors[f].name << "=" << p.point.values[f];
  }
  const auto nees = [](double per_dof, int dof, double low, double high) {
    if (dof <= 0) return std::string("no NEES");
    char text[96];
    std::snprintf(text, sizeof text, "NEES/dof %.3f (band %.3f .. %.3f)%s", per_dof, low, high,
                  per_dof > high ? " above" : per_dof < low ? " below" : "");
    return std::string(text);
  };
  os << "; " << p.runs << " runs, " << p.failed << " failed, " << p.flagged << " flagged; "
     << nees(p.nees_per_dof, p.nees_dof, p.nees_low, p.nees_high);
  if (p.flagged > 0) {
    os << "; unflagged runs: "
       << nees(p.nees_unflagged_per_dof, p.nees_unflagged_dof, p.nees_unflagged_low,
               p.nees_unflagged_high);
  }
  return os.str();
}

class SweepCommand : public Command {
 public:
  explicit SweepCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "sweep",
        "Sensitivity study of the calibration procedure: simulate a design at every point of a "
        "study's factors, fit it, and summarise the errors against the truth, the sigmas and "
        "the NEES per point (CSV and JSON)");
    app_->footer("Example (how many poses the base model needs; then two machines' halves joined):\n  plumb sweep examples/studies/poses.json --out poses --jobs 2\n  plumb sweep examples/studies/poses.json --out half1 --shard 1/2\n  plumb sweep merge half1 half2 --out poses");
    SweepArgs& a = args_;
    app_->add_option("STUDY", a.study_path,
                     "The study file: JSON, or YAML when it ends in .yaml or .yml (see "
                     "examples/studies/)")
        ->type_name("STUDY.json|yaml");
    app_->add_option("--out", a.out, "Folder for the results (created; a rerun resumes)")
        ->type_name("DIR");
    app_->add_option("--shard", a.shard,
                     "Run only the K-th of N shares of the points (index = K-1 modulo N); join "
                     "the shards with 'plumb sweep merge'")
        ->type_name("K/N");
    app_->add_option("--jobs", a.jobs, "Runs in parallel (default: every core)")
        ->check(Jobs);
    merge_ = app_->add_subcommand("merge", "Join the folders of a study's shards into one result");
    merge_->add_option("DIR", a.merge_dirs, "The shards' --out folders")->required();
    merge_->add_option("--out", a.merge_out, "Folder for the joined result")->required();
  }

  FileRoles Files() const override {
    const SweepArgs& a = args_;
    FileRoles roles;
    if (merge_->parsed()) {
      for (const std::string& dir : a.merge_dirs) roles.inputs.push_back({"merge DIR", dir});
      roles.output_folders.push_back({"merge --out", a.merge_out});
    } else {
      roles.inputs.push_back({"STUDY", a.study_path});
      roles.output_folders.push_back({"--out", a.out});
    }
    return roles;
  }

  int Run() override {
    if (merge_->parsed()) return Merge();
    const SweepArgs& a = args_;
    if (a.study_path.empty() || a.out.empty()) {
      throw UsageError("sweep needs a study file and --out DIR (or: sweep merge DIR... --out DIR)");
    }
    const auto [k, n] = ParseShard(a.shard);
    study::Study s = study::ParseStudy(study::ReadStudyFile(a.study_path), a.study_path);
    // A session template: relative to the study file's folder.
    pipeline::ReadSessionTemplate(s, fs::path(a.study_path).parent_path().string());
    const std::vector<study::Point> points = study::DesignPoints(s);
    fs::create_directories(fs::path(a.out) / "points");
    report::WriteJson((fs::path(a.out) / "study.json").string(), s.source);
    // The points of this shard not written yet (a rerun resumes).
    std::vector<study::Point> todo;
    int kept = 0;
    for (const study::Point& p : points) {
      if (p.index % n != k - 1) continue;
      const std::string path = PointPath(a.out, p.index);
      if (fs::exists(path)) {
        // Another study's point, another point's copy, an edited one: an error.
        study::PointFromJson(s, ReadJsonFile(path), path, p);
        ++kept;
        continue;
      }
      todo.push_back(p);
    }
    std::cout << "study " << (s.name.empty() ? a.study_path : s.name) << ": " << points.size()
              << " points x " << s.runs << " runs" << (n > 1 ? ", shard " + a.shard : "")
              << "; " << kept << " already written, " << todo.size() << " to run\n";
    RunPoints(s, todo);
    if (n == 1) {
      WriteResults(s, points, a.out);
      std::cout << "wrote " << (fs::path(a.out) / "results.csv").string()
                << ", results.json and index.html\n";
    } else {
      std::cout << "shard " << a.shard << " done; join the shards with 'plumb sweep merge DIR... "
                   "--out DIR'\n";
    }
    return 0;
  }

 private:
  /// Every run of every point in `todo`, in parallel; a point is written when its last run ends.
  void RunPoints(const study::Study& s, const std::vector<study::Point>& todo) const {
    const auto runs = static_cast<std::size_t>(s.runs);
    const std::size_t tasks = todo.size() * runs;
    std::vector<std::vector<study::RunOutcome>> outcomes(todo.size(),
                                                         std::vector<study::RunOutcome>(runs));
    std::vector<std::atomic<std::size_t>> done(todo.size());
    const int jobs = args_.jobs > 0 ? args_.jobs : Cores();
    std::size_t written = 0;
    Progress::Of().Stage("0 of " + std::to_string(todo.size()) + " points");
    std::string error;
#pragma omp parallel for schedule(dynamic) num_threads(jobs)
    for (std::size_t t = 0; t < tasks; ++t) {
      const std::size_t i = t / runs, r = t % runs;
      try {
        outcomes[i][r] = study::RunOnce(s, todo[i], static_cast<int>(r));
      } catch (const std::exception& e) {
#pragma omp critical(sweep_error)
        if (error.empty()) error = e.what();
      }
      if (++done[i] == runs) {
#pragma omp critical(sweep_write)
        {
          const study::PointSummary summary =
              study::Summarise(todo[i], outcomes[i], study::SensitivityFactors(s));
          report::WriteJson(PointPath(args_.out, todo[i].index), study::PointJson(s, summary));
          std::cout << PointLine(s, summary) << "\n" << std::flush;
          Progress::Of().Stage(std::to_string(++written) + " of " + std::to_string(todo.size()) +
                               " points");
        }
      }
    }
    Progress::Of().Clear();
    if (!error.empty()) throw Error("sweep: " + error);
  }

  /// sweep merge DIR... --out DIR.
  int Merge() const {
    const SweepArgs& a = args_;
    const std::string first = (fs::path(a.merge_dirs.front()) / "study.json").string();
    const study::Study s = study::ParseStudy(ReadJsonFile(first), first);
    for (const std::string& dir : a.merge_dirs) {
      const std::string path = (fs::path(dir) / "study.json").string();
      if (ReadJsonFile(path) != s.source) {
        throw InputError(path, "", "another study than " + first + ": shards must share the study");
      }
    }
    const std::vector<study::Point> points = study::DesignPoints(s);
    // Every point found and read before anything is written: a shard missing writes nothing.
    std::vector<study::PointSummary> summaries;
    for (const study::Point& p : points) {
      std::string found;
      for (const std::string& dir : a.merge_dirs) {
        if (fs::exists(PointPath(dir, p.index))) found = PointPath(dir, p.index);
      }
      if (found.empty()) {
        throw Error("sweep merge: point " + std::to_string(p.index) + " is in none of the shards "
                    "(run the missing shard, or rerun it to resume); nothing was written");
      }
      summaries.push_back(study::PointFromJson(s, ReadJsonFile(found), found, p));
    }
    // The folder is written whole, then put in place (a full disk leaves no half of it).
    CheckMergeFolder(a.merge_out);
    const fs::path parent = fs::absolute(a.merge_out).parent_path();
    if (!parent.empty()) fs::create_directories(parent);
    io::StagedFolder staged(a.merge_out);
    const std::string out = staged.staging();
    fs::create_directories(fs::path(out) / "points");
    report::WriteJson((fs::path(out) / "study.json").string(), s.source);
    for (const study::PointSummary& summary : summaries) {
      report::WriteJson(PointPath(out, summary.point.index), study::PointJson(s, summary));
    }
    WriteResults(s, points, out);
    staged.Commit();
    std::cout << "merged " << points.size() << " points from " << a.merge_dirs.size()
              << " folders; wrote " << (fs::path(a.merge_out) / "results.csv").string()
              << ", results.json and index.html\n";
    return 0;
  }

  SweepArgs args_;
  CLI::App* merge_ = nullptr;
};

}  // namespace

std::unique_ptr<Command> MakeSweepCommand(CLI::App& parent) {
  return std::make_unique<SweepCommand>(parent);
}

}  // namespace plumb::cli

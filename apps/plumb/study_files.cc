// See study_files.h.
#include "study_files.h"

#include <cstdio>
#include <filesystem>

#include "plumb/core/error.h"
#include "plumb/io/common/atomic_file.h"
#include "plumb/report/gnuplot.h"
#include "plumb/report/study_page.h"

namespace plumb::cli {

namespace fs = std::filesystem;

std::string PointPath(const std::string& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "point-%05d.json", index);
  return (fs::path(dir) / "points" / name).string();
}

std::vector<study::PointSummary> ReadStudyPoints(const study::Study& study,
                                                 const std::vector<study::Point>& points,
                                                 const std::string& dir) {
  std::vector<study::PointSummary> out;
  for (const study::Point& p : points) {
    const std::string path = PointPath(dir, p.index);
    out.push_back(study::PointFromJson(study, ReadJsonFile(path), path, p));
  }
  return out;
}

std::string WriteStudyPage(const study::Study& study,
                           const std::vector<study::PointSummary>& points, const std::string& dir,
                           bool figures, const std::string& gnuplot) {
  std::string note = "not drawn (--no-figures)";
  std::vector<report::InlineFigure> drawn;
  if (figures) {
    const report::GnuplotOutcome out =
        report::RunGnuplot(dir, report::StudyFigures(study, points), gnuplot);
    note = out.ran ? "" : out.message;
    drawn = report::TakeSvgFiles(dir, out.written);  // inside the page, not beside it
  }
  io::WriteFileAtomic((fs::path(dir) / "index.html").string(),
                      report::StudyPage(study, points, drawn, note));
  return note;
}

}  // namespace plumb::cli

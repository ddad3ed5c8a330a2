// The files of a sensitivity study's folder (plumb sweep, plumb report --study): the study as
// read (study.json), one file per point (points/point-NNNNN.json), the results and the page.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "plumb/io/text/json_file.h"
#include "plumb/study/study.h"
#include "plumb/study/summary.h"

namespace plumb::cli {

/// A JSON file; plumb::InputError naming it (and the byte of a syntax error) otherwise.
using io::ReadJsonFile;

/// DIR/points/point-NNNNN.json.
std::string PointPath(const std::string& dir, int index);

/// Every design point's summary from the point files of `dir` (all must be there).
std::vector<study::PointSummary> ReadStudyPoints(const study::Study& study,
                                                 const std::vector<study::Point>& points,
                                                 const std::string& dir);

/// DIR/index.html and, unless `figures` is false, its figures drawn by `gnuplot` (a missing
/// gnuplot is said on the page and returned, not thrown). Returns why there are no figures, or "".
std::string WriteStudyPage(const study::Study& study,
                           const std::vector<study::PointSummary>& points, const std::string& dir,
                           bool figures = true, const std::string& gnuplot = "gnuplot");

}  // namespace plumb::cli

// plumb/report/study_page.h — a sensitivity study (plumb/study) as a page: the points with
// their runs, failures and NEES, and per factor two figures drawn by gnuplot: the NEES per
// degree of freedom with its 95 % band, and the RMS error and the mean sigma of the headline
// parameters, against the factor (the other factors held at the first point's values). The
// figures are SVGs inside the page (inline_svg.h): the page needs no file beside it.
#pragma once

#include <string>
#include <vector>

#include "plumb/report/gnuplot.h"
#include "plumb/report/inline_svg.h"
#include "plumb/study/study.h"
#include "plumb/study/summary.h"

namespace plumb::report {

/// The figures' data and script (nees_FACTOR.svg, error_FACTOR.svg for every factor with two
/// or more values along it), for RunGnuplot in the study's folder.
GnuplotJob StudyFigures(const study::Study& study, const std::vector<study::PointSummary>& points);

/// The page (index.html): `figures` the drawn ones (TakeSvgFiles of what RunGnuplot wrote),
/// `figure_note` why there are none.
std::string StudyPage(const study::Study& study, const std::vector<study::PointSummary>& points,
                      const std::vector<InlineFigure>& figures, const std::string& figure_note);

}  // namespace plumb::report

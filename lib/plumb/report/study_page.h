// plumb/report/study_page.h — a sensitivity study (plumb/study) as a page: the points with
// their runs, failures and NEES, and per factor the figures drawn by gnuplot (study_figures.h):
// the NEES per degree of freedom with its 95 % band, and for every parameter the study scores
// (on one pose, the combinations the data determine) the signed mean error with its spread
// over the runs, +- the mean sigma the fit reported and, for uncertain factors, the mean +-
// the first-order spread they predict (sd_first_order), against the factor (the other factors
// held at the first point's values), with units. The figures are grouped by factor, a section
// each with a heading, and listed in a table of contents. The figures are SVGs inside the
// page (inline_svg.h): the page needs no file beside it.
#pragma once

#include <string>
#include <vector>

#include "plumb/report/gnuplot.h"
#include "plumb/report/inline_svg.h"
#include "plumb/report/study_figures.h"
#include "plumb/study/study.h"
#include "plumb/study/summary.h"

namespace plumb::report {

/// The figures' data and script (PlanStudyFigures(study, points).job: nees_FACTOR.svg and
/// error_FACTOR_N.svg for every factor with two or more values along it), for RunGnuplot in
/// the study's folder.
GnuplotJob StudyFigures(const study::Study& study, const std::vector<study::PointSummary>& points);

/// The page (index.html): `figures` the drawn ones (TakeSvgFiles of what RunGnuplot wrote),
/// placed in their factor's section by file name (PlanStudyFigures), `figure_note` why there
/// are none.
std::string StudyPage(const study::Study& study, const std::vector<study::PointSummary>& points,
                      const std::vector<InlineFigure>& figures, const std::string& figure_note);

}  // namespace plumb::report

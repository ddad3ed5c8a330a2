// plumb/report/study_figures.h — the figures of a sensitivity study's page (study_page.h), as
// a gnuplot job (gnuplot.h) and the list of what each figure shows.
//
// Per factor with two or more values along it (the other factors at the first point's values):
//   nees_FACTOR.svg     the NEES per degree of freedom (all runs, and the runs no gate flagged)
//                       with its 95 % band, against the factor
//   error_FACTOR_N.svg  for every parameter the study scores (N: the row's place among the rows
//                       of the points along the factor, first seen first; the fitted model's
//                       parameters a run determined, or on one pose the combinations the
//                       data determine, matched along the factor by their leading
//                       parameter: the other coefficients may change with it, and the name
//                       then says "(coefficients vary)"), the signed mean error (estimate -
//                       truth) over the runs with its spread (+- 1 standard deviation over the
//                       runs, as error bars), +- the mean sigma the fit reported (about zero),
//                       and, where the study has uncertain factors (Factor::sigma) with an
//                       analytic sensitivity, the mean error +- sd_first_order (the spread over
//                       the runs they predict to first order, study::FirstOrderCovariance, about
//                       the mean error as the bars are), against the factor; the y axis in the
//                       parameter's unit
// The x axis is the factor in its unit (study::FactorUnit), logarithmic when every value is
// positive and they span a factor 50 or more. A factor with a value that names a category
// (study::FactorLevelName: fit_gravity_m_s2 = 0 is "WGS84") is drawn as categories, one tic
// per value, named, in value order. Every line has a legend entry. The data are one CSV per
// factor with a '#' header line (per row: mean_error, sd_error, mean_sigma, sd_first_order);
// non-finite values are left empty (gnuplot skips them), and a series with no finite value is
// not drawn (gnuplot stops at such a plot): which ones have values is decided from the
// summaries as the file is made.
#pragma once

#include <string>
#include <vector>

#include "plumb/report/gnuplot.h"
#include "plumb/study/study.h"
#include "plumb/study/summary.h"

namespace plumb::report {

/// One figure of the study page.
struct StudyFigure {
  std::string file;       ///< the SVG gnuplot writes, e.g. "error_poses_3.svg"
  std::size_t factor = 0;  ///< index in Study::factors
  std::string parameter;  ///< the row's name; "" for the NEES figure
  std::string unit;       ///< the parameter's unit ("" for the NEES figure or none)
  bool first_order = false;  ///< an error figure that draws mean +- sd_first_order
};

struct StudyFigurePlan {
  GnuplotJob job;                    ///< data files, script (study.gp), outputs
  std::vector<StudyFigure> figures;  ///< in page order (factor by factor), one per output
};

/// The figures of `points` (file comment).
StudyFigurePlan PlanStudyFigures(const study::Study& study,
                                 const std::vector<study::PointSummary>& points);

/// The points along factor f: every other factor at the first point's value, sorted by f.
std::vector<const study::PointSummary*> PointsAlong(const std::vector<study::PointSummary>& points,
                                                    std::size_t f);

/// "name (unit)", or the name alone without a unit.
std::string WithUnit(const std::string& name, const std::string& unit);

}  // namespace plumb::report

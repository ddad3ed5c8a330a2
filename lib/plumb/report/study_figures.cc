#include "plumb/report/study_figures.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "plumb/core/error.h"

namespace plumb::report {
namespace {

constexpr const char* kMeanColour = "#1565c0";
constexpr const char* kSpreadColour = "#64b5f6";
constexpr const char* kSigmaColour = "#c62828";
constexpr const char* kBandColour = "#2e7d32";
constexpr const char* kFirstOrderColour = "#ef6c00";
/// Appended to a combination's name when its coefficients change along the factor.
constexpr const char* kVaries = " (coefficients vary)";

/// A CSV field: empty when not finite (gnuplot skips it).
std::string Field(double v) { return std::isfinite(v) ? Number(v, 10) : ""; }

std::string Safe(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

/// The factor's unit: its own (study::FactorUnit), or for truth.PARAMETER the parameter's.
std::string UnitOfFactor(const std::string& name, const std::vector<study::PointSummary>& points) {
  const std::string unit = study::FactorUnit(name);
  if (!unit.empty() || name.rfind("truth.", 0) != 0 || points.empty()) return unit;
  for (const study::ParameterSummary& p : points.front().parameters) {
    if (p.name == name.substr(6)) return p.unit;
  }
  return "";
}

/// What a row is along a factor: a parameter's name, or for a determined combination its
/// leading parameter's (the text's first term, coefficient 1) marked as a combination: its
/// other coefficients may change with the factor ("accel.bias.z - 9.78 accel.matrix.zz" at
/// WGS84's gravity, "accel.bias.z - 9.807 accel.matrix.zz" at 9.80665).
std::string RowKey(const std::string& name) {
  const std::size_t space = name.find(' ');
  return space == std::string::npos ? name : name.substr(0, space) + " (combination)";
}

/// The row of point `p` whose RowKey is `key`, or null.
const study::ParameterSummary* Row(const study::PointSummary& p, const std::string& key) {
  for (const study::ParameterSummary& r : p.parameters) {
    if (RowKey(r.name) == key) return &r;
  }
  return nullptr;
}

/// How the x axis of one factor is drawn.
struct Axis {
  bool categorical = false;
  std::string setup;  ///< gnuplot commands that set the x axis up
  std::string label;  ///< the x label
};

Axis FactorAxis(const std::string& name, const std::string& unit,
                const std::vector<const study::PointSummary*>& along, std::size_t f) {
  Axis axis;
  axis.label = WithUnit(name, unit);
  for (const auto* p : along) {
    axis.categorical = axis.categorical || !study::FactorLevelName(name, p->point.values[f]).empty();
  }
  if (axis.categorical) {
    std::string tics;
    for (std::size_t i = 0; i < along.size(); ++i) {
      const double v = along[i]->point.values[f];
      const std::string level = study::FactorLevelName(name, v);
      tics += std::string(i == 0 ? "" : ", ") + GnuplotQuote(level.empty() ? Number(v) : level) +
              " " + std::to_string(i);
    }
    axis.setup = "unset logscale x\nset xrange [-0.5:" + Number(along.size() - 0.5) +
                 "]\nset xtics (" + tics + ")\nset offsets 0, 0, graph 0.05, graph 0.05\n";
    axis.label += ", by level";
    return axis;
  }
  const double low = along.front()->point.values[f], high = along.back()->point.values[f];
  const bool log = low > 0.0 && high / low >= 50.0;
  axis.setup = std::string("unset logscale x\nset autoscale x\nset xtics autofreq\n") +
               (log ? "set logscale x\n" : "") +
               "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n";
  if (log) axis.label += ", log scale";
  return axis;
}

/// Which series of a row's columns have a value at some point along the factor.
struct RowSeries {
  bool mean = false, sd = false, sigma = false;
  bool first_order = false;  ///< sd_first_order where the mean error is too (drawn around it)
};

/// A factor's data file and which of its series have a value, decided from the summaries as
/// the file is made (a series with none is not drawn: gnuplot stops at it).
struct FactorData {
  std::string csv;
  bool nees = false, nees_unflagged = false;
  std::vector<RowSeries> rows;  ///< per row, in the file's row order
};

/// Columns (1-based) of the data file: x, level, the NEES per dof, its band, the NEES per dof
/// of the runs not flagged, then kRowColumns per row from kFirstRowColumn: the mean error, its
/// standard deviation over the runs, the mean sigma, sd_first_order.
constexpr std::size_t kFirstRowColumn = 7, kRowColumns = 4;

/// Appends `v` as a field (",v"; empty when not finite) and returns whether it is finite.
bool Put(std::string& csv, double v) {
  csv += "," + Field(v);
  return std::isfinite(v);
}

/// sd_first_order of each of `p`'s parameters (its parameter order): the square root of the
/// diagonal of study::FirstOrderCovariance, the spread the uncertain factors add to the
/// error over the runs, in the parameter's unit (as in results.csv); NaN without an uncertain
/// factor or a sensitivity.
std::vector<double> FirstOrderSd(const study::Study& study, const study::PointSummary& p) {
  const auto cov = study::FirstOrderCovariance(study, p);
  std::vector<double> sd(p.parameters.size(), NAN);
  for (std::size_t j = 0; j < cov.size() && j < sd.size(); ++j) sd[j] = std::sqrt(cov[j][j]);
  return sd;
}

/// Appends point `p`'s line (the k-th along factor f) to `data`, its rows `rows`.
void AppendPoint(const study::Study& study, std::size_t f, const Axis& axis,
                 const study::PointSummary& p, std::size_t k, const std::vector<std::string>& rows,
                 FactorData& data) {
  const double v = p.point.values[f];
  const std::string level = study::FactorLevelName(study.factors[f].name, v);
  const bool nees = p.nees_dof > 0, unflagged = p.nees_unflagged_dof > 0;
  data.csv += (axis.categorical ? std::to_string(k) : Field(v)) + "," + (level.empty() ? Field(v) : level);
  data.nees = Put(data.csv, nees ? p.nees_per_dof : NAN) || data.nees;
  Put(data.csv, nees ? p.nees_low : NAN);
  Put(data.csv, nees ? p.nees_high : NAN);
  data.nees_unflagged = Put(data.csv, unflagged ? p.nees_unflagged_per_dof : NAN) || data.nees_unflagged;
  const std::vector<double> first_order = FirstOrderSd(study, p);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const study::ParameterSummary* r = Row(p, rows[i]);
    const bool has = r != nullptr && r->runs > 0;
    RowSeries& series = data.rows[i];
    const bool mean = Put(data.csv, has ? r->mean_error : NAN);
    series.mean = mean || series.mean;
    series.sd = Put(data.csv, has ? r->sd_error : NAN) || series.sd;
    series.sigma = Put(data.csv, has ? r->mean_sigma : NAN) || series.sigma;
    const bool spread = Put(data.csv, has ? first_order[r - p.parameters.data()] : NAN);
    series.first_order = (mean && spread) || series.first_order;
  }
  data.csv += "\n";
}

/// The factor's data file over the points `along` it (the columns: see kFirstRowColumn), with
/// a '#' header line naming the columns.
FactorData FactorCsv(const study::Study& study, std::size_t f, const Axis& axis,
                     const std::vector<const study::PointSummary*>& along,
                     const std::vector<std::string>& rows) {
  FactorData data;
  data.rows.resize(rows.size());
  data.csv = "# x,level,nees_per_dof,nees_low,nees_high,nees_unflagged_per_dof";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string n = std::to_string(i);
    data.csv += ",mean_error" + n + ",sd_error" + n + ",mean_sigma" + n + ",sd_first_order" + n;
  }
  data.csv += "\n";
  for (std::size_t k = 0; k < along.size(); ++k) AppendPoint(study, f, axis, *along[k], k, rows, data);
  return data;
}

/// The NEES figure's script, "" when no point has a NEES (closed forms: no sigma).
std::string NeesScript(const std::string& csv_name, const FactorData& data, const std::string& svg,
                       const std::string& name, const Axis& axis) {
  if (!data.nees) return "";
  const std::string style = axis.categorical ? "points" : "linespoints";
  std::string s = "set output '" + svg + "'\n" + axis.setup + "set logscale y\nset autoscale y\nset xlabel " +
                  GnuplotQuote(axis.label) + "\nset ylabel 'NEES / dof (dimensionless)'\nset title " +
                  GnuplotQuote("NEES per degree of freedom against " + name) + "\nplot '" + csv_name +
                  "' using 1:4 with lines dt 2 lw 1.5 lc rgb '" + kBandColour +
                  "' title '95 % band of NEES / dof (honest sigma)', '' using 1:5 with lines dt 2 lw 1.5 lc rgb '" +
                  kBandColour + "' notitle, '' using 1:3 with " + style + " pt 7 lc rgb '" + kMeanColour +
                  "' title 'NEES / dof, all runs'";
  if (data.nees_unflagged) {
    s += ", '' using 1:6 with " + style + " pt 6 dt 3 lc rgb '#6a1b9a' title 'NEES / dof, runs no gate flagged'";
  }
  return s + "\nunset logscale y\n";
}

/// The dashed pair mean error (column m) +- sd_first_order (column o), in the y axis' unit:
/// the spread over the runs that the uncertain factors predict to first order (S sigma^2
/// S^T, docs/sensitivity.md), about the mean error as the runs' spread is.
std::string FirstOrderLines(const std::string& m, const std::string& o) {
  const std::string style = " with lines dt 2 lw 1.5 lc rgb '" + std::string(kFirstOrderColour) + "'";
  return ", '' using 1:($" + m + "+$" + o + ")" + style +
         " title 'mean +- sd_first_order', '' using 1:($" + m +
         "-$" + o + ")" + style + " notitle";
}

/// The error figure's script for row `i` (its series `has`), "" when no point has its mean
/// error.
std::string ErrorScript(const std::string& csv_name, const RowSeries& has, const std::string& svg,
                        const Axis& axis, std::size_t i, const std::string& row, const std::string& unit) {
  if (!has.mean) return "";
  const std::size_t mean = kFirstRowColumn + kRowColumns * i;
  const std::string m = std::to_string(mean), d = std::to_string(mean + 1), g = std::to_string(mean + 2),
                    o = std::to_string(mean + 3);
  std::string s = "set output '" + svg + "'\n" + axis.setup + "unset logscale y\nset autoscale y\nset xlabel " +
                  GnuplotQuote(axis.label) + "\nset ylabel " +
                  GnuplotQuote(WithUnit("error, estimate - truth", unit.empty() ? "dimensionless" : unit)) +
                  "\nset title " + GnuplotQuote(row) + "\nplot 0 with lines lc rgb '#9e9e9e' title 'zero error'";
  if (has.sd) {
    s += ", '" + csv_name + "' using 1:" + m + ":" + d + " with yerrorbars ps 0 lw 2 lc rgb '" + kSpreadColour +
         "' title 'spread: mean +- 1 sd over runs'";
  }
  s += ", '" + csv_name + "' using 1:" + m + " with " + (axis.categorical ? "points" : "linespoints") +
       " pt 7 lc rgb '" + kMeanColour + "' title 'mean error over runs'";
  if (has.sigma) {
    s += ", '' using 1:" + g + " with lines dt 2 lw 1.5 lc rgb '" + kSigmaColour +
         "' title '+- mean sigma the fit reported', '' using 1:(-$" + g + ") with lines dt 2 lw 1.5 lc rgb '" +
         kSigmaColour + "' notitle";
  }
  if (has.first_order) s += FirstOrderLines(m, o);
  return s + "\n";
}

}  // namespace

std::string WithUnit(const std::string& name, const std::string& unit) {
  return unit.empty() ? name : name + " (" + unit + ")";
}

std::vector<const study::PointSummary*> PointsAlong(const std::vector<study::PointSummary>& points,
                                                    std::size_t f) {
  std::vector<const study::PointSummary*> out;
  if (points.empty()) return out;
  const std::vector<double>& base = points.front().point.values;
  for (const study::PointSummary& p : points) {
    bool others = true;
    for (std::size_t g = 0; g < base.size(); ++g) others = others && (g == f || p.point.values[g] == base[g]);
    if (others) out.push_back(&p);
  }
  std::stable_sort(out.begin(), out.end(), [f](const auto* a, const auto* b) {
    return a->point.values[f] < b->point.values[f];
  });
  return out;
}

StudyFigurePlan PlanStudyFigures(const study::Study& study,
                                 const std::vector<study::PointSummary>& points) {
  StudyFigurePlan plan;
  GnuplotJob& job = plan.job;
  job.script_name = "study.gp";
  job.log_name = "study.log";
  job.script = SvgTerminal(560, 380) + "set datafile separator ','\nset grid\nset key below samplen 2\n";
  for (std::size_t f = 0; f < study.factors.size(); ++f) {
    const auto along = PointsAlong(points, f);
    if (along.size() < 2) continue;
    const std::string name = study.factors[f].name, safe = Safe(name);
    const Axis axis = FactorAxis(name, UnitOfFactor(name, points), along, f);
    // Every row of every point along the factor (by RowKey), first seen first (the first
    // point's order), named by its first text; a combination whose text changes along the
    // factor says so.
    std::vector<std::string> rows, names, units;
    for (const auto* p : along) {
      for (const study::ParameterSummary& r : p->parameters) {
        const auto at = std::find(rows.begin(), rows.end(), RowKey(r.name));
        if (at == rows.end()) {
          rows.push_back(RowKey(r.name));
          names.push_back(r.name);
          units.push_back(r.unit);
        } else if (names[at - rows.begin()] != r.name &&
                   names[at - rows.begin()].find(kVaries) == std::string::npos) {
          names[at - rows.begin()] += kVaries;
        }
      }
    }
    const std::string csv_name = "study_" + safe + ".csv";
    const FactorData data = FactorCsv(study, f, axis, along, rows);
    const std::size_t drawn = plan.figures.size();
    const std::string nees = NeesScript(csv_name, data, "nees_" + safe + ".svg", name, axis);
    if (!nees.empty()) {
      job.script += nees;
      job.outputs.push_back("nees_" + safe + ".svg");
      plan.figures.push_back({"nees_" + safe + ".svg", f, "", ""});
    }
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const std::string svg = "error_" + safe + "_" + std::to_string(i) + ".svg";
      const std::string script = ErrorScript(csv_name, data.rows[i], svg, axis, i, names[i], units[i]);
      if (script.empty()) continue;  // not determined along this factor
      job.script += script;
      job.outputs.push_back(svg);
      plan.figures.push_back({svg, f, names[i], units[i], data.rows[i].first_order});
    }
    if (plan.figures.size() > drawn) job.data.push_back({csv_name, data.csv});
  }
  return plan;
}

}  // namespace plumb::report

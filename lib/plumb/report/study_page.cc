#include "plumb/report/study_page.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/report/html_report.h"
#include "plumb/report/version.h"

namespace plumb::report {
namespace {

/// Rows drawn against each factor: the first four of the point's rows (the accelerometer's
/// scale and cross terms come first in the base model; combinations when one pose).
constexpr std::size_t kHeadline = 4;

std::string CsvValue(double v) { return std::isfinite(v) ? Number(v, 10) : "NaN"; }

/// `v` with 3 decimals ("%.3f"), "n/a" when not finite.
std::string Short(double v) { return std::isfinite(v) ? FixedText(v, 3) : "n/a"; }

/// The points along factor f: every other factor at the first point's value, sorted by f.
std::vector<const study::PointSummary*> Along(const std::vector<study::PointSummary>& points,
                                              std::size_t f) {
  std::vector<const study::PointSummary*> out;
  if (points.empty()) return out;
  const std::vector<double>& base = points.front().point.values;
  for (const study::PointSummary& p : points) {
    bool others = true;
    for (std::size_t g = 0; g < base.size(); ++g) others = others && (g == f || p.point.values[g] == base[g]);
    if (others) out.push_back(&p);
  }
  std::sort(out.begin(), out.end(), [f](const auto* a, const auto* b) {
    return a->point.values[f] < b->point.values[f];
  });
  return out;
}

std::string Safe(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

/// Two table cells: a NEES per dof (marked when outside its band, "n/a" without runs) and
/// its band.
std::string NeesCells(double per_dof, int dof, double low, double high) {
  if (dof <= 0) return "<td class=\"num\">n/a</td><td></td>";
  const bool outside = per_dof > high || per_dof < low;
  return "<td class=\"num" + std::string(outside ? " warn" : "") + "\">" + Short(per_dof) +
         "</td><td class=\"num\">" + Short(low) + " .. " + Short(high) + "</td>";
}

}  // namespace

GnuplotJob StudyFigures(const study::Study& study, const std::vector<study::PointSummary>& points) {
  GnuplotJob job;
  job.script_name = "study.gp";
  job.log_name = "study.log";
  job.script = SvgTerminal(800, 480) + "set datafile separator ','\nset grid\nset key outside right\n";
  for (std::size_t f = 0; f < study.factors.size(); ++f) {
    const auto along = Along(points, f);
    if (along.size() < 2) continue;
    const std::string name = study.factors[f].name, safe = Safe(name);
    // NEES per degree of freedom with its band (none for closed forms: no sigma). gnuplot
    // stops at a plot with no defined point, so such series are left out.
    const bool any_nees = std::any_of(along.begin(), along.end(),
                                      [](const auto* p) { return std::isfinite(p->nees_per_dof); });
    std::string nees = "value,nees_per_dof,low,high\n";
    for (const auto* p : along) {
      nees += CsvValue(p->point.values[f]) + "," + CsvValue(p->nees_per_dof) + "," + CsvValue(p->nees_low) + "," +
              CsvValue(p->nees_high) + "\n";
    }
    if (any_nees) job.data.push_back({"nees_" + safe + ".csv", nees});
    if (any_nees) job.script += "set output 'nees_" + safe + ".svg'\nset logscale y\nset xlabel " +
                  GnuplotQuote(name) + "\nset ylabel 'NEES / dof'\nset title " +
                  GnuplotQuote("NEES per degree of freedom against " + name + " (95 % band)") +
                  "\nplot 'nees_" + safe + ".csv' every ::1 using 1:3 with lines dt 2 lc rgb '#2e7d32' title 'band', " +
                  "'' every ::1 using 1:4 with lines dt 2 lc rgb '#2e7d32' notitle, " +
                  "'' every ::1 using 1:2 with linespoints pt 7 lc rgb '#1565c0' title 'NEES / dof'\n";
    if (any_nees) job.outputs.push_back("nees_" + safe + ".svg");
    // RMS error and mean sigma of the headline rows.
    const std::size_t rows = std::min(kHeadline, along.front()->parameters.size());
    if (rows == 0) continue;
    std::string err = "value";
    for (std::size_t i = 0; i < rows; ++i) err += ",rms" + std::to_string(i) + ",sigma" + std::to_string(i);
    err += "\n";
    for (const auto* p : along) {
      err += CsvValue(p->point.values[f]);
      for (std::size_t i = 0; i < rows; ++i) {
        const bool has = i < p->parameters.size();
        err += "," + CsvValue(has ? p->parameters[i].rms_error : NAN) + "," +
               CsvValue(has ? p->parameters[i].mean_sigma : NAN);
      }
      err += "\n";
    }
    job.data.push_back({"error_" + safe + ".csv", err});
    job.script += "set output 'error_" + safe + ".svg'\nset ylabel 'RMS error (points), mean sigma (dashed)'\nset title " +
                  GnuplotQuote("error and sigma against " + name) + "\nplot ";
    auto defined = [&](std::size_t i, bool sigma) {
      return std::any_of(along.begin(), along.end(), [&](const auto* p) {
        return i < p->parameters.size() &&
               std::isfinite(sigma ? p->parameters[i].mean_sigma : p->parameters[i].rms_error);
      });
    };
    std::string plots;
    for (std::size_t i = 0; i < rows; ++i) {
      const std::string label = along.front()->parameters[i].name;
      const std::string col = std::to_string(2 + 2 * i);
      const std::string sig = std::to_string(3 + 2 * i);
      const std::string lc = " lc " + std::to_string(i + 1);
      if (defined(i, false)) {
        plots += std::string(plots.empty() ? "" : ", ") + "'error_" + safe + ".csv' every ::1 using 1:" +
                 col + " with points pt 7" + lc + " title " + GnuplotQuote(label);
      }
      if (defined(i, true)) {
        plots += std::string(plots.empty() ? "" : ", ") + "'error_" + safe + ".csv' every ::1 using 1:" +
                 sig + " with lines dt 2" + lc + " notitle";
      }
    }
    if (plots.empty()) {  // nothing determined along this factor
      job.data.pop_back();
      job.script.resize(job.script.rfind("set output 'error_"));
      continue;
    }
    job.script += plots;
    job.script += "\nunset logscale y\n";
    job.outputs.push_back("error_" + safe + ".svg");
  }
  return job;
}

std::string StudyPage(const study::Study& study, const std::vector<study::PointSummary>& points,
                      const std::vector<InlineFigure>& figures, const std::string& figure_note) {
  std::string html = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"generator\" content=\"plumb sweep\"><title>plumb sweep: " +
                     HtmlEscape(study.name) + "</title><style>" + PageStyle() +
                     "</style></head><body>\n<h1>plumb sweep: " + HtmlEscape(study.name) + "</h1>\n";
  html += "<p class=\"muted\">plumb " + HtmlEscape(Version()) + "; " + std::to_string(points.size()) +
          " points x " + std::to_string(study.runs) + " runs, seed " + std::to_string(study.seed) +
          ", method " + HtmlEscape(study.fit_method) + ", fitted model " + HtmlEscape(study.fit_model) +
          ". The numbers are in results.csv and results.json beside this page.</p>\n";
  html += "<h2>Points</h2>\n<table><tr><th>point</th>";
  for (const study::Factor& f : study.factors) html += "<th>" + HtmlEscape(f.name) + "</th>";
  html += "<th>runs</th><th>failed</th><th>flagged</th><th>NEES / dof</th><th>95 % band</th>"
          "<th>NEES / dof, runs not flagged</th><th>95 % band</th></tr>\n";
  for (const study::PointSummary& p : points) {
    const bool outside = p.nees_dof > 0 && (p.nees_per_dof > p.nees_high || p.nees_per_dof < p.nees_low);
    html += "<tr><td class=\"num\">" + std::to_string(p.point.index) + "</td>";
    for (double v : p.point.values) html += "<td class=\"num\">" + (std::isfinite(v) ? Number(v) : std::string("n/a")) + "</td>";
    html += "<td class=\"num\">" + std::to_string(p.runs) + "</td><td class=\"num\">" +
            std::to_string(p.failed) + "</td><td class=\"num\">" + std::to_string(p.flagged) +
            "</td><td class=\"num" + std::string(outside ? " warn" : "") + "\">" +
            (p.nees_dof > 0 ? Short(p.nees_per_dof) : "n/a") + "</td><td class=\"num\">" +
            (p.nees_dof > 0 ? Short(p.nees_low) + " .. " + Short(p.nees_high) : "") +
            "</td>" + NeesCells(p.nees_unflagged_per_dof, p.nees_unflagged_dof, p.nees_unflagged_low,
                                p.nees_unflagged_high) +
            "</tr>\n";
  }
  html += "</table>\n<h2>Figures</h2>\n";
  if (!figure_note.empty()) html += "<p class=\"warn\">No figures: " + HtmlEscape(figure_note) + "</p>\n";
  for (const InlineFigure& fig : figures) html += "<figure>\n" + fig.svg + "\n</figure>\n";
  return html + "</body></html>\n";
}

}  // namespace plumb::report

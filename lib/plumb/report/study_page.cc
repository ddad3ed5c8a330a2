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

/// `v` with 3 decimals ("%.3f"), "n/a" when not finite.
std::string Short(double v) { return std::isfinite(v) ? FixedText(v, 3) : "n/a"; }

std::string Safe(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

/// A factor's value in the points table: its level's name (study::FactorLevelName) or number.
std::string LevelText(const std::string& factor, double v) {
  const std::string level = study::FactorLevelName(factor, v);
  if (!level.empty()) return level;
  return std::isfinite(v) ? Number(v) : std::string("n/a");
}

constexpr const char* kFigureStyle =
    ".figs { display: flex; flex-wrap: wrap; gap: 0.8em; }\n"
    ".figs figure { margin: 0.4em 0; flex: 1 1 460px; max-width: 640px; }\n"
    "nav.toc li { margin: 0.15em 0; }\n";

/// The figures section: what the figures show, a table of contents (a line per factor with a
/// link per parameter), then a section per factor with its figures, captioned.
std::string FiguresSection(const study::Study& study, const std::vector<study::PointSummary>& points,
                           const std::vector<InlineFigure>& figures) {
  const StudyFigurePlan plan = PlanStudyFigures(study, points);
  auto svg_of = [&](const std::string& file) -> const InlineFigure* {
    for (const InlineFigure& f : figures) {
      if (f.file == file) return &f;
    }
    return nullptr;
  };
  std::string toc, sections;
  for (std::size_t f = 0; f < study.factors.size(); ++f) {
    const std::string& name = study.factors[f].name;
    std::string links, body;
    for (const StudyFigure& fig : plan.figures) {
      const InlineFigure* drawn = fig.factor == f ? svg_of(fig.file) : nullptr;
      if (drawn == nullptr) continue;
      const std::string id = "fig-" + fig.file.substr(0, fig.file.size() - 4);
      const std::string caption =
          fig.parameter.empty() ? "NEES per degree of freedom, with its 95 % band"
                                : "error of " + WithUnit(fig.parameter, fig.unit) +
                                      ": mean over the runs, +- 1 sd, and +- the mean sigma" +
                                      (fig.first_order ? "; mean +- the first-order spread" : "");
      links += std::string(links.empty() ? "" : ", ") + "<a href=\"#" + id + "\">" +
               HtmlEscape(fig.parameter.empty() ? "NEES" : fig.parameter) + "</a>";
      body += "<figure id=\"" + id + "\">\n" + drawn->svg + "\n<figcaption>" + HtmlEscape(caption) +
              "</figcaption></figure>\n";
    }
    if (body.empty()) continue;
    const std::string unit = study::FactorUnit(name);
    const std::string heading = WithUnit(name, unit);
    toc += "<li><a href=\"#factor-" + Safe(name) + "\">" + HtmlEscape(heading) + "</a>: " + links + "</li>\n";
    sections += "<section id=\"factor-" + Safe(name) + "\">\n<h3>Against " + HtmlEscape(heading) +
                "</h3>\n<div class=\"figs\">\n" + body + "</div>\n</section>\n";
  }
  if (sections.empty()) return "";
  return "<p>Against each factor, the other factors at the first point's values: the NEES per "
         "degree of freedom with its 95 % band, and for every parameter the study scores (on one "
         "pose, the combinations the data determine) the signed error, estimate - truth, in the "
         "parameter's unit: its mean over the runs (points), +- 1 standard deviation over the runs "
         "(bars), and +- the mean sigma the fit reported (dashed). A mean outside the dashed lines "
         "is a bias the sigma does not cover. Where a factor is uncertain (its sigma), the mean +- "
         "sd_first_order (dashed, orange) is the spread over the runs its analytic sensitivity "
         "predicts. A factor whose value names a case (gravity 0: WGS84's) is drawn by level.</p>\n"
         "<nav class=\"toc\"><ul>\n" + toc + "</ul></nav>\n" + sections;
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
  return PlanStudyFigures(study, points).job;
}

std::string StudyPage(const study::Study& study, const std::vector<study::PointSummary>& points,
                      const std::vector<InlineFigure>& figures, const std::string& figure_note) {
  std::string html = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"generator\" content=\"plumb sweep\"><title>plumb sweep: " +
                     HtmlEscape(study.name) + "</title><style>" + PageStyle() + kFigureStyle +
                     "</style></head><body>\n<h1>plumb sweep: " + HtmlEscape(study.name) + "</h1>\n";
  html += "<p class=\"muted\">plumb " + HtmlEscape(Version()) + "; " + std::to_string(points.size()) +
          " points x " + std::to_string(study.runs) + " runs, seed " + std::to_string(study.seed) +
          ", method " + HtmlEscape(study.fit_method) + ", fitted model " + HtmlEscape(study.fit_model) +
          ". The numbers are in results.csv and results.json beside this page.</p>\n";
  html += "<h2>Points</h2>\n<table><tr><th>point</th>";
  for (const study::Factor& f : study.factors) {
    html += "<th>" + HtmlEscape(WithUnit(f.name, study::FactorUnit(f.name))) + "</th>";
  }
  html += "<th>runs</th><th>failed</th><th>flagged</th><th>NEES / dof</th><th>95 % band</th>"
          "<th>NEES / dof, runs not flagged</th><th>95 % band</th></tr>\n";
  for (const study::PointSummary& p : points) {
    const bool outside = p.nees_dof > 0 && (p.nees_per_dof > p.nees_high || p.nees_per_dof < p.nees_low);
    html += "<tr><td class=\"num\">" + std::to_string(p.point.index) + "</td>";
    for (std::size_t f = 0; f < p.point.values.size() && f < study.factors.size(); ++f) {
      html += "<td class=\"num\">" + LevelText(study.factors[f].name, p.point.values[f]) + "</td>";
    }
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
  html += FiguresSection(study, points, figures);
  return html + "</body></html>\n";
}

}  // namespace plumb::report

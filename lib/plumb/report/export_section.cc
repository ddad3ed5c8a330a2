#include "plumb/report/export_section.h"

#include <cmath>
#include <cstdio>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/report/html_report.h"

namespace plumb::report {
namespace {

std::string G3(double value) { return std::isfinite(value) ? Number(value, 3) : "n/a"; }

std::string Code(const std::string& text) { return "<code>" + HtmlEscape(text) + "</code>"; }
std::string NumberCell(const std::string& text) { return "<td class=\"num\">" + text + "</td>"; }

/// What the format is, in words.
std::string FormatTitle(const std::string& format) {
  if (format == "ardupilot") return "ArduPilot (Mission Planner .param)";
  if (format == "px4") return "PX4 (QGroundControl .params)";
  if (format == "kalibr") return "Kalibr (imu.yaml, noise only)";
  return format;
}

/// One row of the error table: the format, the sensor, RMS and max per axis in `unit` (SI
/// values times `factor`), the largest linear term lost per unit input in ppm.
std::string ErrorRow(const std::string& format, const std::string& sensor,
                     const exporter::AxisErrors& e, double factor, const std::string& unit,
                     const Mat3& per_input) {
  std::string row = "<tr><td>" + HtmlEscape(format) + "</td><td>" + HtmlEscape(sensor) + "</td>";
  for (int i = 0; i < 3; ++i) row += NumberCell(G3(e.rms[i] * factor));
  for (int i = 0; i < 3; ++i) row += NumberCell(G3(e.max_abs[i] * factor));
  return row + "<td>" + HtmlEscape(unit) + "</td>" + NumberCell(G3(per_input.cwiseAbs().maxCoeff() * 1e6)) +
         "</tr>\n";
}

std::string ErrorTable(const std::vector<exporter::ExportPreview>& previews) {
  std::string rows;
  int segments = 0;
  for (const auto& p : previews) {
    if (!p.output || !p.output->report) continue;
    const exporter::ExportReport& r = *p.output->report;
    segments = r.accel_still.segments;
    rows += ErrorRow(p.format, "accelerometer", r.accel_still, 1.0 / units::kMilliG, "mg",
                     r.accel_per_input);
    if (r.has_gyro) {
      rows += ErrorRow(p.format, "gyroscope", r.gyro_still, units::kDegPerHourPerRadPerS, "deg/h",
                       r.gyro_per_input);
    }
  }
  if (rows.empty()) return "";
  return "<p>The firmware's correction minus plumb's, over the " + std::to_string(segments) +
         " still segments of the fit (each segment's mean output corrected both ways):</p>\n"
         "<table>\n<tr><th rowspan=\"2\">export</th><th rowspan=\"2\">sensor</th>"
         "<th colspan=\"3\">RMS</th><th colspan=\"3\">largest</th><th rowspan=\"2\">unit</th>"
         "<th rowspan=\"2\">linear term lost, ppm of the input</th></tr>\n<tr><th>x</th><th>y</th>"
         "<th>z</th><th>x</th><th>y</th><th>z</th></tr>\n" + rows + "</table>\n";
}

/// `line` without leading blanks and a leading "note: ".
std::string Trimmed(const std::string& line) {
  const std::size_t first = line.find_first_not_of(' ');
  std::string out = first == std::string::npos ? "" : line.substr(first);
  return out.rfind("note: ", 0) == 0 ? out.substr(6) : out;
}

/// What a firmware format drops and says beyond the table and its file (`text`).
std::string FirmwareDetails(const exporter::ExportReport& r, const std::string& text) {
  std::vector<std::string> dropped;
  for (const exporter::DroppedEffect& d : r.dropped) {
    std::string text = d.effect + ":";
    for (std::size_t i = 0; i < d.names.size(); ++i) {
      text += " " + d.names[i] + " " + G3(d.values[i]) + " " + d.units[i] +
              (i + 1 < d.names.size() ? "," : "");
    }
    if (!d.seen_at_rest) text += " (acts in motion only: not in the still-segment error)";
    dropped.push_back(text);
  }
  std::string out;
  if (!dropped.empty()) out += "<p>Effects it has no parameter for (dropped):</p>\n" + HtmlList(dropped);
  std::vector<std::string> notes;  // those the file does not carry as comments
  for (const Notice& note : r.notes) {
    if (text.find("# " + note.message + "\n") == std::string::npos) notes.push_back(note.message);
  }
  if (!notes.empty()) out += HtmlList(notes);
  return out;
}

std::string FormatPart(const exporter::ExportPreview& p,
                       const std::map<std::string, std::string>& commands) {
  std::string out = "<h3>" + HtmlEscape(FormatTitle(p.format)) + "</h3>\n";
  if (!p.output) {
    return out + "<p class=\"warn\">Not written: " + HtmlEscape(p.refused) + "</p>\n";
  }
  const auto command = commands.find(p.format);
  if (command != commands.end()) {
    out += "<p>Written by:</p>\n<pre>" + HtmlEscape(command->second) + "</pre>\n";
  }
  if (p.output->report) {
    out += FirmwareDetails(*p.output->report, p.output->text);
  } else {
    std::vector<std::string> lines;
    for (const std::string& line : p.output->lines) lines.push_back(Trimmed(line));
    out += HtmlList(lines);
  }
  const std::size_t count = p.output->parameters ? p.output->parameters->parameters.size() : 0;
  out += "<p>The file" + (count > 0 ? " (" + std::to_string(count) + " parameters)" : std::string()) +
         (p.output->report ? ", with its notes as comments" : "") + ":</p>\n<pre>" + HtmlEscape(p.output->text) + "</pre>\n";
  return out;
}

}  // namespace

std::string ExportSection(const std::vector<exporter::ExportPreview>& previews,
                          const std::map<std::string, std::string>& commands,
                          const std::string& note) {
  std::string out = "<h2 id=\"firmware\">Firmware</h2>\n";
  if (previews.empty()) {
    return out + "<p class=\"muted\">Not computed" + (note.empty() ? "." : ": " + HtmlEscape(note)) +
           "</p>\n";
  }
  out += "<p>What " + Code("plumb calibrate --export FORMAT=FILE") + " would write from this "
         "calibration, and what it leaves. ArduPilot and PX4 correct each axis on its own "
         "(an offset, an accelerometer scale, a temperature polynomial), so the cross-axis terms "
         "of F and E, the gyroscope scales and plumb's other effects are lost; each file is read "
         "back into the correction the firmware applies and compared with plumb's.</p>\n";
  if (!note.empty()) out += "<p class=\"warn\">" + HtmlEscape(note) + "</p>\n";
  out += ErrorTable(previews);
  for (const auto& p : previews) out += FormatPart(p, commands);
  return out;
}

}  // namespace plumb::report

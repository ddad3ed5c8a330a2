#include "plumb/report/html_report.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/model/board_mount.h"
#include "plumb/estimation/uncertainty.h"
#include "plumb/report/calibration_text.h"
#include "plumb/report/export_section.h"
#include "plumb/report/noise_text.h"
#include "plumb/report/summary.h"
#include "plumb/report/version.h"
#include "plumb/signal/chi_square.h"

namespace plumb::report {
namespace {

/// Two-sided probability outside the band of chi^2/dof drawn on the page.
/// Unobservable directions name at most this many of their terms in words.
constexpr std::size_t kNamedTerms = 6;

const char kStyle[] = R"css(
body { font-family: system-ui, sans-serif; max-width: 1060px; margin: 2em auto; padding: 0 1em;
       color: #222; line-height: 1.4; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.25em; border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { border: 1px solid #ddd; padding: 0.2em 0.6em; text-align: left; vertical-align: top; }
th { background: #f3f5f8; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
code, pre { font-family: ui-monospace, monospace; font-size: 0.92em; }
pre { background: #f6f8fa; padding: 0.8em; overflow-x: auto; white-space: pre-wrap; }
.ok { background: #e8f5e9; border-left: 4px solid #2e7d32; padding: 0.5em 0.8em; }
.bad { background: #fff3e0; border-left: 4px solid #e65100; padding: 0.5em 0.8em; }
.warn { color: #8a4b00; }
.muted { color: #666; }
figure { margin: 1em 0; }
figure svg { display: block; max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.92em; color: #444; }
)css";

/// `value` to `digits` significant digits, "n/a" when not finite.
std::string Shown(double value, int digits) {
  return std::isfinite(value) ? Number(value, digits) : "n/a";
}
std::string G6(double value) { return Shown(value, 6); }
std::string G3(double value) { return Shown(value, 3); }
std::string G2(double value) { return Shown(value, 2); }

std::string Td(const std::string& html) { return "<td>" + html + "</td>"; }
std::string TdNum(const std::string& html) { return "<td class=\"num\">" + html + "</td>"; }
std::string Th(const std::string& html) { return "<th>" + html + "</th>"; }
std::string Code(const std::string& text) { return "<code>" + HtmlEscape(text) + "</code>"; }

/// A header row from plain-text column names.
std::string HeaderRow(const std::vector<std::string>& names) {
  std::string row = "<tr>";
  for (const auto& n : names) row += Th(HtmlEscape(n));
  return row + "</tr>\n";
}

/// A two-column row: `what` (plain text) and `html`.
std::string KeyRow(const std::string& what, const std::string& html) {
  return "<tr>" + Th(HtmlEscape(what)) + Td(html) + "</tr>\n";
}

std::string VecCells(const Vec3& v) { return TdNum(G3(v.x())) + TdNum(G3(v.y())) + TdNum(G3(v.z())); }

std::string SiteSourceWords(const std::string& source) {
  if (source == "flags") return "the command-line flags";
  if (source == "gps") return "the log's GPS";
  if (source == "file") return "the input file";
  return source;
}

/// The command to run next, as a paragraph and a block to copy ("" without one).
std::string NextCommandHtml(const std::string& command) {
  if (command.empty()) return "";
  return "<p>Next: the refit diagnose advises (it lowers this fit's chi2/dof):</p>\n"
         "<pre class=\"next\">" + HtmlEscape(command) +
         "</pre>\n";
}

std::string SummarySection(const estimation::CalibrationResult& r,
                           const diagnostics::Diagnosis* d, const std::string& next_command) {
  const auto band = estimation::Chi2Band(r.fit.dof);
  const double ratio = r.fit.chi2_dof();
  // "ok" exactly when the verdict says consistent (one meaning, estimation::Chi2Band).
  const bool good = r.fit.dof > 0 && ratio >= band.first && ratio <= band.second &&
                    r.fit.gates.empty();
  std::string out = "<h2 id=\"summary\">Summary</h2>\n<p class=\"" +
                    std::string(good ? "ok" : "bad") + "\">" + HtmlEscape(FitVerdict(r.fit)) +
                    "</p>\n<ul>\n";
  for (const auto& g : r.fit.gates) {
    out += "<li class=\"warn\">gate failed: " + Code(g.name) + ": " + HtmlEscape(g.message) +
           "</li>\n";
  }
  int free = 0;
  for (const auto& p : r.calibration.parameters) free += p.fixed ? 0 : 1;
  out += "<li>" + std::to_string(free) + " parameters fitted (model " + Code(r.calibration.model.spec()) +
         ", method " + HtmlEscape(r.calibration.method) + ") on " + std::to_string(r.fit.still_segments) +
         " still segments and " + std::to_string(r.fit.motion_segments) +
         " motion intervals.</li>\n";
  const std::size_t lost = r.calibration.observability.unobservable.size();
  out += lost == 0 ? std::string("<li>Every parameter is determined by the data.</li>\n")
                   : "<li class=\"warn\">" + std::to_string(lost) +
                         " unobservable direction" + (lost > 1 ? "s" : "") +
                         ": see <a href=\"#observability\">observability</a>.</li>\n";
  if (d != nullptr) {
    const diagnostics::Candidate* best = diagnostics::Recommended(*d);
    const bool any_significant =
        std::any_of(d->candidates.begin(), d->candidates.end(),
                    [](const diagnostics::Candidate& c) { return c.significant; });
    if (best != nullptr) {
      out += "<li class=\"warn\">Most likely missing: " + Code(best->effect) +
             " (predicted fall of chi2 " + G3(best->lm) + "; the refit with it has chi2/dof " +
             G3(best->refit->fit.chi2_dof()) + " against " + G3(d->fit.fit.chi2_dof()) +
             "): see <a href=\"#diagnosis\">missing effects</a>.</li>\n";
    } else if (any_significant) {
      out += "<li>Nothing advised: no significant effect of the catalogue lowers this fit's "
             "chi2/dof when refitted (see <a href=\"#diagnosis\">missing effects</a>).</li>\n";
    } else {
      out += "<li>No effect of the catalogue is significantly missing at the " +
             G2(100.0 * d->significance) + " % level.</li>\n";
    }
  }
  return out + "</ul>\n" + NextCommandHtml(next_command);
}

std::string SiteHtml(const geo::Site& site) {
  if (site.known) {
    return G6(site.lat_deg) + "&deg; N, " + G6(site.lon_deg) + "&deg; E, " + G6(site.height_m) +
           " m (from " + HtmlEscape(SiteSourceWords(site.source)) + "); gravity " +
           G6(site.gravity()) + " m/s^2";
  }
  return "<span class=\"warn\">none: gravity fixed at " + G6(site.gravity()) +
         " m/s^2 and the Earth rate left out. The gyroscope biases absorb the Earth rate "
         "(up to 7.3e-5 rad/s) and the accelerometer scales take the gravity error; give "
         "--lat --lon --height, or use a log with GPS.</span>";
}

std::string InputSection(const InputSummary& in, const segmentation::SegmentationResult& seg,
                         const estimation::CalibrationResult& r, const PageExtras& extras) {
  std::string out = "<h2 id=\"input\">Input</h2>\n<table>\n";
  out += KeyRow("source", HtmlEscape(in.source));
  if (!in.inputs.empty()) {
    std::string files;
    for (const auto& f : in.inputs) files += (files.empty() ? "" : "<br>") + Code(f);
    out += KeyRow("inputs", files);
  }
  out += KeyRow("samples", std::to_string(in.samples));
  out += KeyRow("rate", in.rate_hz > 0 ? G6(in.rate_hz) + " Hz" : std::string("unknown"));
  out += KeyRow("duration", G6(in.duration_s) + " s");
  out += KeyRow("sensors", "accelerometer (" + HtmlEscape(in.acc_unit) + ")" +
                               (in.has_gyro ? ", gyroscope (" + HtmlEscape(in.gyr_unit) + ")"
                                            : std::string(", no gyroscope")));
  out += KeyRow("temperature", in.has_temperature ? G3(in.temp_min_c) + " to " +
                                                        G3(in.temp_max_c) + " degC"
                                                  : std::string("none"));
  out += KeyRow("site", SiteHtml(r.calibration.site));
  const std::string how = seg.report.method == "given"
                              ? "given" + (extras.segments_source.empty()
                                               ? std::string()
                                               : " in " + Code(extras.segments_source))
                              : std::string("detected (window ") + G3(seg.report.window_s) +
                                    " s, shortest kept " + G3(seg.report.min_still_s) + " s)";
  out += KeyRow("still segments", std::to_string(seg.segments.size()) + ", " + how);
  out += "</table>\n";
  if (!in.warnings.empty()) out += "<p>Reader warnings:</p>\n" + HtmlList(in.warnings, "warn");
  return out;
}

std::string ModelSection(const estimation::CalibrationResult& r) {
  std::string out = "<h2 id=\"model\">Model</h2>\n<p>Spec " + Code(r.calibration.model.spec()) +
                    ", method " + HtmlEscape(r.calibration.method) + "; reference time " +
                    G6(r.calibration.model.t_ref_s) + " s, reference temperature " +
                    G6(r.calibration.model.temp_ref_c) + " degC. Forward model y_a = F f_b + b_a + "
                    "(effects), y_g = E omega_b + b_g + (effects), body frame FRD.</p>\n<table>\n" +
                    HeaderRow({"effect", "term in the forward model", "parameters"});
  for (const auto& term : r.calibration.model.terms()) {
    const auto& info = term.effect->info();
    out += "<tr>" + Td(Code(info.name + (info.option.empty() ? "" : ":" + info.option))) +
           Td(Code(info.term)) + TdNum(std::to_string(info.size())) + "</tr>\n";
  }
  return out + "</table>\n";
}

/// "0.41 &rarr; 0.17" in `scale` units, the "after" marked when beyond `limit`.
std::string BeforeAfterCell(double before, double after, double limit, double scale) {
  const std::string shown = G2(after * scale);
  return TdNum(G2(before * scale) + " &rarr; " +
               (after > limit ? "<span class=\"warn\">" + shown + "</span>" : shown));
}

/// The board's other IMUs (SPEC 6): each one's rotation into the body with its sigma, and its
/// disagreement with IMU 0 at rest before and after the calibration against ArduPilot's
/// pre-arm check (estimation/board_agreement.h).
std::string BoardSection(const estimation::CalibrationResult& r, const PageExtras& extras) {
  const estimation::Calibration& c = r.calibration;
  if (c.board.empty()) return "";
  const double scale = estimation::SigmaScale(r.fit);
  std::string out =
      "<h2 id=\"board\">The board's IMUs</h2>\n<p>Fitted with IMU 0, the still attitudes "
      "shared; IMU 0's accelerometer defines the body frame. The rotation is each IMU's frame "
      "into the body (rotation vector, deg, &plusmn; sigma); the disagreement is the largest "
      "over the still poses, as ArduPilot's pre-arm check measures it (accelerometers: z "
      "halved, within " + G2(estimation::kArduPilotAccelThreshold_m_s2) + " m/s^2, " +
      G2(estimation::kArduPilotAccelThreshold_m_s2 * estimation::kArduPilotThirdImuFactor) +
      " from IMU3 on; gyroscopes within " +
      G2(estimation::kArduPilotGyroThreshold_rad_s * units::kDegPerRad) +
      " deg/s), before &rarr; after the calibration, and what is left once the IMUs' turn is "
      "taken out. The firmware turns every IMU by one board orientation, so their turn "
      "between them stays in its comparison.</p>\n<table>\n" +
      HeaderRow({"IMU", "model", "rotation into the body (deg)", "accel (m/s^2)",
                 "accel, turned", "gyro (deg/s)", "gyro, turned"});
  for (std::size_t k = 0; k < c.board.size(); ++k) {
    const estimation::BoardImuCalibration& b = c.board[k];
    std::string rotation;
    if (b.RotationDetermined()) {
      const Eigen::AngleAxisd aa(b.R_b_i());
      const Vec3 rho = aa.angle() * aa.axis() * units::kDegPerRad;
      for (int i = 0; i < 3; ++i) {
        rotation += (i ? ", " : "") + G3(rho[i]) + " &plusmn; " +
                    G2(scale * b.MountParameter(model::board_mount::kRotation + i).sigma *
                       units::kDegPerRad);
      }
    } else {
      rotation = "not determined by these data (see the observability section)";
    }
    out += "<tr>" + Td("imu" + std::to_string(b.instance)) + Td(Code(b.model.spec())) +
           Td(rotation);
    const estimation::ImuAgreement* a = nullptr;
    for (const auto& each : extras.board_agreement) {
      if (each.instance == b.instance) a = &each;
    }
    if (a == nullptr) {
      out += Td("") + Td("") + Td("") + Td("") + "</tr>\n";
      continue;
    }
    out += BeforeAfterCell(a->accel_before, a->accel_after, a->accel_limit, 1.0) +
           TdNum(G2(a->accel_in_body));
    if (a->has_gyro) {
      out += BeforeAfterCell(a->gyro_before, a->gyro_after,
                             estimation::kArduPilotGyroThreshold_rad_s, units::kDegPerRad) +
             TdNum(G2(a->gyro_in_body * units::kDegPerRad));
    } else {
      out += Td("no gyroscope") + Td("");
    }
    out += "</tr>\n";
  }
  out += "</table>\n";
  if (extras.board_diagnosis.empty()) {
    return out + "<p>The diagnosis below is IMU 0's; " + Code("plumb diagnose --imus") +
           " diagnoses each IMU alone and the board across.</p>\n";
  }
  return out + "<p>Each IMU alone against its noise (a misfit of its own is named with the "
               "effect it misses), the board together against them (do the IMUs move as one "
               "rigid board?), and the board refitted with each IMU's advice, as " +
         Code("plumb diagnose --imus") + " finds them; the diagnosis below is IMU 0's alone:</p>\n"
         "<pre>" + HtmlEscape(extras.board_diagnosis) + "</pre>\n";
}

std::string FitSection(const estimation::CalibrationResult& r) {
  const auto& f = r.fit;
  const auto band = estimation::Chi2Band(f.dof);
  std::string out = "<h2 id=\"fit\">Fit quality</h2>\n<table>\n";
  out += KeyRow("chi2", G6(f.chi2) + " over " + std::to_string(f.num_residuals) +
                            " whitened residuals");
  out += KeyRow("degrees of freedom", std::to_string(f.dof));
  out += KeyRow("chi2/dof", "<b>" + G3(f.chi2_dof()) +
                                "</b> (band of a complete model, 1 &plusmn; 3 sqrt(2/dof): " +
                                G3(band.first) + " to " + G3(band.second) + ")");
  out += KeyRow("verdict", HtmlEscape(FitVerdict(f)));
  out += KeyRow("solver", std::string(f.converged ? "converged" : "<span class=\"warn\">not "
                                                                  "converged</span>") +
                              " after " + std::to_string(f.iterations) + " iterations");
  out += KeyRow("sigmas from", HtmlEscape(r.calibration.sigma_source.empty() ? "n/a" : r.calibration.sigma_source));
  out += "</table>\n<p>Residual RMS per axis (measured minus predicted):</p>\n<table>\n" +
         HeaderRow({"residual", "unit", "x", "y", "z"});
  out += "<tr>" + Td("still accelerometer") + Td(HtmlEscape(r.calibration.acc_unit)) + VecCells(f.rms_acc) +
         "</tr>\n";
  if (r.calibration.has_gyro) {
    out += "<tr>" + Td("still gyroscope") + Td(HtmlEscape(r.calibration.gyr_unit)) + VecCells(f.rms_gyr) +
           "</tr>\n";
  }
  if (f.motion_segments > 0) {
    out += "<tr>" + Td("motion rotation") + Td("rad") + VecCells(f.rms_motion) + "</tr>\n";
  }
  if (f.velocity_segments > 0) {
    out += "<tr>" + Td("motion velocity") + Td("m/s") + VecCells(f.rms_velocity) + "</tr>\n";
  }
  out += "<tr>" + Td("noise per sample, accelerometer") + Td(HtmlEscape(r.calibration.acc_unit)) +
         VecCells(r.calibration.noise.acc) + "</tr>\n";
  if (r.calibration.has_gyro) {
    out += "<tr>" + Td("noise per sample, gyroscope") + Td(HtmlEscape(r.calibration.gyr_unit)) +
           VecCells(r.calibration.noise.gyr) + "</tr>\n";
  }
  return out + "</table>\n";
}

/// One cell of the noise table: value (with "<" for a bound), datasheet value, tau range.
std::string NoiseCell(const signal::NoiseTerm& t, const NoiseTermLabel& label) {
  const std::string mark = t.resolved ? "" : "&lt; ";
  std::string cell = mark + G3(t.value());
  if (!label.datasheet_unit.empty()) {
    cell += "<br><span class=\"muted\">" + mark + G3(t.value() * label.datasheet_scale) + " " +
            HtmlEscape(label.datasheet_unit) + "</span>";
  }
  const std::string tau = t.resolved && t.tau_min_s != t.tau_max_s
                              ? G3(t.tau_min_s) + "&ndash;" + G3(t.tau_max_s)
                              : G3(t.tau_min_s);
  return TdNum(cell + "<br><span class=\"muted\">tau " + tau + " s</span>");
}

std::string NoiseSection(const PageExtras& extras) {
  std::string out = "<h2 id=\"noise\">Sensor noise</h2>\n";
  if (!extras.still_noise) {
    return out + "<p class=\"muted\">Not measured" +
           (extras.still_noise_note.empty() ? std::string(".")
                                            : ": " + HtmlEscape(extras.still_noise_note)) +
           "</p>\n";
  }
  const signal::StillNoise& n = *extras.still_noise;
  out += "<p>IEEE Std 952 noise terms fitted to the overlapping Allan deviation of " +
         G3(n.still_s) + " s of still data (" + std::to_string(n.segments.size()) +
         " still segment(s) pooled, the longest " + G3(n.longest_s) +
         " s), as <code>plumb allan</code> measures them: weighted least squares with "
         "non-negative coefficients. &lt; marks an upper bound (at " +
         G2(100.0 * n.options.terms.term_confidence) +
         " %): the data does not resolve that term. Each cell: the value in the unit of the "
         "row, the datasheet unit, and the cluster times it was read from. The points, their "
         "intervals and the fit are in <code>allan.json</code>.</p>\n";
  for (signal::Sensor sensor : {signal::Sensor::kAccel, signal::Sensor::kGyro}) {
    if (n.Find(sensor, 0) == nullptr) continue;
    const std::string unit = sensor == signal::Sensor::kAccel ? n.acc_unit : n.gyr_unit;
    out += "<h3>" + HtmlEscape(signal::SensorName(sensor)) + "</h3>\n<table>\n" +
           HeaderRow({"term", "unit", "x", "y", "z"});
    for (int k = 0; k < signal::kNoiseTermCount; ++k) {
      const auto kind = static_cast<signal::NoiseTermKind>(k);
      const NoiseTermLabel label = LabelNoiseTerm(sensor, kind, unit);
      out += "<tr>" + Td(HtmlEscape(std::string(signal::NoiseTermSymbol(kind)) + " " +
                                    label.name)) +
             Td(HtmlEscape(label.unit));
      for (int axis = 0; axis < 3; ++axis) {
        const signal::AxisNoise* a = n.Find(sensor, axis);
        out += a != nullptr ? NoiseCell(a->fit.term(kind), label) : TdNum("&ndash;");
      }
      out += "</tr>\n";
    }
    out += "</table>\n";
  }
  for (const signal::AxisNoise& a : n.axes) {
    if (!a.fit.misfit) continue;
    out += "<p class=\"warn\">" + HtmlEscape(std::string(signal::SensorName(a.sensor)) + " " +
                                              "xyz"[a.axis] + ": " + MisfitWords(a, n)) +
           "</p>\n";
  }
  for (const std::string& note : n.notes) {
    out += "<p class=\"muted\">" + HtmlEscape(note) + "</p>\n";
  }
  return out;
}

/// "series" of "series.svg".
std::string FigureStem(const std::string& file) { return file.substr(0, file.rfind('.')); }

std::string FigureSection(const PageExtras& extras) {
  std::string out = "<h2 id=\"figures\">Figures</h2>\n";
  for (const auto& note : extras.figure_notes) {
    out += "<p class=\"warn\">No figures: " + HtmlEscape(note) + "</p>\n";
  }
  for (const auto& fig : extras.figures) {
    out += "<figure id=\"figure-" + HtmlEscape(FigureStem(fig.file)) + "\">\n" + fig.svg +
           "\n<figcaption><b>" + HtmlEscape(fig.title) + ".</b> " + HtmlEscape(fig.caption) +
           "</figcaption></figure>\n";
  }
  return out;
}

std::string ParameterSection(const estimation::CalibrationResult& r) {
  // Above its band, chi^2/dof scales the sigma (estimation/uncertainty.h): both columns, and
  // the note the terminal prints beside them.
  const double scale = estimation::SigmaScale(r.fit);
  const bool scaled = scale > 1.0;
  std::string out = "<h2 id=\"parameters\">Parameters</h2>\n<p>Forward-model quantities, SI "
                    "(sample units for biases and additive terms); sigma is one standard "
                    "deviation.</p>\n";
  if (scaled) {
    std::istringstream note(OverDispersionNote(r.fit));
    for (std::string line; std::getline(note, line);) {
      out += "<p class=\"warn\">" + HtmlEscape(line) + "</p>\n";
    }
  }
  out += "<table>\n" + (scaled ? HeaderRow({"parameter", "value", "sigma", "scaled sigma", "unit", "status"})
                               : HeaderRow({"parameter", "value", "sigma", "unit", "status"}));
  for (const auto& p : r.calibration.parameters) {
    const std::string status = p.fixed ? "fixed" : !p.observable ? "unobservable" : "";
    const bool none = p.fixed || !p.observable;
    out += "<tr>" + Td(Code(p.name)) + TdNum(G6(p.value)) +
           TdNum(none ? "&ndash;" : "&plusmn; " + G2(p.sigma)) +
           (scaled ? TdNum(none ? "&ndash;" : "&plusmn; " + G2(scale * p.sigma)) : std::string()) +
           Td(HtmlEscape(p.unit)) +
           Td(status.empty() ? std::string() : "<span class=\"warn\">" + status + "</span>") +
           "</tr>\n";
  }
  return out + "</table>\n";
}

std::string MatrixTable(const Mat3& m) {
  std::string out = "<table>\n";
  for (int i = 0; i < 3; ++i) {
    out += "<tr>";
    for (int j = 0; j < 3; ++j) out += TdNum(G6(m(i, j)));
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

std::string VectorTable(const Vec3& v) {
  return "<table>\n<tr>" + TdNum(G6(v.x())) + TdNum(G6(v.y())) + TdNum(G6(v.z())) +
         "</tr>\n</table>\n";
}

/// One sensor's forward matrix, bias and the correction x = M^-1 (y - b).
std::string SensorMatrices(const std::string& sensor, const std::string& m, const std::string& b,
                           const Mat3& matrix, const Vec3& bias) {
  const Eigen::FullPivLU<Mat3> lu(matrix);
  std::string out = "<h3>" + HtmlEscape(sensor) + "</h3>\n<p>" + Code(m) + " (forward):</p>\n" +
                    MatrixTable(matrix) + "<p>" + Code(b) + ":</p>\n" + VectorTable(bias);
  out += lu.isInvertible()
             ? "<p>Correction " + Code(m + "^-1") + ", applied as " +
                   Code(m + "^-1 (y - " + b + ")") + ":</p>\n" + MatrixTable(lu.inverse())
             : std::string("<p class=\"warn\">The matrix is singular: no correction.</p>\n");
  return out;
}

std::string MatrixSection(const estimation::CalibrationResult& r) {
  std::string out = "<h2 id=\"correction\">Forward model and correction</h2>\n";
  out += SensorMatrices("Accelerometer", "F", "b_a", r.calibration.AccelMatrix(), r.calibration.AccelBias());
  if (r.calibration.has_gyro) out += SensorMatrices("Gyroscope", "E", "b_g", r.calibration.GyroMatrix(), r.calibration.GyroBias());
  return out;
}

/// The names in a direction "a p1 + b p2 - ..." (tokens that start with a letter).
std::vector<std::string> NamesIn(const std::string& direction) {
  std::vector<std::string> names;
  std::istringstream tokens(direction);
  std::string token;
  while (tokens >> token) {
    if (std::isalpha(static_cast<unsigned char>(token.front()))) names.push_back(token);
  }
  return names;
}

/// An unobservable direction in words: which parameters the data cannot tell apart.
std::string DirectionWords(const std::string& direction) {
  const std::vector<std::string> names = NamesIn(direction);
  if (names.size() == 1) {
    return "The data does not determine " + Code(names.front()) + " at all (" + Code(direction) +
           ").";
  }
  // The largest terms lead; a long direction names the first few and counts the rest.
  const std::size_t shown = names.size() > kNamedTerms + 1 ? kNamedTerms : names.size();
  std::string list;
  for (std::size_t i = 0; i < shown; ++i) {
    list += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + Code(names[i]);
  }
  if (shown < names.size()) list += " and " + std::to_string(names.size() - shown) + " more";
  return "The data cannot tell apart " + list + ": moving them together along " +
         Code(direction) + " changes no prediction.";
}

std::string ObservabilitySection(const estimation::CalibrationResult& r) {
  const auto& o = r.calibration.observability;
  std::string out = "<h2 id=\"observability\">Observability</h2>\n<p>Rank " +
                    std::to_string(o.rank) + " of " + std::to_string(o.num_unknowns) +
                    " unknowns (parameters and attitudes).</p>\n";
  if (o.unobservable.empty()) {
    return out + "<p>Every parameter is determined by the data.</p>\n";
  }
  out += "<p>Some combinations of parameters are not determined by this data: any split "
         "between the parameters of each fits equally well, so their separate values and sigmas "
         "mean nothing; use the determined combinations below, or record poses or motions that "
         "excite them.</p>\n<ul>\n";
  for (const auto& u : o.unobservable) out += "<li>" + DirectionWords(u) + "</li>\n";
  out += "</ul>\n";
  if (o.determined.empty()) return out;
  out += "<p>What the data does determine:</p>\n<table>\n" +
         HeaderRow({"combination", "value", "sigma"});
  for (const auto& d : o.determined) {
    out += "<tr>" + Td(Code(d.text)) + TdNum(G6(d.value)) + TdNum("&plusmn; " + G2(d.sigma)) +
           "</tr>\n";
  }
  return out + "</table>\n";
}

std::string YesNo(bool value) { return value ? "yes" : "no"; }

/// Why one parameter of a candidate cannot be judged, in words.
std::string ConfoundingWords(const diagnostics::Confounding& n) {
  if (!n.excited) return n.parameter + " is not excited by this data";
  if (n.too_weak) {
    return n.parameter + " is determined only to " + G3(n.sigma) + ", its typical size is " +
           G3(n.typical);
  }
  std::string with;
  for (const auto& c : n.confounders) with += (with.empty() ? "" : ", ") + c;
  return n.parameter + " is confounded with " + (with.empty() ? std::string("the fit") : with);
}

/// The candidate's notes: the divisor of its LM, the candidates it cannot be told from.
std::string CandidateNotes(const diagnostics::Candidate& c) {
  std::string notes;
  if (c.with_velocity) notes = "scored in the fit with velocity residuals";
  if (c.dispersion > 1.0) {
    notes += "; LM divided by " + G3(c.dispersion) + " (the velocity residuals' misfit)";
  }
  if (!c.indistinguishable_from.empty()) {
    std::string others;
    for (const auto& o : c.indistinguishable_from) others += (others.empty() ? "" : ", ") + o;
    notes += (notes.empty() ? "" : "; ") + std::string("indistinguishable here from ") + others;
  }
  return notes;
}

/// The fit with velocity residuals where some candidates are scored, in words ("" without).
std::string VelocityFitWords(const diagnostics::Diagnosis& d) {
  if (!d.fit_with_velocity ||
      d.fit_with_velocity->fit.velocity_segments <= d.fit.fit.velocity_segments) {
    return "";
  }
  const auto& v = d.fit_with_velocity->fit;
  return " The candidates that need the accelerometer during the turns (noted in the table) are "
         "scored, and their refit drop measured, in the fit with velocity residuals: chi2 " +
         G3(v.chi2) + " on " + std::to_string(v.dof) + " dof, chi2/dof " + G3(v.chi2_dof()) + ".";
}

std::string CandidateRow(const diagnostics::Candidate& c) {
  return "<tr>" + Td(Code(c.effect + (c.option.empty() ? "" : ":" + c.option))) +
         TdNum(G3(c.lm)) + TdNum(std::to_string(c.dof)) + TdNum(G3(c.evidence)) +
         TdNum(G3(c.threshold)) +
         Td(c.significant ? "<b>yes</b>" : std::string("no")) + Td(YesNo(c.identifiable)) +
         TdNum(c.refit_drop ? G3(*c.refit_drop) : std::string("&ndash;")) +
         TdNum(c.refit ? G3(c.refit->fit.chi2_dof()) : std::string("&ndash;")) +
         Td(c.refit ? (c.recommended ? "<b>yes</b>" : std::string("no")) : "&ndash;") +
         Td(HtmlEscape(CandidateNotes(c))) + "</tr>\n";
}

std::string DiagnosisSection(const diagnostics::Diagnosis* d, const std::string& next_command) {
  std::string out = "<h2 id=\"diagnosis\">Missing effects</h2>\n";
  if (d == nullptr) return out + "<p class=\"muted\">Not run (--no-diagnose).</p>\n";
  out += "<p>The score test of every catalogue effect not in the model, at the fit: LM is the "
         "predicted fall of chi2 if the effect were added (chi2 with q degrees of freedom when "
         "it is not missing), ranked by evidence = LM - q ln N (N = " +
         std::to_string(d->num_residuals) + " residuals); significant when LM exceeds the "
         "threshold (level " + G2(d->significance) + ") and the effect is identifiable; the "
         "best ones refitted. An effect is advised only when its refit, made as you would "
         "make it, has a lower chi2/dof than this fit (" + G3(d->fit.fit.chi2_dof()) + ")." +
         VelocityFitWords(*d) + "</p>\n<table>\n" +
         HeaderRow({"effect", "LM", "q", "evidence", "threshold", "significant", "identifiable",
                    "refit drop", "chi2/dof after", "advised", "notes"});
  std::vector<std::string> notes;
  for (const auto& c : d->candidates) {
    out += CandidateRow(c);
    if (c.not_identifiable.empty()) continue;
    std::string why;
    for (const auto& n : c.not_identifiable) why += (why.empty() ? "" : "; ") + ConfoundingWords(n);
    notes.push_back(c.effect + ": " + why);
  }
  out += "</table>\n";
  if (!notes.empty()) out += "<p>Not identifiable from this data (not absent):</p>\n" + HtmlList(notes);
  std::vector<std::string> skipped;
  for (const auto& s : d->skipped) skipped.push_back(s.effect + ": " + s.reason);
  if (!skipped.empty()) out += "<p>Not tested:</p>\n" + HtmlList(skipped, "muted");
  return out + NextCommandHtml(next_command);
}

std::string WorstSection(const diagnostics::ResidualAnalysis& a) {
  std::string out = "<h2 id=\"worst\">Where the model fits worst</h2>\n";
  if (a.worst.empty()) return out + "<p class=\"muted\">No residual ranges.</p>\n";
  out += "<p>The largest whitened residual components (in standard deviations; above about 3 "
         "is unlikely under a complete model):</p>\n<table>\n" +
         HeaderRow({"range", "residual", "axis", "score (sigma)"});
  for (const auto& w : a.worst) {
    out += "<tr>" + Td(HtmlEscape(w.name)) +
           Td(HtmlEscape(diagnostics::ResidualKindName(w.residual))) +
           Td(std::string(1, "xyz"[w.axis])) + TdNum(G3(w.score)) + "</tr>\n";
  }
  out += "</table>\n";
  std::string rows;
  for (const auto& s : a.signatures) {
    if (!s.significant) continue;
    rows += "<tr>" + Td(HtmlEscape(std::string(diagnostics::ResidualKindName(s.residual)) + " " +
                                   "xyz"[s.axis])) +
            Td(HtmlEscape(s.regressor + " (" + s.unit + ")")) + TdNum(G2(s.correlation)) +
            TdNum(G3(s.slope_residual) + " &plusmn; " + G2(s.slope_residual_sigma)) +
            TdNum(G2(s.p_value)) + "</tr>\n";
  }
  if (rows.empty()) {
    return out + "<p>No residual signature is significant (" + std::to_string(a.num_tests) +
           " tests, p below " + G2(a.p_threshold) + ").</p>\n";
  }
  return out + "<p>Significant residual signatures (p below " + G2(a.p_threshold) + ", " +
         std::to_string(a.num_tests) + " tests):</p>\n<table>\n" +
         HeaderRow({"residual", "against", "correlation", "slope", "p"}) + rows + "</table>\n";
}

std::string TailSection(const estimation::CalibrationResult& r, const PageExtras& extras) {
  std::string out;
  if (!r.fit.warnings.empty()) {
    out += "<h2 id=\"warnings\">Warnings</h2>\n" + HtmlList(Messages(r.fit.warnings), "warn");
  }
  if (!extras.files.empty()) {
    out += "<h2 id=\"files\">Files</h2>\n<p>Written beside this page in its folder, for other "
           "programs (the page needs none of them):</p>\n<ul>\n";
    for (const auto& f : extras.files) out += "<li>" + Code(f) + "</li>\n";
    out += "</ul>\n";
  }
  out += "<h2 id=\"reproduce\">Reproduce</h2>\n<pre>" + HtmlEscape(extras.command) + "</pre>\n";
  out += "<p class=\"muted\">Made by plumb " + HtmlEscape(Version()) + ".</p>\n";
  return out;
}

}  // namespace

const char* PageStyle() { return kStyle; }

std::string HtmlList(const std::vector<std::string>& items, const std::string& css_class) {
  if (items.empty()) return "";
  std::string out = css_class.empty() ? "<ul>\n" : "<ul class=\"" + css_class + "\">\n";
  for (const auto& item : items) out += "<li>" + HtmlEscape(item) + "</li>\n";
  return out + "</ul>\n";
}

std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}


std::string HtmlReport(const InputSummary& input,
                       const segmentation::SegmentationResult& segmentation,
                       const estimation::CalibrationResult& result,
                       const diagnostics::ResidualAnalysis& analysis,
                       const diagnostics::Diagnosis* diagnosis, const PageExtras& extras) {
  std::string page = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                     "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
                     "<meta name=\"generator\" content=\"plumb report\">\n"
                     "<title>" + HtmlEscape(extras.title) + "</title>\n<style>" + kStyle +
                     "</style>\n</head>\n<body>\n<h1>" + HtmlEscape(extras.title) + "</h1>\n" +
                     "<p class=\"muted\">" + HtmlEscape(input.source) + "</p>\n";
  page += SummarySection(result, diagnosis, extras.next_command);
  page += InputSection(input, segmentation, result, extras);
  page += ModelSection(result);
  page += FitSection(result);
  page += NoiseSection(extras);
  page += FigureSection(extras);
  page += ParameterSection(result);
  page += MatrixSection(result);
  page += BoardSection(result, extras);
  page += ExportSection(extras.exports, extras.export_commands, extras.exports_note);
  page += ObservabilitySection(result);
  page += DiagnosisSection(diagnosis, extras.next_command);
  page += WorstSection(analysis);
  page += TailSection(result, extras);
  return page + "</body>\n</html>\n";
}

}  // namespace plumb::report

#include "plumb/report/figures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "plumb/core/number_text.h"
#include "plumb/core/error.h"
#include "plumb/report/inline_svg.h"

namespace plumb::report {
namespace {

using diagnostics::ResidualKind;

/// Line colours of the x, y and z axes in every figure.
constexpr const char* kAxisColour[3] = {"#d62728", "#2ca02c", "#1f77b4"};
constexpr const char* kAxisName[3] = {"x", "y", "z"};
/// Fill of the still segments in series.svg.
constexpr const char* kStillShade = "#dce6f2";
/// Whitened residuals beyond this many sigma are unlikely under a complete model.
constexpr double kWhitenedBand = 3.0;

/// A CSV cell: 9 significant digits, empty when not finite (gnuplot skips empty fields).
std::string Cell(double value) {
  if (!std::isfinite(value)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", value);
  return buf;
}

void Cells(std::ostringstream& os, const Vec3& v, bool present) {
  for (int i = 0; i < 3; ++i) os << "," << (present ? Cell(v[i]) : std::string());
}

/// `plot` clauses of three columns (x, y, z) of `file` starting at `first_column`, against
/// column `x_column`, in the axis colours.
std::string AxisClauses(const std::string& file, int x_column, int first_column,
                        const std::string& style) {
  std::string out;
  for (int i = 0; i < 3; ++i) {
    out += (i == 0 ? "'" + file + "'" : std::string(", ''")) + " using " +
           std::to_string(x_column) + ":" + std::to_string(first_column + i) + " with " + style +
           " lc rgb '" + kAxisColour[i] + "' title '" + kAxisName[i] + "'";
  }
  return out;
}

/// The +-band lines of whitened residuals.
std::string BandClauses() {
  const std::string band = FormattedText("%g", kWhitenedBand);
  return ", " + band + " with lines dt 2 lc rgb 'gray40' notitle, -" + band +
         " with lines dt 2 lc rgb 'gray40' notitle";
}

std::string Begin(const FigureOptions& o, const std::string& file, int panels) {
  return "\n# " + file + "\n" + SvgTerminal(o.width_px, o.panel_height_px * panels) +
         "set output " + GnuplotQuote(file) + "\nset multiplot layout " +
         std::to_string(panels) + ",1\n";
}

std::string End() { return "unset multiplot\nset output\n"; }

/// series.svg and its data file.
void SeriesFigure(const ImuSeries& series, const std::vector<StillSegment>& segments,
                  const FigureOptions& o, FigurePlan& plan) {
  const double t0 = series.t_s.front();
  const std::size_t stride =
      std::max<std::size_t>(1, (series.size() + o.max_series_points - 1) / o.max_series_points);
  std::ostringstream csv;
  csv << "# time_s (since first sample),acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,temp_c\n";
  for (std::size_t i = 0; i < series.size(); i += stride) {
    csv << Cell(series.t_s[i] - t0);
    Cells(csv, series.acc[i].cast<double>(), true);
    Cells(csv, series.has_gyro() ? Vec3(series.gyr[i].cast<double>()) : Vec3::Zero(),
          series.has_gyro());
    csv << "," << (series.has_temperature() ? Cell(series.temp_c[i]) : std::string()) << "\n";
  }
  plan.job.data.push_back({"series.csv", csv.str()});

  const int panels = 1 + (series.has_gyro() ? 1 : 0) + (series.has_temperature() ? 1 : 0);
  std::ostringstream gp;
  gp << Begin(o, "series.svg", panels);
  int tag = 1;
  for (const auto& s : segments) {
    if (s.end <= s.begin || s.end > series.size()) continue;
    gp << "set object " << tag++ << " rect from first " << Cell(series.t_s[s.begin] - t0)
       << ", graph 0 to first " << Cell(series.t_s[s.end - 1] - t0)
       << ", graph 1 behind fillcolor rgb '" << kStillShade << "' fillstyle solid 1.0 noborder\n";
  }
  gp << "set xlabel 'time since the first sample (s)'\n"
     << "set ylabel " << GnuplotQuote("accelerometer (" + series.acc_unit + ")") << "\n"
     << "plot " << AxisClauses("series.csv", 1, 2, "lines") << "\n";
  if (series.has_gyro()) {
    gp << "set ylabel " << GnuplotQuote("gyroscope (" + series.gyr_unit + ")") << "\n"
       << "plot " << AxisClauses("series.csv", 1, 5, "lines") << "\n";
  }
  if (series.has_temperature()) {
    gp << "set ylabel 'temperature (degC)'\n"
       << "plot 'series.csv' using 1:8 with lines lc rgb 'black' notitle\n";
  }
  gp << End() << "unset object\n";
  plan.job.script += gp.str();
  plan.job.outputs.push_back("series.svg");
  plan.figures.push_back(
      {"series.svg", "Input time series",
       "The samples against time since the first one (" + FormattedText("%.6g", t0) + " s in the log), " +
           (stride > 1 ? "one sample in " + std::to_string(stride) + " drawn; " : std::string()) +
           "shaded: the " + std::to_string(segments.size()) +
           " still segments the fit used. Accelerometer in " + series.acc_unit +
           (series.has_gyro() ? ", gyroscope in " + series.gyr_unit : std::string()) +
           (series.has_temperature() ? ", temperature in degC." : std::string(".")), ""});
}

/// still.csv and motion.csv: per-segment and per-interval residuals.
void ResidualData(const ImuSeries& series, const diagnostics::ResidualAnalysis& a,
                  FigurePlan& plan) {
  const double t0 = series.t_s.front();
  std::ostringstream still;
  still << "# t_mid_s (since first sample),temp_c,acc_whitened_x,acc_whitened_y,"
           "acc_whitened_z,gyr_whitened_x,gyr_whitened_y,gyr_whitened_z,acc_residual_x,"
           "acc_residual_y,acc_residual_z,gyr_residual_x,gyr_residual_y,gyr_residual_z\n";
  for (const auto& c : a.still) {
    still << Cell(c.t_mid_s - t0) << "," << Cell(c.temp_c);
    Cells(still, c.acc_whitened, c.has_acc);
    Cells(still, c.gyr_whitened, c.has_gyr);
    Cells(still, c.acc_residual, c.has_acc);
    Cells(still, c.gyr_residual, c.has_gyr);
    still << "\n";
  }
  plan.job.data.push_back({"still.csv", still.str()});
  if (a.motion.empty()) return;
  std::ostringstream motion;
  motion << "# t_mid_s (since first sample),whitened_x,whitened_y,whitened_z\n";
  for (const auto& m : a.motion) {
    motion << Cell(0.5 * (m.t_begin_s + m.t_end_s) - t0);
    Cells(motion, m.whitened, true);
    motion << "\n";
  }
  plan.job.data.push_back({"motion.csv", motion.str()});
}

/// residuals.svg.
void ResidualFigure(const diagnostics::ResidualAnalysis& a, const FigureOptions& o,
                    FigurePlan& plan) {
  const bool acc = std::any_of(a.still.begin(), a.still.end(), [](const auto& c) { return c.has_acc; });
  const bool gyr = std::any_of(a.still.begin(), a.still.end(), [](const auto& c) { return c.has_gyr; });
  const bool motion = !a.motion.empty();
  const int panels = (acc ? 1 : 0) + (gyr ? 1 : 0) + (motion ? 1 : 0);
  if (panels == 0) return;
  std::ostringstream gp;
  // The y range reaches at least the +-band lines so that both are always drawn.
  const std::string reach = FormattedText("%g", kWhitenedBand + 0.5);
  gp << Begin(o, "residuals.svg", panels) << "set xlabel 'time since the first sample (s)'\n"
     << "set yrange [*<-" << reach << ":" << reach << "<*]\n";
  const std::string style = "linespoints pt 7 ps 0.6";
  if (acc) {
    gp << "set ylabel 'still accelerometer (whitened)'\nplot "
       << AxisClauses("still.csv", 1, 3, style) << BandClauses() << "\n";
  }
  if (gyr) {
    gp << "set ylabel 'still gyroscope (whitened)'\nplot "
       << AxisClauses("still.csv", 1, 6, style) << BandClauses() << "\n";
  }
  if (motion) {
    gp << "set ylabel 'motion rotation (whitened)'\nplot "
       << AxisClauses("motion.csv", 1, 2, style) << BandClauses() << "\n";
  }
  gp << End() << "set autoscale y\n";
  plan.job.script += gp.str();
  plan.job.outputs.push_back("residuals.svg");
  plan.figures.push_back(
      {"residuals.svg", "Whitened residuals against time",
       "Measured minus predicted, divided by its standard deviation (dimensionless; about "
       "N(0, 1) per axis when the model is complete; dashed: +-3): the still accelerometer and "
       "gyroscope per segment at its mean time" +
           std::string(motion ? ", the rotation over each motion interval at its middle" : "") +
           ". A trend or a jump shows what the model misses and when.", ""});
}

/// temperature.svg, when the segments have temperatures.
void TemperatureFigure(const ImuSeries& series, const diagnostics::ResidualAnalysis& a,
                       const FigureOptions& o, FigurePlan& plan) {
  const bool has = series.has_temperature() &&
                   std::any_of(a.still.begin(), a.still.end(),
                               [](const auto& c) { return std::isfinite(c.temp_c); });
  if (!has) return;
  const bool acc = std::any_of(a.still.begin(), a.still.end(), [](const auto& c) { return c.has_acc; });
  const bool gyr = std::any_of(a.still.begin(), a.still.end(), [](const auto& c) { return c.has_gyr; });
  const int panels = (acc ? 1 : 0) + (gyr ? 1 : 0);
  if (panels == 0) return;
  std::ostringstream gp;
  gp << Begin(o, "temperature.svg", panels) << "set xlabel 'segment mean temperature (degC)'\n";
  if (acc) {
    gp << "set ylabel " << GnuplotQuote("accelerometer residual (" + series.acc_unit + ")")
       << "\nplot " << AxisClauses("still.csv", 2, 9, "points pt 7 ps 0.8") << "\n";
  }
  if (gyr) {
    gp << "set ylabel " << GnuplotQuote("gyroscope residual (" + series.gyr_unit + ")")
       << "\nplot " << AxisClauses("still.csv", 2, 12, "points pt 7 ps 0.8") << "\n";
  }
  gp << End();
  plan.job.script += gp.str();
  plan.job.outputs.push_back("temperature.svg");
  plan.figures.push_back(
      {"temperature.svg", "Residuals against temperature",
       "Still residual per segment (measured minus predicted mean; accelerometer in " +
           series.acc_unit + ", gyroscope in " + series.gyr_unit +
           ") against the segment's mean temperature. A slope is a temperature effect the "
           "model lacks (accel_temperature_bias, gyro_temperature_bias).", ""});
}

/// allan.svg and allan.csv (gnuplot data blocks, one per entry of a.allan).
void AllanFigure(const ImuSeries& series, const estimation::CalibrationResult& fit,
                 const diagnostics::ResidualAnalysis& a, const FigureOptions& o,
                 FigurePlan& plan) {
  if (a.allan.empty()) return;
  std::ostringstream csv;
  for (const auto& al : a.allan) {
    csv << "# " << diagnostics::ResidualKindName(al.residual) << " " << kAxisName[al.axis]
        << ": tau_s,adev,white\n";
    for (std::size_t m = 0; m < al.tau_s.size(); ++m) {
      csv << Cell(al.tau_s[m]) << "," << Cell(al.adev[m]) << "," << Cell(al.white[m]) << "\n";
    }
    csv << "\n\n";
  }
  plan.job.data.push_back({"allan.csv", csv.str()});
  std::ostringstream gp;
  int panels = 0;
  std::string ratios;
  for (ResidualKind kind : {ResidualKind::kStillAccel, ResidualKind::kStillGyro}) {
    std::string clauses;
    for (std::size_t i = 0; i < a.allan.size(); ++i) {
      const auto& al = a.allan[i];
      if (al.residual != kind) continue;
      const std::string colour = kAxisColour[al.axis];
      clauses += std::string(clauses.empty() ? "'allan.csv'" : ", ''") + " index " +
                 std::to_string(i) + " using 1:2 with linespoints pt 7 ps 0.6 lc rgb '" + colour +
                 "' title '" + kAxisName[al.axis] + "', '' index " + std::to_string(i) +
                 " using 1:3 with lines dt 2 lc rgb '" + colour + "' title '" +
                 kAxisName[al.axis] + " white'";
      ratios += (ratios.empty() ? "" : ", ") + std::string(diagnostics::ResidualKindName(kind)) +
                " " + kAxisName[al.axis] + " " + FormattedText("%.2g", al.ratio);
    }
    if (clauses.empty()) continue;
    ++panels;
    const std::string unit = kind == ResidualKind::kStillAccel ? series.acc_unit : series.gyr_unit;
    gp << "set ylabel "
       << GnuplotQuote(std::string(kind == ResidualKind::kStillAccel ? "accel" : "gyro") +
                       " ADEV (" + unit + ")")
       << "\nplot " << clauses << "\n";
  }
  std::string labels;
  for (std::size_t k : a.allan_segments) {
    if (k < fit.fit.still.size()) labels += (labels.empty() ? "'" : ", '") + fit.fit.still[k].segment.label + "'";
  }
  plan.job.script += Begin(o, "allan.svg", panels) +
                     "set logscale xy\nset format y '%g'\nset xlabel 'cluster time tau (s)'\n" +
                     gp.str() + End() + "unset logscale\nset format y\n";
  plan.job.outputs.push_back("allan.svg");
  plan.figures.push_back(
      {"allan.svg", "Allan deviation of the still residual",
       "Allan deviation of the per-sample still residual (measured minus predicted) of the "
       "still segment" + std::string(a.allan_segments.size() == 1 ? " " : "s ") + labels +
           ", per axis (solid), beside the white-noise line sigma_white / sqrt(m) (dashed). "
           "Where the curve rises above its line, something slow (drift, random walk, "
           "temperature) is left in the residual. Ratio at the largest cluster: " +
           ratios + ".", ""});
}

/// One gnuplot data block per axis of `noise`, in its order: tau, adev, lower, upper, model
/// (the model only over the fitted taus).
std::string StillNoiseData(const signal::StillNoise& noise) {
  std::ostringstream csv;
  for (const signal::AxisNoise& a : noise.axes) {
    csv << "# " << signal::SensorName(a.sensor) << " " << kAxisName[a.axis]
        << ": tau_s,adev,lower,upper,model\n";
    const signal::AllanDeviation& d = a.adev;
    for (std::size_t j = 0; j < d.tau_s.size(); ++j) {
      const bool fitted = j >= a.fit.first && j <= a.fit.last && !a.fit.misfit;
      csv << Cell(d.tau_s[j]) << "," << Cell(d.adev[j]) << "," << Cell(d.adev_lower[j]) << ","
          << Cell(d.adev_upper[j]) << ","
          << (fitted ? Cell(std::sqrt(a.fit.Avar(d.tau_s[j]))) : std::string()) << "\n";
    }
    csv << "\n\n";
  }
  return csv.str();
}

}  // namespace

void AddStillNoiseFigure(const signal::StillNoise& noise, const FigureOptions& o,
                         FigurePlan& plan) {
  if (o.width_px <= 0 || o.panel_height_px <= 0) throw Error("figures: the sizes must be > 0");
  if (noise.axes.empty()) return;
  plan.job.data.push_back({"noise.csv", StillNoiseData(noise)});
  std::ostringstream gp;
  int panels = 0;
  for (signal::Sensor sensor : {signal::Sensor::kAccel, signal::Sensor::kGyro}) {
    std::string clauses;
    for (std::size_t i = 0; i < noise.axes.size(); ++i) {
      const signal::AxisNoise& a = noise.axes[i];
      if (a.sensor != sensor) continue;
      const std::string colour = kAxisColour[a.axis];
      const std::string index = " index " + std::to_string(i);
      clauses += std::string(clauses.empty() ? "'noise.csv'" : ", ''") + index +
                 " using 1:2:3:4 with yerrorbars pt 7 ps 0.5 lc rgb '" + colour + "' title '" +
                 kAxisName[a.axis] + "', ''" + index + " using 1:5 with lines lw 2 lc rgb '" +
                 colour + "' title '" + kAxisName[a.axis] + " model'";
    }
    if (clauses.empty()) continue;
    ++panels;
    const bool accel = sensor == signal::Sensor::kAccel;
    gp << "set ylabel "
       << GnuplotQuote(std::string(accel ? "accel" : "gyro") + " ADEV (" +
                       (accel ? noise.acc_unit : noise.gyr_unit) + ")")
       << "\nplot " << clauses << "\n";
  }
  plan.job.script += Begin(o, "noise.svg", panels) +
                     "set logscale xy\nset format y '%g'\nset xlabel 'cluster time tau (s)'\n" +
                     gp.str() + End() + "unset logscale\nset format y\n";
  plan.job.outputs.push_back("noise.svg");
  const double confidence = noise.axes.front().adev.confidence;
  plan.figures.push_back(
      {"noise.svg", "Allan deviation of the still data and the IEEE noise model",
       "Overlapping Allan deviation of the raw samples over " + FormattedText("%.4g", noise.still_s) +
           " s of still data in " + std::to_string(noise.segments.size()) +
           " segment(s), per axis (points, with " + FormattedText("%.3g", 100.0 * confidence) +
           " % chi-square intervals for the noise type the fit finds at each tau), and the "
           "fitted model 3Q^2/tau^2 + N^2/tau + 0.44 B^2 + K^2 tau/3 (line, over the fitted "
           "taus). Slopes -1, -1/2, 0, +1/2: quantisation, white noise, bias instability, "
           "random walk. The terms are in the 'Sensor noise' table.", ""});
}

FigurePlan PlanFigures(const ImuSeries& series, const std::vector<StillSegment>& segments,
                       const estimation::CalibrationResult& fit,
                       const diagnostics::ResidualAnalysis& analysis, const FigureOptions& o) {
  if (o.max_series_points < 100 || o.width_px <= 0 || o.panel_height_px <= 0) {
    throw Error("figures: max_series_points must be >= 100 and the sizes > 0");
  }
  if (series.empty()) throw Error("figures: the series has no samples");
  FigurePlan plan;
  plan.job.script =
      "# The figures of plumb report. Run in this folder: gnuplot figures.gp\n"
      "set datafile separator ','\nset grid\nset key outside right top\n"
      "set lmargin 12\nset rmargin 16\n";  // the same plot width in every panel
  SeriesFigure(series, segments, o, plan);
  ResidualData(series, analysis, plan);
  ResidualFigure(analysis, o, plan);
  TemperatureFigure(series, analysis, o, plan);
  AllanFigure(series, fit, analysis, o, plan);
  return plan;
}

std::vector<ReportFigure> EmbedDrawnFigures(const std::string& folder, const FigurePlan& plan,
                                            const GnuplotOutcome& outcome) {
  std::vector<ReportFigure> drawn;
  std::vector<std::string> files;
  for (const ReportFigure& figure : plan.figures) {
    if (std::find(outcome.written.begin(), outcome.written.end(), figure.file) ==
        outcome.written.end()) {
      continue;
    }
    drawn.push_back(figure);
    files.push_back(figure.file);
  }
  const std::vector<InlineFigure> inline_svgs = TakeSvgFiles(folder, files);
  for (std::size_t i = 0; i < drawn.size(); ++i) drawn[i].svg = inline_svgs[i].svg;
  return drawn;
}

}  // namespace plumb::report

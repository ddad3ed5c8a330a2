// plumb/report/figures.h — the figures of `plumb report`, as a gnuplot job (gnuplot.h): the
// data files, one script and the list of SVGs (gnuplot's svg terminal) with their titles and
// captions; EmbedDrawnFigures puts the drawn ones inside the page (inline_svg.h).
//
//   series.svg       the input time series (accelerometer, gyroscope, temperature when present)
//                    against time since the first sample, still segments shaded
//   residuals.svg    the fit's whitened residuals per axis against time: still accelerometer
//                    and still gyroscope per segment (at its mean time), motion per interval
//                    (at its middle), with the +-3 lines (whitened residuals are ~N(0, 1) when
//                    the model is complete)
//   temperature.svg  (only with temperature) still residuals per segment, series' units,
//                    against the segment's mean temperature
//   allan.svg        (only when the analysis has an Allan deviation) the residual's Allan
//                    deviation per axis against the white-noise line sigma_white / sqrt(m),
//                    log-log, series' units against cluster time in s
//   noise.svg        (AddStillNoiseFigure) the Allan deviation of the still data per axis with
//                    its confidence intervals as error bars, and the fitted IEEE noise model
//                    (signal/noise_terms.h) as a line over the fitted taus; one panel per
//                    sensor, log-log
// Times in every figure are seconds since the first sample of the series (log times may be
// Unix times). Data files are CSV with a '#' header line; non-finite values are left empty
// (gnuplot skips them).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/diagnostics/residual_analysis.h"
#include "plumb/estimation/result.h"
#include "plumb/report/gnuplot.h"
#include "plumb/signal/noise_terms.h"

namespace plumb::report {

/// One figure of the page.
struct ReportFigure {
  std::string file;     ///< the SVG gnuplot writes, relative to the folder, e.g. "series.svg"
  std::string title;    ///< a few words
  std::string caption;  ///< what is drawn, with units
  std::string svg;      ///< the drawing as inline <svg> markup (EmbedDrawnFigures); "" until drawn
};

struct FigureOptions {
  /// Most samples drawn of the input series, >= 100: every k-th sample with
  /// k = ceil(samples / max_series_points) (the caption states k).
  std::size_t max_series_points = 6000;
  int width_px = 1000;        ///< drawing width (SVG units, CSS pixels at full size), > 0
  int panel_height_px = 260;  ///< height per panel, same units, > 0
};

struct FigurePlan {
  GnuplotJob job;                      ///< data files, script, outputs
  std::vector<ReportFigure> figures;   ///< in page order, one per job output
};

/// The figures of a fit of `series` on `segments`. `analysis` is AnalyseResiduals(series,
/// fit); its `allan` entries (drawn as they are: the caller chooses which segments they pool,
/// `plumb report` the longest) give allan.svg. Throws plumb::Error for options out of range.
FigurePlan PlanFigures(const ImuSeries& series, const std::vector<StillSegment>& segments,
                       const estimation::CalibrationResult& fit,
                       const diagnostics::ResidualAnalysis& analysis,
                       const FigureOptions& options = {});

/// Adds noise.svg and its data noise.csv (one gnuplot data block per axis: tau_s, adev,
/// lower, upper, model) to `plan`: the still data's noise as `plumb allan` measures it. Throws
/// plumb::Error for options out of range.
void AddStillNoiseFigure(const signal::StillNoise& noise, const FigureOptions& options,
                         FigurePlan& plan);

/// The figures of `plan` that gnuplot drew in `folder` (outcome.written), in page order, each
/// with its SVG as inline markup (TakeSvgFiles, ids prefixed by the file's stem); the SVG
/// files are removed: the page holds them, and the script redraws them. Throws plumb::Error
/// naming a file that cannot be read or is not an SVG.
std::vector<ReportFigure> EmbedDrawnFigures(const std::string& folder, const FigurePlan& plan,
                                            const GnuplotOutcome& outcome);

}  // namespace plumb::report

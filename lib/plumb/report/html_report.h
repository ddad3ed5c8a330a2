// plumb/report/html_report.h — the page of `plumb report`: one self-contained HTML file (inline
// CSS and SVG figures, no script, nothing fetched) that says what was calibrated and how well,
// for a browser and for sharing.
//
// Sections, in order: summary (the verdict on chi^2/dof, unobservable directions, the best
// candidate and the command to run next), input (source, samples, rate, duration, site and where it came from, still
// segments, reader warnings), model (spec, terms), fit quality (chi^2, dof, chi^2/dof with
// the band of a complete model, per-axis RMS, noise), sensor noise (the IEEE terms of the
// still data per axis, noise_text.h, when PageExtras has them), figures, parameters (value +- sigma
// with units, or "unobservable"/"fixed"), forward model and correction matrices, firmware (what
// each export would write and the error it leaves, export_section.h), observability
// (unobservable directions in words, determined combinations), missing effects (diagnose's
// ranking and the command to run next), worst residual ranges and residual signatures,
// warnings, the files beside the page, and the command that reproduces the page.
//
// The page stands alone: the CSS is inline, the figures are inline SVG (figures.h), and it
// has no script, no link to another file and no reference that a browser would fetch.
//
// The band of a complete model: estimation::Chi2Band, 1 -+ 3 sqrt(2/dof), the one meaning of
// "consistent with the noise" that the terminal's verdict uses too.
//
// Every piece of text from outside (file names, labels, warnings, the command) is
// HTML-escaped; numbers are printed with %.6g (values) and %.2g (sigmas).
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "plumb/diagnostics/diagnose.h"
#include "plumb/diagnostics/residual_analysis.h"
#include "plumb/estimation/board_agreement.h"
#include "plumb/estimation/result.h"
#include "plumb/export/export.h"
#include "plumb/report/figures.h"
#include "plumb/segmentation/still_detector.h"
#include "plumb/signal/noise_terms.h"

namespace plumb::report {

/// What was read, for the input section.
struct InputSummary {
  std::string source;                 ///< file name(s) as the reader names them
  std::vector<std::string> inputs;    ///< the INPUT arguments
  std::size_t samples = 0;            ///< samples in the session, >= 0
  double rate_hz = 0.0;               ///< 1 / median sample interval, Hz (0: unknown)
  double duration_s = 0.0;            ///< last minus first sample time, s
  bool has_gyro = false;
  bool has_temperature = false;
  double temp_min_c = 0.0, temp_max_c = 0.0;  ///< temperature range, degC (with temperature)
  std::string acc_unit = "m/s^2", gyr_unit = "rad/s";  ///< units of the samples
  std::vector<std::string> warnings;  ///< the readers' warnings
};

/// Everything on the page besides the result structs.
struct PageExtras {
  std::string title = "plumb report";       ///< the page's <title> and heading
  std::vector<ReportFigure> figures;        ///< drawn figures, in order (may be empty)
  std::vector<std::string> figure_notes;    ///< why figures are missing (e.g. no gnuplot)
  std::string command;                      ///< the command line that reproduces the page
  std::vector<std::string> files;           ///< other files written beside the page
  std::string segments_source;              ///< --segments FILE, or "" when detected
  /// The still data's noise (plumb allan's analysis of the fit's still segments), if measured.
  std::optional<signal::StillNoise> still_noise;
  std::string still_noise_note;  ///< why it is missing, when it is
  /// The firmware section (export_section.h): what each export would write and the error it
  /// leaves (exporter::PreviewExports); empty: not computed, `exports_note` says why.
  std::vector<exporter::ExportPreview> exports;
  std::map<std::string, std::string> export_commands;  ///< format -> the command writing it
  std::string exports_note;  ///< a line above the firmware table, or why there is none
  /// The command to run next when the diagnosis finds a significant effect (the refit with
  /// diagnostics::NextModelSpec); "" for none.
  std::string next_command;
  /// With the board's IMUs (SPEC 6): each other IMU against IMU 0 at rest
  /// (estimation::BoardAgreement), for the page's "The board's IMUs" section.
  std::vector<estimation::ImuAgreement> board_agreement;
  /// With the board's IMUs and the diagnosis: diagnose --imus's summary (each IMU alone, the
  /// board across, each IMU's advice refitted together: report::BoardDiagnosisSummary); ""
  /// without it.
  std::string board_diagnosis;
};

/// Escapes & < > " ' for HTML text and attribute values; invalid UTF-8 passes unchanged.
std::string HtmlEscape(std::string_view text);

/// `items` as an HTML list (each escaped), with `css_class` when given; "" for no items.
std::string HtmlList(const std::vector<std::string>& items, const std::string& css_class = "");

/// The CSS of plumb's pages (the calibration report, the study page).
const char* PageStyle();

/// The whole page. `diagnosis` may be null (not run); `segmentation` is how the still
/// segments were found; `analysis` is AnalyseResiduals of `result`.
std::string HtmlReport(const InputSummary& input,
                       const segmentation::SegmentationResult& segmentation,
                       const estimation::CalibrationResult& result,
                       const diagnostics::ResidualAnalysis& analysis,
                       const diagnostics::Diagnosis* diagnosis, const PageExtras& extras);

}  // namespace plumb::report

// plumb allan INPUT... [--json FILE] — the sensor's noise from its still data (SPEC sections 3
// and 6): the overlapping Allan deviation of each axis with confidence intervals, and the
// IEEE Std 952 / 1293 terms fitted to it (quantisation Q, white noise N, bias instability B,
// random walk K, optionally the ramp R) with units, tau ranges and whether each is resolved
// or only an upper bound (plumb/signal/noise_terms.h, plumb/report/noise_text.h).
//
// Reads the inputs as calibrate does (input_options.h), finds the still segments as calibrate
// does (segment_options.h: detected, or --segments FILE) or takes the whole input as one still
// record (--whole), pools the segments per axis, prints the terms and writes the JSON document
// when asked.
#include <filesystem>
#include <iostream>
#include <sstream>

#include "validators.h"
#include "jobs.h"
#include "commands.h"
#include "fit_options.h"
#include "input_options.h"
#include "plumb/core/error.h"
#include "plumb/report/json_report.h"
#include "plumb/report/noise_text.h"
#include "plumb/report/summary.h"
#include "plumb/signal/noise_terms.h"
#include "segment_options.h"
#include "json_output.h"

namespace plumb::cli {
namespace {

struct AllanArgs {
  InputArgs input;
  SegmentArgs segments;           ///< --segments FILE or the still detector's options
  bool whole = false;             ///< --whole: the whole input is one still record
  std::string json_path;          ///< --json FILE
  signal::StillNoiseOptions noise;  ///< --confidence, --points-per-decade, --tau-min, ...
  bool no_quantisation = false;   ///< --no-quantisation: Q left out of the model
};

constexpr const char* kExample =
    "Example (a 449 s still record of an MPU-6050, raw counts at 100 Hz):\n"
    "  plumb allan ../shared/data/multipose/tomisuarez2/example_data_tinit_calc.csv "
    "--skip-lines 4 --header --columns ax,ay,az,gx,gy,gz --rate 100 --acc-unit g "
    "--acc-scale 1/16384 --gyr-unit deg/s --gyr-scale 1/131 --whole --json allan.json";

class AllanCommand : public Command {
 public:
  explicit AllanCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "allan",
        "The sensor's noise from its still data: the overlapping Allan deviation of each axis "
        "with confidence intervals, and the IEEE noise terms fitted to it (quantisation, white "
        "noise, bias instability, random walk) with units and tau ranges");
    AllanArgs& a = args_;
    AddInputOptions(app_, a.input);
    app_->add_flag("--whole", a.whole,
                   "The whole input is one still record (no still detection, no --segments)");
    app_->add_option("--json", a.json_path,
                     "Write the Allan deviation points with their intervals and the fitted terms "
                     "as JSON to FILE (atomically; - for stdout)")
        ->type_name("FILE");
    auto* fit = app_->add_option_group("Allan deviation and terms", "How the noise is measured");
    fit->add_option("--confidence", a.noise.allan.confidence,
                    "Two-sided confidence of the Allan deviation's intervals (0.6827 = one "
                    "sigma)")
        ->check(CLI::Range(0.01, 0.9999))
        ->capture_default_str();
    fit->add_option("--points-per-decade", a.noise.allan.points_per_decade,
                    "Cluster times per decade of tau")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
    fit->add_option("--tau-min", a.noise.terms.tau_min_s,
                    "Shortest cluster time fitted, s (0: from the sample interval; raise it "
                    "past a low-pass filter's time constant)")
        ->check(NonNegative)
        ->capture_default_str();
    fit->add_option("--tau-max", a.noise.terms.tau_max_s,
                    "Longest cluster time fitted, s (0: as far as the data has 2 degrees of "
                    "freedom)")
        ->check(NonNegative)
        ->capture_default_str();
    fit->add_option("--term-confidence", a.noise.terms.term_confidence,
                    "Confidence of the test that resolves a term and of the upper bounds")
        ->check(CLI::Range(0.51, 0.9999))
        ->capture_default_str();
    fit->add_flag("--rate-ramp", a.noise.terms.rate_ramp,
                  "Fit the rate ramp R too (it competes with the random walk K at long taus)");
    fit->add_flag("--no-quantisation", a.no_quantisation,
                  "Leave quantisation Q out of the model (its bound is still reported)");
    AddSegmentOptions(app_, a.segments);
    app_->footer(kExample);
  }

  FileRoles Files() const override {
    FileRoles roles;
    AddInputFiles(args_.input, roles);
    if (!args_.segments.segments_path.empty()) {
      roles.inputs.push_back({"--segments", args_.segments.segments_path});
    }
    roles.output_files.push_back({"--json", args_.json_path});
    return roles;
  }

  int Run() override {
    AllanArgs& a = args_;
    const TextAsideForJson text_aside(a.json_path);  // "-": the JSON alone on stdout
    if (a.whole && !a.segments.segments_path.empty()) {
      throw UsageError("--whole and --segments do not go together: --whole takes the whole "
                       "input as one still record");
    }
    a.noise.terms.quantisation = !a.no_quantisation;
    const Session session = ReadInputs(a.input);
    const ImuSeries& series = session.series;
    std::ostream& out = std::cout;
    std::vector<StillSegment> still;
    segmentation::SegmentationResult seg;
    if (a.whole) {
      StillSegment all;
      all.begin = 0;
      all.end = series.size();
      all.label = "whole input";
      still.push_back(all);
    } else {
      seg = FindSegments(series, a.segments);
      still = seg.segments;
    }
    PrintSession(session);
    out << (a.whole ? std::string("still segments: the whole input (--whole)\n")
                    : report::SegmentationSummary(seg, a.segments.segments_path,
                                                  a.segments.verbose));
    signal::StillNoise noise;
    try {
      noise = signal::AnalyseStillNoise(series, still, a.noise, ParallelJobs(0));
    } catch (const InsufficientDataError& e) {
      throw InsufficientDataError(session.source + ": " + e.what());
    }
    out << report::StillNoiseText(noise);
    if (!a.json_path.empty()) {
      nlohmann::json doc = report::StillNoiseJson(noise, series);
      std::vector<std::string> inputs = a.input.inputs;
      if (!a.input.acc_file.empty()) inputs.push_back(a.input.acc_file + "," + a.input.gyr_file);
      doc["inputs"] = inputs;
      doc["source"] = session.source;
      doc["still"]["method"] = a.whole ? "whole" : seg.report.method;
      doc["warnings"] = Messages(session.warnings);
      WriteJsonOutput(a.json_path, doc);
    }
    return 0;
  }

 private:
  AllanArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeAllanCommand(CLI::App& parent) {
  return std::make_unique<AllanCommand>(parent);
}

}  // namespace plumb::cli

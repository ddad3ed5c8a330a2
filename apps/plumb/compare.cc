// plumb compare RESULT.json --imu-tk ACC.calib GYRO.calib | --imu-tk-params FILE |
//               --imucal CAL.json [--gravity G] [--json FILE]
// plumb compare RESULT.json... --truth TRUTH.json [--json FILE]
//
// Sets plumb's calibration (what `plumb calibrate --json` wrote) beside another tool's answer,
// both in plumb's forward form (plumb/peers), prints the side-by-side table and imu_tk's
// accelerometer cost of both on plumb's still segments, and writes the comparison as JSON.
// With --truth, against a simulated session's truth instead: errors in sigmas and the NEES
// (plumb/peers/truth.h), one line per result when there are several.
#include <iostream>

#include "validators.h"
#include "commands.h"
#include "plumb/peers/comparison.h"
#include "plumb/peers/imu_tk.h"
#include "plumb/peers/imucal.h"
#include "plumb/peers/plumb_result.h"
#include "plumb/peers/truth.h"
#include "plumb/report/json_report.h"
#include "json_output.h"

namespace plumb::cli {
namespace {

struct CompareArgs {
  std::vector<std::string> results;     ///< RESULT.json of plumb calibrate --json (several: --truth)
  std::vector<std::string> imu_tk;      ///< --imu-tk ACC.calib GYRO.calib
  std::string imu_tk_params;            ///< --imu-tk-params full_precision_params.txt
  std::string imucal;                   ///< --imucal CAL.json
  double gravity_m_s2 = 0.0;            ///< --gravity, m/s^2, > 0; 0 = the result's
  std::string json_path;                ///< --json FILE
  std::string truth;                    ///< --truth TRUTH.json of plumb simulate --truth-json
};

class CompareCommand : public Command {
 public:
  explicit CompareCommand(CLI::App& parent) {
    app_ = parent.add_subcommand(
        "compare",
        "Compare plumb's calibration (calibrate --json) with another tool's answer on the same "
        "data, parameter by parameter in plumb's forward form");
    app_->footer("Example (a calibration against the simulator's truth: errors in sigmas and the NEES):\n  plumb compare cal.json --truth truth.json");
    CompareArgs& a = args_;
    app_->add_option("RESULT", a.results,
                     "The JSON that 'plumb calibrate --json' wrote (several only with --truth)")
        ->required()
        ->type_name("RESULT.json");
    auto* tk = app_->add_option("--imu-tk", a.imu_tk,
                                "imu_tk's accelerometer and gyroscope .calib files "
                                "(calibrated = T K (raw - B))")
                   ->expected(2)
                   ->type_name("ACC.calib GYRO.calib");
    auto* tk_full = app_->add_option("--imu-tk-params", a.imu_tk_params,
                                     "imu_tk's answer in full precision (sections ACC and GYRO "
                                     "with T=, K=, B=), instead of the rounded .calib files")
                        ->type_name("FILE");
    auto* cal = app_->add_option("--imucal", a.imucal,
                                 "imucal's Ferraris (or Turntable) calibration JSON")
                    ->type_name("CAL.json");
    auto* truth = app_->add_option("--truth", a.truth,
                                   "The truth of a simulated session ('plumb simulate "
                                   "--truth-json'): each parameter's error in sigmas and the "
                                   "NEES over the full covariance, with its chi^2 band")
                      ->type_name("TRUTH.json");
    tk->excludes(tk_full)->excludes(cal)->excludes(truth);
    tk_full->excludes(cal)->excludes(truth);
    cal->excludes(truth);
    app_->add_option("--gravity", a.gravity_m_s2,
                     "Gravity magnitude of imu_tk's cost, m/s^2 (default: the result's "
                     "site.gravity; imu_tk's demo used 9.81744)")
        ->check(EarthGravity);
    app_->add_option("--json", a.json_path, "Also write the comparison as JSON to FILE (- for stdout, the text then on stderr)")
        ->type_name("FILE");
  }

  FileRoles Files() const override {
    const CompareArgs& a = args_;
    FileRoles roles;
    for (const std::string& r : a.results) roles.inputs.push_back({"RESULT", r});
    for (const std::string& f : a.imu_tk) roles.inputs.push_back({"--imu-tk", f});
    if (!a.imu_tk_params.empty()) roles.inputs.push_back({"--imu-tk-params", a.imu_tk_params});
    if (!a.imucal.empty()) roles.inputs.push_back({"--imucal", a.imucal});
    if (!a.truth.empty()) roles.inputs.push_back({"--truth", a.truth});
    roles.output_files.push_back({"--json", a.json_path});
    return roles;
  }

  int Run() override {
    const CompareArgs& a = args_;
    const TextAsideForJson text_aside(a.json_path);
    if (!a.truth.empty()) return RunTruth();
    if (a.results.size() != 1) {
      throw UsageError("compare takes one RESULT.json against another tool (several only with "
                       "--truth)");
    }
    const peers::PlumbResult result = peers::ReadPlumbResult(a.results.front());
    const peers::ForwardCalibration peer = ReadPeer(result);
    peers::CompareOptions options;
    options.gravity_m_s2 = a.gravity_m_s2;
    const peers::Comparison comparison = peers::Compare(result, peer, options);
    std::cout << peers::ComparisonText(comparison);
    if (!a.json_path.empty()) {
      WriteJsonOutput(a.json_path, peers::ComparisonJson(comparison));
    }
    return 0;
  }

 private:
  /// --truth: each result against the simulated truth.
  int RunTruth() const {
    const CompareArgs& a = args_;
    const std::vector<peers::TrueParameter> truth = peers::ReadSimulationTruth(a.truth);
    nlohmann::json all = nlohmann::json::array();
    for (const std::string& path : a.results) {
      const peers::TruthComparison c =
          peers::CompareWithTruth(peers::ReadPlumbResult(path), truth, a.truth);
      std::cout << peers::TruthComparisonText(c, a.results.size() == 1);
      all.push_back(peers::TruthComparisonJson(c));
    }
    if (!a.json_path.empty()) WriteJsonOutput(a.json_path, a.results.size() == 1 ? all[0] : all);
    return 0;
  }

  /// The peer's answer in plumb's forward form, in the frame of `result`: imucal's own (its
  /// poses') when plumb's F is full and determined (known faces define plumb's frame too).
  peers::ForwardCalibration ReadPeer(const peers::PlumbResult& result) const {
    const CompareArgs& a = args_;
    if (!a.imu_tk.empty()) {
      peers::ImuTkCalibration c;
      c.acc = peers::ReadImuTkCalib(a.imu_tk[0]);
      c.gyro = peers::ReadImuTkCalib(a.imu_tk[1]);
      return peers::ImuTkToForward(c, a.imu_tk);
    }
    if (!a.imu_tk_params.empty()) {
      return peers::ImuTkToForward(peers::ReadImuTkFullPrecision(a.imu_tk_params),
                                   {a.imu_tk_params});
    }
    if (!a.imucal.empty()) {
      const peers::PlumbParameter* lower = peers::FindParameter(result, "accel.matrix.yx");
      const bool poses = lower != nullptr && !lower->fixed && lower->observable;
      return peers::ImucalToForward(
          peers::ReadImucalJson(a.imucal), a.imucal,
          poses ? peers::ImucalFrame::kPoses : peers::ImucalFrame::kAccelerometerDefined);
    }
    throw UsageError("name the other tool's answer: --imu-tk ACC.calib GYRO.calib, "
                     "--imu-tk-params FILE or --imucal CAL.json");
  }

  CompareArgs args_;
};

}  // namespace

std::unique_ptr<Command> MakeCompareCommand(CLI::App& parent) {
  return std::make_unique<CompareCommand>(parent);
}

}  // namespace plumb::cli

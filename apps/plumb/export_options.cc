#include "export_options.h"

#include <algorithm>

#include "commands.h"
#include "fit_options.h"
#include "plumb/core/error.h"
#include "plumb/export/board_export.h"
#include "plumb/export/export.h"
#include "plumb/export/kalibr.h"
#include "plumb/io/common/atomic_file.h"
#include "validators.h"

namespace plumb::cli {

void AddExportOptions(CLI::App* app, ExportArgs& a) {
  app->add_option("--export", a.exports,
                  "Write the calibration for another tool, FORMAT=FILE (repeatable): ardupilot "
                  "(Mission Planner .param: INS_ACCOFFS/ACCSCAL/GYROFFS, INS_TCALn_* when a "
                  "temperature term was fitted), px4 (QGroundControl .params: CAL_ACCn_*, "
                  "CAL_GYROn_*, TC_A/TC_G), kalibr (imu.yaml noise densities and random walks), "
                  "json (all three); prints what each target cannot represent, in numbers. With "
                  "--imus, every IMU of the board under its own instance's names (kalibr: "
                  "Kalibr's multi-IMU yaml)")
      ->type_name("FORMAT=FILE");
  a.imu_option = app->add_option("--export-imu", a.imu,
                                 "IMU instance in the exported parameter names, 0-based "
                                 "(ArduPilot 0..2: INS_ACC, INS_ACC2, INS_ACC3; PX4 0..3: "
                                 "CAL_ACC0..3); default: --imu")
                     ->check(NonNegative);
  app->add_flag("--export-undetermined", a.undetermined,
                "Write ArduPilot/PX4 parameters even when the session leaves the plumb "
                "parameters they come from undetermined (one still pose, say): those values are "
                "the ones plumb held, not measured, and replace the vehicle's");
  app->add_flag("--export-anyway", a.anyway,
                "Write the --export files even when the fit failed a gate (not converged, "
                "segments of one pose, samples out of range, a unit or rate the data "
                "contradict, a saturated axis); without it such an export is refused (exit 1) "
                "and nothing is written");
  app->add_option("--kalibr-topic", a.rostopic, "rostopic written in Kalibr's imu.yaml")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](const std::string& topic) {
            const std::string p = exporter::RosTopicProblem(topic);
            return p.empty() ? p : "not a ROS topic name (" + p + ")";
          },
          "ROS topic"));
  app->add_flag("--keep-gyro-offsets", a.keep_gyro_offsets,
                "Also write what keeps plumb's gyroscope offsets: INS_GYR_CAL 0 (ArduPilot "
                "measures them at rest after every boot while it is 1) and SENS_IMU_AUTOCAL 0 "
                "(PX4 likewise)");
  a.sysid_option = app->add_option("--sysid", a.sysid,
                                   "The vehicle's MAVLink system id, the first column of "
                                   "QGroundControl's .params (default: the log's, else 1)")
                       ->check(CLI::Range(1, 255));
}

std::vector<ExportRequest> ParseExports(const ExportArgs& a) {
  std::vector<ExportRequest> out;
  const auto& formats = exporter::ExportFormats();
  for (const std::string& e : a.exports) {
    const auto eq = e.find('=');
    if (eq == std::string::npos || eq + 1 == e.size()) {
      throw UsageError("--export takes FORMAT=FILE (e.g. ardupilot=imu.param), got '" + e + "'");
    }
    ExportRequest r{e.substr(0, eq), e.substr(eq + 1)};
    if (std::find(formats.begin(), formats.end(), r.format) == formats.end()) {
      throw UsageError("--export: unknown format '" + r.format +
                       "' (ardupilot, px4, kalibr, json)");
    }
    out.push_back(r);
  }
  return out;
}

void CheckExportable(const ImuSeries& series) {
  if (series.acc_unit != "m/s^2" || (series.has_gyro() && series.gyr_unit != "rad/s")) {
    throw Error("--export: the samples are in " + series.acc_unit + " and " + series.gyr_unit +
                " (unscaled sensor output), not m/s^2 and rad/s; firmware parameters and noise "
                "densities act on SI output, so they cannot be exported from this session "
                "(give --acc-scale/--acc-unit and --gyr-scale/--gyr-unit to calibrate in SI)");
  }
}

void CheckGatesForExport(const std::vector<ExportRequest>& requests, const ExportArgs& a,
                         const estimation::FitReport& fit, const std::string& source) {
  if (requests.empty() || fit.gates.empty() || a.anyway) return;
  throw Error("--export refused: " + GateFailure(fit, source) +
              " (see 'gate failed' above), so its parameters would replace the vehicle's with "
              "numbers not to be trusted; nothing written. Fix the input, or give "
              "--export-anyway to write them regardless");
}

nlohmann::json RunExports(const std::vector<ExportRequest>& requests, const ExportArgs& a,
                          int imu, const estimation::CalibrationResult& result,
                          const Session& session, std::ostream& out) {
  const ImuSeries& series = session.series;
  nlohmann::json doc = nlohmann::json::object();
  exporter::ExportOptions options;
  options.imu = a.imu_option != nullptr && a.imu_option->count() > 0 ? a.imu : imu;
  options.rostopic = a.rostopic;
  options.allow_undetermined = a.undetermined;
  options.log_params = session.log_params;
  options.system_id = session.system_id;
  options.device_ids = session.device_ids;
  if (a.sysid_option != nullptr && a.sysid_option->count() > 0) options.system_id = a.sysid;
  options.keep_gyro_offsets = a.keep_gyro_offsets;
  // A board fit (--imus) writes every IMU's instance in each file.
  const std::vector<exporter::BoardImuExport> board =
      result.calibration.board.empty()
          ? std::vector<exporter::BoardImuExport>{}
          : exporter::BoardImuExports(result.calibration, series, result.fit.still,
                                      session.other_imus, options.imu, session.device_ids);
  for (const ExportRequest& r : requests) {
    const exporter::ExportOutput e =
        board.empty() ? exporter::Export(r.format, result.calibration, series, result.fit.still, options)
                      : exporter::ExportBoard(r.format, board, options);
    io::WriteFileAtomic(r.path, e.text);
    out << "\n";
    for (const std::string& line : e.lines) out << line << "\n";
    out << "wrote " << r.path << " (" << r.format << ")\n";
    doc[r.format] = e.json;
    doc[r.format]["file"] = r.path;
  }
  return doc;
}

}  // namespace plumb::cli

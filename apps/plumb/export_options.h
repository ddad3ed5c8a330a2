// apps/plumb/export_options.h — `plumb calibrate --export FORMAT=FILE`: firmware parameters
// and Kalibr noise written from the calibration (plumb/export), with the report of what each
// target cannot represent.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/session.h"
#include "plumb/estimation/result.h"

namespace plumb::cli {

struct ExportArgs {
  std::vector<std::string> exports;  ///< --export FORMAT=FILE, repeatable
  int imu = 0;                       ///< --export-imu N: instance in parameter names, >= 0
  CLI::Option* imu_option = nullptr; ///< to tell whether --export-imu was given
  std::string rostopic = "/imu0";    ///< --kalibr-topic: Kalibr's rostopic
  bool undetermined = false;         ///< --export-undetermined: write undetermined values too
  bool anyway = false;               ///< --export-anyway: write even when the fit failed a gate
  bool keep_gyro_offsets = false;    ///< --keep-gyro-offsets: INS_GYR_CAL 0, SENS_IMU_AUTOCAL 0
  int sysid = 0;                     ///< --sysid N: the vehicle's MAVLink system id
  CLI::Option* sysid_option = nullptr;
};

/// One requested export.
struct ExportRequest {
  std::string format;  ///< ardupilot | px4 | kalibr | json
  std::string path;    ///< file to write (atomically)
};

/// Registers --export, --export-imu, --export-undetermined, --export-anyway and --kalibr-topic.
void AddExportOptions(CLI::App* app, ExportArgs& args);

/// The requests of --export; throws UsageError for a missing '=', an empty file or an
/// unknown format.
std::vector<ExportRequest> ParseExports(const ExportArgs& args);

/// Throws plumb::Error when the session's samples are not in SI (raw counts): firmware
/// parameters and noise densities would be meaningless. Call before calibrating.
void CheckExportable(const ImuSeries& series);

/// Throws plumb::Error, naming `source` and the gates, when there are `requests` and the fit
/// failed a gate (estimation/gates.h) without --export-anyway. Call before writing anything.
void CheckGatesForExport(const std::vector<ExportRequest>& requests, const ExportArgs& args,
                         const estimation::FitReport& fit, const std::string& source);

/// Writes every request (atomically), prints each report to `out`, and returns the JSON
/// object {"<format>": {...}} for calibrate's document. `imu` is the instance used when
/// --export-imu is absent (the input's --imu).
nlohmann::json RunExports(const std::vector<ExportRequest>& requests, const ExportArgs& args,
                          int imu, const estimation::CalibrationResult& result,
                          const Session& session, std::ostream& out);

}  // namespace plumb::cli

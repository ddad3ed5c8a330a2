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
#include "plumb/estimation/result.h"

namespace plumb::cli {

struct ExportArgs {
  std::vector<std::string> exports;  ///< --export FORMAT=FILE, repeatable
  int imu = 0;                       ///< --export-imu N: instance in parameter names, >= 0
  CLI::Option* imu_option = nullptr; ///< to tell whether --export-imu was given
  std::string rostopic = "/imu0";    ///< --kalibr-topic: Kalibr's rostopic
  bool undetermined = false;         ///< --export-undetermined: write undetermined values too
};

/// One requested export.
struct ExportRequest {
  std::string format;  ///< ardupilot | px4 | kalibr | json
  std::string path;    ///< file to write (atomically)
};

/// Registers --export, --export-imu, --export-undetermined and --kalibr-topic.
void AddExportOptions(CLI::App* app, ExportArgs& args);

/// The requests of --export; throws UsageError for a missing '=', an empty file or an
/// unknown format.
std::vector<ExportRequest> ParseExports(const ExportArgs& args);

/// Throws plumb::Error when the session's samples are not in SI (raw counts): firmware
/// parameters and noise densities would be meaningless. Call before calibrating.
void CheckExportable(const ImuSeries& series);

/// Writes every request (atomically), prints each report to `out`, and returns the JSON
/// object {"<format>": {...}} for calibrate's document. `imu` is the instance used when
/// --export-imu is absent (the input's --imu).
nlohmann::json RunExports(const std::vector<ExportRequest>& requests, const ExportArgs& args,
                          int imu, const estimation::CalibrationResult& result,
                          const ImuSeries& series, std::ostream& out);

}  // namespace plumb::cli

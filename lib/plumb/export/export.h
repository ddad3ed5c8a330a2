// plumb/export/export.h — one call per export format, for the command line: the file's text,
// the report lines for the terminal and the JSON for the calibration document ("export").
//
// Formats:
//   ardupilot  Mission Planner .param (formats.h), INS_* for the chosen IMU instance
//   px4        QGroundControl .params (formats.h), CAL_ACC/CAL_GYRO/TC_* for the instance
//   kalibr     Kalibr imu.yaml (kalibr.h), noise only
//   json       the three above as one JSON document (parameters, reports, noise)
// Every firmware format is evaluated from the parameter values it writes (read back through
// ArdupilotCorrection / Px4Correction), so the reported error is that of the file.
//
// The notes' codes (core/notice.h; ParameterSet, ExportReport and KalibrImu notes), beside
// each where it is made:
//   parameters_written      formats.cc: which parameters, for which instance, and their equation
//   thermal_kept            formats.cc: no temperature term; the vehicle's thermal parameters stay
//   thermal_model           formats.cc: the firmware's temperature polynomial written
//   gyro_offsets_kept       export.cc: the firmware keeps the offsets (kKeepGyroOffsets given)
//   gyro_offsets_replaced   export.cc: the firmware measures new offsets at boot
//                           (kKeepGyroOffsets keeps plumb's)
//   level_kept              export.cc: ArduPilot's AHRS_TRIM left as it is
//   device_id_unknown       export.cc: no device id in the input; the vehicle's stay
//   device_id               export.cc: the device id the log records, written
//   system_id               export.cc: the PX4 vehicle id written (kSystemId when not given)
//   board_frame             export.cc: the axes are the log's board frame
//   board_mount             board_export.cc: where a board IMU sits, which no parameter holds
//   no_still_segment        firmware.cc: nothing at rest to measure on
//   undetermined            firmware.cc: directions the session does not determine
//   noise_model_only        kalibr.cc: imu.yaml holds the noise model only
//   noise_terms_unresolved  kalibr.cc: the still data give no IEEE noise terms
//   noise_terms_fitted      kalibr.cc: the IEEE terms and the data they come from
//   noise_terms_source      kalibr.cc: which value each axis takes, per sensor
//   walk_upper_bound        kalibr.cc: walks written as upper bounds
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/session.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"
#include "plumb/export/firmware.h"
#include "plumb/export/formats.h"
#include "plumb/export/kalibr.h"

namespace plumb::exporter {

struct ExportOptions {
  int imu = 0;                     ///< IMU instance for parameter names, 0-based (ArduPilot 0..2,
                                   ///< PX4 0..3: the slot preferred where `device_ids` find
                                   ///< none, Px4SlotsOf)
  std::string rostopic = "/imu0";  ///< Kalibr's rostopic
  /// Write firmware parameters even when the session does not determine the plumb parameters
  /// they come from (accelerometer diagonal and biases, gyroscope biases, temperature terms).
  /// Off: Export() refuses, naming them — a single still pose would otherwise overwrite the
  /// vehicle's offsets and scales with values held at nominal, not measured.
  bool allow_undetermined = false;
  /// The vehicle as the log records it (Session::log_params, Session::system_id): the files
  /// say what the firmware will do with the values (INS_GYR_CAL, SENS_IMU_AUTOCAL) and carry
  /// the device ids (CAL_*_ID, TC_*_ID) and the system id (QGroundControl's first column).
  std::map<std::string, double> log_params;
  std::optional<int> system_id;
  /// The IMU's sensors' device ids (Session::device_ids): PX4's slots are the ones whose
  /// CAL_ACCn_ID, CAL_GYROn_ID, TC_An_ID, TC_Gn_ID hold them, as the firmware finds them; `imu`
  /// is then only the slot preferred where none does (Px4SlotsOf).
  DeviceIds device_ids;
  /// Write what keeps plumb's gyroscope offsets: INS_GYR_CAL 0 (ArduPilot measures them at
  /// every boot while it is 1, the default) and SENS_IMU_AUTOCAL 0 (PX4 overwrites CAL_GYRO
  /// offsets at rest while it is 1).
  bool keep_gyro_offsets = false;
};

/// PX4's slots for the IMU of `options` (formats.h Px4Slots), as the firmware finds each
/// sensor's: the n whose CAL_ACCn_ID (CAL_GYROn_ID, TC_An_ID, TC_Gn_ID) in the log is the
/// sensor's device id; where none is, a slot no device holds (ID 0 or not in the log), the
/// instance's first, as PX4 picks one for a new calibration (FindAvailableCalibrationIndex);
/// where the device id is not known, the instance's. Throws plumb::Error when every slot holds
/// another device.
Px4Slots Px4SlotsOf(const ExportOptions& options);

/// The formats Export() knows, in the order above.
const std::vector<std::string>& ExportFormats();

struct ExportOutput {
  std::string format;              ///< one of ExportFormats()
  std::string text;                ///< the file's content
  std::vector<std::string> lines;  ///< the report for the terminal
  nlohmann::json json;             ///< parameters and report, for "export" in calibrate's JSON
  /// ardupilot, px4: the parameters written (with the notes at the top of the file) and what
  /// the firmware's correction, read back from them, leaves against plumb's (Evaluate).
  std::optional<ParameterSet> parameters;
  std::optional<ExportReport> report;
  std::optional<KalibrImu> kalibr;  ///< kalibr: the values written and the numbers behind them
};

/// Builds one format for the calibration `calibration` of the session `series`, whose still
/// segments as the fit saw them (`still`, CalibrationResult::fit.still) measure the error the
/// format leaves. Export depends on what the calibration is, not on how the fit went. Throws
/// plumb::Error for an unknown format, outputs not in SI (counts), an instance the target has
/// no parameters for, or (firmware formats, unless options.allow_undetermined) parameters the
/// firmware values come from that the session leaves undetermined.
ExportOutput Export(const std::string& format, const estimation::Calibration& calibration,
                    const ImuSeries& series,
                    const std::vector<estimation::StillSegmentFit>& still,
                    const ExportOptions& options);

/// What one format would write for a page (plumb report): its output, or why there is none.
struct ExportPreview {
  std::string format;                 ///< "ardupilot", "px4" or "kalibr"
  std::optional<ExportOutput> output;  ///< Export()'s, when it writes the format
  std::string refused;                ///< otherwise why not: the message Export() threw
};

/// Export() of ardupilot, px4 and kalibr in that order, for a page: a format Export() refuses
/// (undetermined parameters, outputs not in SI, ...) carries the refusal instead of throwing.
/// `firmware_refused`, when not empty, is a reason known beforehand not to write the firmware
/// formats (the samples keep corrections plumb could not undo: Session::firmware_left); they
/// carry it without being built.
std::vector<ExportPreview> PreviewExports(const estimation::Calibration& calibration,
                                          const ImuSeries& series,
                                          const std::vector<estimation::StillSegmentFit>& still,
                                          const ExportOptions& options,
                                          const std::string& firmware_refused = "");

/// JSON of a report: errors in SI and in mg / deg/h, per-input matrices, dropped effects.
nlohmann::json ToJson(const ExportReport& report);
/// JSON of Kalibr's values with the per-axis numbers behind them.
nlohmann::json ToJson(const KalibrImu& imu);

}  // namespace plumb::exporter

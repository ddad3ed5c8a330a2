#include "plumb/export/board_export.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <utility>

#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/core/units.h"
#include "plumb/estimation/board_alone.h"

namespace plumb::exporter {
namespace {

/// "IMU k (instance N)", as the report heads an IMU's lines.
std::string ImuName(std::size_t k, const BoardImuExport& imu) {
  return "IMU " + std::to_string(k) + " (instance " + std::to_string(imu.instance) + ")";
}

/// Kalibr's topic of the board's k-th IMU: `topic`'s trailing number replaced by k ("/imu0",
/// the default, gives "/imu1", "/imu2"), else `topic` + "_k"; IMU 0 keeps `topic`.
std::string KalibrTopic(const std::string& topic, std::size_t k) {
  if (k == 0) return topic;
  std::size_t digits = topic.size();
  while (digits > 0 && std::isdigit(static_cast<unsigned char>(topic[digits - 1])) != 0) --digits;
  return digits < topic.size() ? topic.substr(0, digits) + std::to_string(k)
                               : topic + "_" + std::to_string(k);
}

/// What the firmware files cannot carry of where a board IMU sits.
std::string MountNote(const BoardImuExport& imu) {
  const std::string angle =
      imu.mount_determined
          ? FormattedText("%.3g", Eigen::AngleAxisd(imu.R_b_i).angle() * units::kDegPerRad) +
                " deg from IMU 0"
          : "at a rotation from IMU 0 that the session does not determine";
  return "it sits " + angle +
         " in the body, which no parameter of the file holds (the firmware turns every IMU by "
         "the one board orientation): its corrected axes are its own, and the firmware's "
         "comparison of the IMUs sees that turn";
}

/// Export() of one IMU of the board, its errors naming it.
ExportOutput ExportOne(const std::string& format, std::size_t k, const BoardImuExport& imu,
                       ExportOptions options) {
  options.imu = imu.instance;
  options.device_ids = imu.device_ids;
  options.rostopic = KalibrTopic(options.rostopic, k);
  try {
    return Export(format, imu.calibration, *imu.series, imu.still, options);
  } catch (const Error& e) {
    throw Error(ImuName(k, imu) + ": " + e.what());
  }
}

/// `one`'s parameters added to `all`: a name already there (a vehicle-wide parameter such as
/// INS_GYR_CAL) is written once; the notes, headed by the IMU.
void MergeParameters(const ParameterSet& one, const std::string& name, ParameterSet& all) {
  for (const Parameter& p : one.parameters) {
    const bool there = std::any_of(all.parameters.begin(), all.parameters.end(),
                                   [&](const Parameter& q) { return q.name == p.name; });
    if (!there) all.parameters.push_back(p);
  }
  for (Notice n : one.notes) {
    n.message = name + ": " + n.message;
    all.notes.push_back(std::move(n));
  }
}

}  // namespace

std::vector<BoardImuExport> BoardImuExports(const estimation::Calibration& calibration,
                                            const ImuSeries& series0,
                                            const std::vector<estimation::StillSegmentFit>& still,
                                            const std::vector<BoardImu>& board,
                                            int imu0_instance, const DeviceIds& imu0_device_ids) {
  if (board.size() != calibration.board.size()) {
    throw Error("the board's samples (" + std::to_string(board.size()) +
                " IMUs) do not match its calibration (" +
                std::to_string(calibration.board.size()) + ")");
  }
  std::vector<BoardImuExport> out(1);
  out[0].instance = imu0_instance;
  out[0].device_ids = imu0_device_ids;
  out[0].calibration = calibration;
  out[0].calibration.board.clear();
  out[0].calibration.board_covariance.resize(0, 0);
  out[0].series = &series0;
  out[0].still = still;
  for (std::size_t k = 0; k < board.size(); ++k) {
    const estimation::BoardImuCalibration& b = calibration.board[k];
    BoardImuExport imu;
    imu.instance = board[k].instance;
    imu.device_ids = board[k].device_ids;
    imu.calibration = estimation::BoardImuAlone(calibration, k);
    imu.series = &board[k].series;
    imu.still = estimation::StillFitsOnBoardImu(still, series0, board[k].series, b.R_b_i());
    imu.R_b_i = b.R_b_i();
    imu.lever_arm_m = b.LeverArm();
    imu.time_offset_s = b.TimeOffset();
    imu.mount_determined = b.RotationDetermined();
    out.push_back(std::move(imu));
  }
  return out;
}

ExportOutput ExportBoard(const std::string& format, const std::vector<BoardImuExport>& imus,
                         const ExportOptions& options) {
  ExportOutput out;
  out.format = format;
  if (format == "json") {
    for (const char* f : {"ardupilot", "px4", "kalibr"}) {
      ExportOutput one = ExportBoard(f, imus, options);
      out.json[f] = one.json;
      out.lines.insert(out.lines.end(), one.lines.begin(), one.lines.end());
    }
    out.text = out.json.dump(2) + "\n";
    return out;
  }
  ParameterSet parameters;
  std::vector<KalibrBoardImu> kalibr;
  out.json = nlohmann::json::object();
  out.json["imus"] = nlohmann::json::array();
  for (std::size_t k = 0; k < imus.size(); ++k) {
    ExportOutput one = ExportOne(format, k, imus[k], options);
    out.lines.push_back(ImuName(k, imus[k]) + ":");
    for (const std::string& line : one.lines) out.lines.push_back("  " + line);
    nlohmann::json entry = one.json;
    entry["instance"] = imus[k].instance;
    if (k == 0) {
      for (const auto& [key, value] : one.json.items()) out.json[key] = value;
      parameters.target = one.parameters ? one.parameters->target : "";
      parameters.imu = imus[k].instance;
      parameters.system_id = one.parameters ? one.parameters->system_id : 1;
    }
    out.json["imus"].push_back(std::move(entry));
    if (one.parameters) {
      if (k > 0) {
        AddNotice(one.parameters->notes, "board_mount", MountNote(imus[k]));
        out.lines.push_back("  note: " + one.parameters->notes.back().message);
      }
      MergeParameters(*one.parameters, ImuName(k, imus[k]), parameters);
    }
    if (one.kalibr) {
      kalibr.push_back({*one.kalibr, imus[k].R_b_i, imus[k].lever_arm_m, imus[k].time_offset_s});
    }
  }
  if (format == "ardupilot") out.text = ArdupilotParamFile(parameters);
  if (format == "px4") out.text = Px4ParamsFile(parameters);
  if (format == "kalibr") out.text = KalibrImuSetYaml(kalibr);
  if (format == "ardupilot" || format == "px4") out.parameters = std::move(parameters);
  return out;
}

}  // namespace plumb::exporter

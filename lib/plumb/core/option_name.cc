// See option_name.h.
#include "plumb/core/option_name.h"

#include <atomic>

namespace plumb {
namespace {

std::atomic<OptionSpeller> installed_speller{nullptr};

}  // namespace

std::string LibraryName(Option option) {
  switch (option) {
    case Option::kTimeWindow: return "FlightLogSelection::from_s/to_s";
    case Option::kSegments: return "SegmentRequest::segments_path";
    case Option::kRate: return "InputOptions::rate_hz";
    case Option::kDropNan: return "InputOptions::drop_nan_rows";
    case Option::kAccUnit: return "InputOptions::acc.unit";
    case Option::kAccScale: return "InputOptions::acc.scale";
    case Option::kAccOffset: return "InputOptions::acc.offset";
    case Option::kGyrUnit: return "InputOptions::gyr.unit";
    case Option::kGyrScale: return "InputOptions::gyr.scale";
    case Option::kGyrOffset: return "InputOptions::gyr.offset";
    case Option::kSite: return "FitRequest::site";
    case Option::kHeading: return "CalibrationOptions::first_heading_deg";
    case Option::kLevelNorth: return "FitRequest::level_north";
    case Option::kGravity: return "FitRequest/CompareOptions::gravity_m_s2";
    case Option::kMaxIterations: return "CalibrationOptions::max_iterations";
    case Option::kEstimateWalk: return "CalibrationOptions::estimate_walk";
    case Option::kAccelWalk: return "CalibrationOptions::accel_walk_density";
    case Option::kGyroWalk: return "CalibrationOptions::gyro_walk_density";
    case Option::kAccelInstability: return "CalibrationOptions::accel_instability";
    case Option::kGyroInstability: return "CalibrationOptions::gyro_instability";
    case Option::kNoiseFrom: return "CalibrationOptions::other_still_noise";
    case Option::kSigma: return "ApplyOptions::uncertainty";
    case Option::kExport: return "export::Export's format";
    case Option::kExportUndetermined: return "ExportOptions::allow_undetermined";
    case Option::kKeepGyroOffsets: return "ExportOptions::keep_gyro_offsets";
    case Option::kSystemId: return "ExportOptions::system_id";
    case Option::kCalibrationJson: return "report::CalibrationJson";
    case Option::kTruthJson: return "the plumb command's simulate";
    case Option::kTopic: return "FlightLogSelection::stream (a ROS bag's topic)";
    case Option::kClock: return "InputOptions::clock";
    case Option::kImus: return "InputOptions::all_imus (FlightLogSelection::other_imus)";
  }
  return "an option";
}

std::string LibrarySpelling(Option option, std::string_view value) {
  return LibraryName(option) + (value.empty() ? "" : " = " + std::string(value));
}

void SetOptionSpeller(OptionSpeller speller) { installed_speller.store(speller); }

std::string OptionText(Option option) { return OptionText(option, {}); }

std::string OptionText(Option option, std::string_view value) {
  const OptionSpeller speller = installed_speller.load();
  return speller != nullptr ? speller(option, value) : LibrarySpelling(option, value);
}

}  // namespace plumb

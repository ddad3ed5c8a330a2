// plumb/core/option_name.h — the options the library's messages mention, by meaning: a message
// says "give the accelerometer's unit" as OptionText(Option::kAccUnit, "g"), and the front end
// that runs the library spells it (the command line "--acc-unit g", the Python module
// acc_unit="g"); without one, the library's own name ("InputOptions::acc.unit = g").
//
// A front end installs its speller once, at start-up, before any work (the command's main, the
// Python module's init): the library's errors, gates, warnings and advice are then written in
// that front end's words, and the library itself spells no command-line flag.
#pragma once

#include <string>
#include <string_view>

namespace plumb {

/// An option a message may point the user to. The comment gives the library's name (what
/// LibraryName returns).
enum class Option {
  kTimeWindow,          ///< FlightLogSelection::from_s/to_s, the time window read
  kSegments,            ///< SegmentRequest::segments_path, a segments file
  kRate,                ///< InputOptions::rate_hz, a table's sample rate
  kDropNan,             ///< InputOptions::drop_nan_rows, rows with NaN dropped
  kAccUnit,             ///< InputOptions::acc.unit, the accelerometer's unit
  kAccScale,            ///< InputOptions::acc.scale
  kAccOffset,           ///< InputOptions::acc.offset
  kGyrUnit,             ///< InputOptions::gyr.unit, the gyroscope's unit
  kGyrScale,            ///< InputOptions::gyr.scale
  kGyrOffset,           ///< InputOptions::gyr.offset
  kSite,                ///< FitRequest::site, the user's latitude, longitude and height
  kHeading,             ///< CalibrationOptions::first_heading_deg
  kLevelNorth,          ///< FitRequest::level_north
  kGravity,             ///< the fixed gravity, m/s^2 (CompareOptions::gravity_m_s2)
  kMaxIterations,       ///< CalibrationOptions::max_iterations
  kEstimateWalk,        ///< CalibrationOptions::estimate_walk
  kAccelWalk,           ///< CalibrationOptions::accel_walk_density
  kGyroWalk,            ///< CalibrationOptions::gyro_walk_density
  kAccelInstability,    ///< CalibrationOptions::accel_instability
  kGyroInstability,     ///< CalibrationOptions::gyro_instability
  kNoiseFrom,           ///< CalibrationOptions::other_still_noise, a long still recording's
  kSigma,               ///< ApplyOptions::uncertainty
  kExport,              ///< export::Export's format
  kExportUndetermined,  ///< ExportOptions::allow_undetermined
  kKeepGyroOffsets,     ///< ExportOptions::keep_gyro_offsets
  kSystemId,            ///< ExportOptions::system_id
  kCalibrationJson,     ///< report::CalibrationJson, the calibration's JSON document
  kTruthJson,           ///< the truth file of the command `plumb simulate` (no library call)
  kTopic,               ///< FlightLogSelection::stream, a ROS bag's sensor_msgs/Imu topic
  kClock,               ///< InputOptions::clock, which clock the times follow
  kImus,                ///< InputOptions::all_imus / FlightLogSelection::other_imus, the board's IMUs
};

/// The option's library name: the C++ field or argument, e.g. "CalibrationOptions::max_iterations".
std::string LibraryName(Option option);

/// A front end's spelling of `option`, given `value` ("" for none): e.g. "--acc-unit g".
using OptionSpeller = std::string (*)(Option option, std::string_view value);

/// The library's own spelling: LibraryName, with " = value" when a value is given.
std::string LibrarySpelling(Option option, std::string_view value);

/// Installs the front end's speller (nullptr: the library's own). Call it once at start-up,
/// before any thread of the library runs; messages written afterwards use it.
void SetOptionSpeller(OptionSpeller speller);

/// `option` as the installed front end spells it, e.g. "--max-iterations" or "max_iterations".
std::string OptionText(Option option);

/// `option` given `value`, as the installed front end spells it: "--acc-unit g",
/// acc_unit="g", "InputOptions::acc.unit = g".
std::string OptionText(Option option, std::string_view value);

}  // namespace plumb

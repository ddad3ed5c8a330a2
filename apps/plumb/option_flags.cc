// See option_flags.h.
#include "option_flags.h"

namespace plumb::cli {
namespace {

const char* Flag(Option option) {
  switch (option) {
    case Option::kTimeWindow: return "--from/--to";
    case Option::kSegments: return "--segments";
    case Option::kRate: return "--rate";
    case Option::kDropNan: return "--drop-nan";
    case Option::kAccUnit: return "--acc-unit";
    case Option::kAccScale: return "--acc-scale";
    case Option::kAccOffset: return "--acc-offset";
    case Option::kGyrUnit: return "--gyr-unit";
    case Option::kGyrScale: return "--gyr-scale";
    case Option::kGyrOffset: return "--gyr-offset";
    case Option::kSite: return "--lat --lon --height";
    case Option::kHeading: return "--heading";
    case Option::kLevelNorth: return "--level-north";
    case Option::kGravity: return "--gravity";
    case Option::kMaxIterations: return "--max-iterations";
    case Option::kEstimateWalk: return "--estimate-rw";
    case Option::kAccelWalk: return "--accel-rw";
    case Option::kGyroWalk: return "--gyro-rw";
    case Option::kAccelInstability: return "--accel-bi";
    case Option::kGyroInstability: return "--gyro-bi";
    case Option::kNoiseFrom: return "--noise-from";
    case Option::kSigma: return "--sigma";
    case Option::kExport: return "--export";
    case Option::kExportUndetermined: return "--export-undetermined";
    case Option::kKeepGyroOffsets: return "--keep-gyro-offsets";
    case Option::kSystemId: return "--sysid";
    case Option::kCalibrationJson: return "'plumb calibrate --json'";
    case Option::kTruthJson: return "'plumb simulate --truth-json'";
    case Option::kTopic: return "--topic";
    case Option::kClock: return "--clock";
    case Option::kImus: return "--imus";
  }
  return "";
}

}  // namespace

std::string SpellFlag(Option option, std::string_view value) {
  const char* flag = Flag(option);
  if (*flag == '\0') return LibrarySpelling(option, value);
  return std::string(flag) + (value.empty() ? "" : " " + std::string(value));
}

}  // namespace plumb::cli

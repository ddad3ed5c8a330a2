// The board's exports (issue 38) checked against the firmware itself: every parameter name a
// board export writes, for every instance, is one the firmware's own parameter table holds, as
// the real logs record it (ArduPilot's PARM records, PX4's .ulg parameters); and each device id
// written is the log's for that instance.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "plumb/estimation/calibrator.h"
#include "plumb/export/board_export.h"
#include "plumb/export/formats.h"
#include "plumb/geo/site.h"
#include "plumb/io/input/flight_log_file.h"
#include "plumb/segmentation/still_detector.h"

namespace plumb::exporter {
namespace {

struct Case {
  const char* log;     ///< under ../shared/data
  const char* format;  ///< "ardupilot" or "px4"
  std::size_t imus;    ///< the board's IMUs, IMU 0 included
};

class BoardExportOfARealLog : public ::testing::TestWithParam<Case> {};

TEST_P(BoardExportOfARealLog, WritesOnlyNamesTheFirmwareHasWithItsDeviceIds) {
  const Case c = GetParam();
  const std::string path = std::string(PLUMB_SHARED_DATA_DIR) + "/" + c.log;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  const io::FlightLog log = io::FlightLog::Open(path);
  io::FlightLogSelection pick;
  for (std::size_t k = 1; k < c.imus; ++k) pick.other_imus.push_back(static_cast<int>(k));
  const Session s = log.Select(pick);
  ASSERT_EQ(s.other_imus.size() + 1, c.imus);
  const auto segments = segmentation::DetectStillSegments(s.series, {}).segments;
  model::Model m = model::Model::Parse("base");
  m.t_ref_s = s.series.t_s.front();
  const geo::Site site = geo::ResolveSite(std::nullopt, s.site, std::nullopt);
  const estimation::CalibrationResult r =
      estimation::CalibrateBoard(s.series, s.other_imus, segments, m, site);
  ExportOptions options;
  options.allow_undetermined = true;  // one still pose: the names are the point here
  options.log_params = s.log_params;
  options.keep_gyro_offsets = true;
  const ExportOutput out = ExportBoard(
      c.format, BoardImuExports(r.calibration, s.series, r.fit.still, s.other_imus, 0, s.device_ids), options);
  const std::map<std::string, double> written =
      std::string(c.format) == "ardupilot" ? ReadArdupilotParamFile(out.text, c.log)
                                           : ReadPx4ParamsFile(out.text, c.log);
  std::size_t offsets = 0;
  for (const auto& [name, value] : written) {
    const auto firmware = s.log_params.find(name);
    EXPECT_NE(firmware, s.log_params.end()) << name << " is not a parameter of " << c.log;
    if (firmware == s.log_params.end()) continue;
    if (name.size() > 3 && name.compare(name.size() - 3, 3, "_ID") == 0) {
      EXPECT_EQ(value, firmware->second) << name;
    }
    offsets += name.find("OFF") != std::string::npos ? 1 : 0;
  }
  // Three accelerometer and three gyroscope offsets per IMU.
  EXPECT_EQ(offsets, 6 * c.imus) << out.text;
}

INSTANTIATE_TEST_SUITE_P(
    Logs, BoardExportOfARealLog,
    ::testing::Values(Case{"ardupilot/plane408_centre_point.BIN", "ardupilot", 2},
                      Case{"px4/sample_log_small.ulg", "px4", 3}),
    [](const auto& info) { return std::string(info.param.format); });

}  // namespace
}  // namespace plumb::exporter

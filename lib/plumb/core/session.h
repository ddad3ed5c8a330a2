// plumb/core/session.h — what a reader produces and the calibrator consumes.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"

namespace plumb {

/// Where the IMU was, as the user or the log's GPS stated it.
struct SiteInput {
  double lat_deg = 0.0;   ///< geodetic latitude, degrees, [-90, 90]
  double lon_deg = 0.0;   ///< longitude, degrees, [-180, 180]
  double height_m = 0.0;  ///< height above the WGS84 ellipsoid, m
  std::string source;     ///< "flags", "gps" or "file"
};

/// A recorded session: samples, where they came from, optional segments and site.
struct Session {
  std::string source;              ///< file name(s) it was read from
  ImuSeries series;
  std::vector<StillSegment> given_segments;  ///< stated by the user; empty means detect
  std::optional<SiteInput> site;
  std::vector<std::string> warnings;         ///< what the reader skipped or repaired
};

}  // namespace plumb

// plumb/geo/site.h — where the IMU is: local gravity, Earth rate and C_ecef^ned.
//
// The only module that includes GeographicLib (SPEC section 1): normal gravity of the WGS84
// ellipsoid at the site (NormalGravity::WGS84(), height included, centrifugal part included,
// as an accelerometer at rest senses it), the Earth rotation rate of WGS84 and the
// ECEF-to-NED rotation (the paper's C_ecef^ned) from GeographicLib::Geocentric.
#pragma once

#include <optional>
#include <string>

#include "plumb/core/session.h"
#include "plumb/core/types.h"
#include "plumb/core/units.h"

namespace plumb::geo {

/// Earth rotation rate, rad/s (WGS84; the paper's 7.292115e-5).
double EarthRate();

/// A resolved site. Build it with Site::At or Site::Unknown.
struct Site {
  double lat_deg = 0.0;       ///< geodetic latitude, degrees [-90, 90]
  double lon_deg = 0.0;       ///< longitude, degrees [-180, 180]
  double height_m = 0.0;      ///< height above the WGS84 ellipsoid, m
  std::string source = "none";  ///< "flags", "gps", "file", "fixed" or "none"
  bool known = false;         ///< false: no site; Earth rate is left out and gravity is fixed
  /// Gravity vector in NED, m/s^2 (down positive).
  Vec3 g_n = Vec3(0.0, 0.0, units::kStandardGravity);
  Vec3 omega_ie_n = Vec3::Zero();      ///< Earth rate in NED, rad/s
  Mat3 C_ned_ecef = Mat3::Identity();  ///< maps ECEF vectors into NED (the paper's C_ecef^ned)

  double gravity() const { return g_n.norm(); }

  /// The site at the stated position; throws plumb::Error if lat or lon is out of range or
  /// not finite, or the height is outside [-12000, 100000] m.
  static Site At(double lat_deg, double lon_deg, double height_m, const std::string& source);
  static Site At(const SiteInput& input) {
    return At(input.lat_deg, input.lon_deg, input.height_m, input.source);
  }
  /// No site: gravity `g` (default standard gravity 9.80665 m/s^2) straight down, no Earth rate.
  static Site Unknown(double g = units::kStandardGravity);
};

/// The site a fit uses: `given` (the user's latitude and longitude, source "flags") when set, else
/// `from_log` (the log's GPS), else Site::Unknown. `gravity_m_s2`, when set, replaces the
/// gravity magnitude (still pointing down); without a site it is Site::Unknown's gravity.
Site ResolveSite(const std::optional<SiteInput>& given, const std::optional<SiteInput>& from_log,
                 std::optional<double> gravity_m_s2);

}  // namespace plumb::geo

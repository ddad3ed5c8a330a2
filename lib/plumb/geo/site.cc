#include "plumb/geo/site.h"

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/NormalGravity.hpp>

#include <cmath>
#include <vector>

#include "plumb/core/error.h"

namespace plumb::geo {

double EarthRate() { return GeographicLib::NormalGravity::WGS84().AngularVelocity(); }

Site Site::At(double lat_deg, double lon_deg, double height_m, const std::string& source) {
  if (!std::isfinite(lat_deg) || lat_deg < -90.0 || lat_deg > 90.0) {
    throw Error("site latitude " + Number(lat_deg) + " deg is outside [-90, 90]");
  }
  if (!std::isfinite(lon_deg) || lon_deg < -180.0 || lon_deg > 360.0) {
    throw Error("site longitude " + Number(lon_deg) + " deg is outside [-180, 360]");
  }
  if (!std::isfinite(height_m) || height_m < -12000.0 || height_m > 100000.0) {
    throw Error("site height " + Number(height_m) + " m is outside [-12000, 100000]");
  }
  Site s;
  s.lat_deg = lat_deg;
  s.lon_deg = lon_deg;
  s.height_m = height_m;
  s.source = source;
  s.known = true;

  // Gravity: GeographicLib gives the northward (gammay) and upward (gammaz) components.
  double gamma_north = 0.0, gamma_up = 0.0;
  GeographicLib::NormalGravity::WGS84().Gravity(lat_deg, height_m, gamma_north, gamma_up);
  s.g_n = Vec3(gamma_north, 0.0, -gamma_up);

  // Rotation: M maps local east-north-up vectors into ECEF; NED = (north, east, -up).
  double X = 0.0, Y = 0.0, Z = 0.0;
  std::vector<double> M(9);
  GeographicLib::Geocentric::WGS84().Forward(lat_deg, lon_deg, height_m, X, Y, Z, M);
  Mat3 R_ecef_enu;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R_ecef_enu(r, c) = M[static_cast<std::size_t>(3 * r + c)];
  }
  Mat3 R_enu_ned;
  R_enu_ned << 0, 1, 0,  //
      1, 0, 0,           //
      0, 0, -1;
  s.C_ned_ecef = (R_ecef_enu * R_enu_ned).transpose();
  s.omega_ie_n = s.C_ned_ecef * Vec3(0.0, 0.0, EarthRate());
  return s;
}

Site Site::Unknown(double g) {
  Site s;
  s.g_n = Vec3(0.0, 0.0, g);
  return s;
}

Site ResolveSite(const std::optional<SiteInput>& given, const std::optional<SiteInput>& from_log,
                 std::optional<double> gravity_m_s2) {
  Site site;
  if (given) {
    site = Site::At(*given);
  } else if (from_log) {
    site = Site::At(*from_log);
  } else {
    return Site::Unknown(gravity_m_s2.value_or(units::kStandardGravity));
  }
  if (gravity_m_s2) site.g_n = Vec3(0.0, 0.0, *gravity_m_s2);
  return site;
}

}  // namespace plumb::geo

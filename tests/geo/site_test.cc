#include "plumb/geo/site.h"

#include <gtest/gtest.h>

#include <cmath>

#include "plumb/core/error.h"

namespace plumb::geo {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

TEST(Site, EarthRateIsWgs84) { EXPECT_DOUBLE_EQ(EarthRate(), 7.292115e-5); }

TEST(Site, EarthRateInNedMatchesClosedForm) {
  // omega_ie_n = Omega (cos lat, 0, -sin lat), SPEC section 1.
  const Site s = Site::At(51.64, -1.2, 100.0, "flags");
  const double lat = 51.64 * kDegToRad;
  EXPECT_NEAR(s.omega_ie_n.x(), 7.292115e-5 * std::cos(lat), 1e-15);
  EXPECT_NEAR(s.omega_ie_n.y(), 0.0, 1e-15);
  EXPECT_NEAR(s.omega_ie_n.z(), -7.292115e-5 * std::sin(lat), 1e-15);
}

TEST(Site, CecefNedMatchesThePapersMatrix) {
  const double lat_deg = 6.67, lon_deg = -1.57;  // Kumasi, the paper's site
  const Site s = Site::At(lat_deg, lon_deg, 250.0, "flags");
  const double lat = lat_deg * kDegToRad, lon = lon_deg * kDegToRad;
  Mat3 paper;
  paper << -std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat),
      -std::sin(lon), std::cos(lon), 0.0,  //
      -std::cos(lat) * std::cos(lon), -std::cos(lat) * std::sin(lon), -std::sin(lat);
  EXPECT_LT((s.C_ned_ecef - paper).norm(), 1e-12);
}

TEST(Site, GravityIsWgs84NormalGravity) {
  // Somigliana at the equator and the pole, height 0 (WGS84 defining values).
  EXPECT_NEAR(Site::At(0.0, 0.0, 0.0, "flags").gravity(), 9.7803253359, 1e-9);
  EXPECT_NEAR(Site::At(90.0, 0.0, 0.0, "flags").gravity(), 9.8321849379, 1e-9);
  // Gravity falls by about 3.086e-6 m/s^2 per metre of height.
  const double g0 = Site::At(45.0, 0.0, 0.0, "flags").gravity();
  const double g1 = Site::At(45.0, 0.0, 1000.0, "flags").gravity();
  EXPECT_NEAR(g0 - g1, 3.086e-3, 2e-5);
  EXPECT_GT(Site::At(45.0, 0.0, 0.0, "flags").g_n.z(), 9.8);  // down is positive
}

TEST(Site, UnknownSiteHasNoEarthRate) {
  const Site s = Site::Unknown();
  EXPECT_FALSE(s.known);
  EXPECT_EQ(s.omega_ie_n, Vec3::Zero());
  EXPECT_DOUBLE_EQ(s.gravity(), 9.80665);
}

TEST(Site, RejectsOutOfRangeInput) {
  EXPECT_THROW(Site::At(91.0, 0.0, 0.0, "flags"), Error);
  EXPECT_THROW(Site::At(NAN, 0.0, 0.0, "flags"), Error);
  EXPECT_THROW(Site::At(0.0, 0.0, 1e7, "flags"), Error);
}

}  // namespace
}  // namespace plumb::geo

#include "site_options.h"

#include "plumb/core/units.h"
#include "validators.h"

namespace plumb::cli {

void AddSiteOptions(CLI::App* app, SiteArgs& args) {
  args.lat = app->add_option("--lat", args.lat_deg,
                             "Geodetic latitude of the site, degrees (-90..90); sets local "
                             "gravity (WGS84 normal gravity) and the Earth rate")
                 ->check(CLI::Range(-90.0, 90.0));
  args.lon = app->add_option("--lon", args.lon_deg, "Longitude of the site, degrees (-180..180)")
                 ->check(CLI::Range(-180.0, 180.0));
  args.height = app->add_option("--height", args.height_m,
                                "Height of the site above the WGS84 ellipsoid, m (default 0)");
  args.lat->needs(args.lon);
  args.lon->needs(args.lat);
  args.height->needs(args.lat);
}

geo::Site ResolveSite(const SiteArgs& args, const std::optional<SiteInput>& from_log,
                      std::optional<double> gravity_m_s2) {
  return geo::ResolveSite(args.given_site(), from_log, gravity_m_s2);
}

void AddGravityOption(CLI::App* app, SiteArgs& args) {
  args.gravity = app->add_option("--gravity", args.gravity_m_s2,
                                 "Use this fixed gravity magnitude, m/s^2, instead of WGS84 "
                                 "normal gravity at the site (only when you know better)")
                     ->check(EarthGravity);
}

}  // namespace plumb::cli

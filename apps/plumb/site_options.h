// apps/plumb/site_options.h — --lat --lon --height, shared by calibrate and simulate.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>

#include "plumb/core/session.h"
#include "plumb/geo/site.h"

namespace plumb::cli {

struct SiteArgs {
  double lat_deg = 0.0;        ///< geodetic latitude, degrees [-90, 90]
  double lon_deg = 0.0;        ///< longitude, degrees [-180, 180]
  double height_m = 0.0;       ///< height above the WGS84 ellipsoid, m
  CLI::Option* lat = nullptr;  ///< the registered options, to tell whether they were given
  CLI::Option* lon = nullptr;
  CLI::Option* height = nullptr;

  double gravity_m_s2 = 0.0;       ///< --gravity: fixed gravity magnitude, m/s^2, > 0
  CLI::Option* gravity = nullptr;  ///< registered by AddGravityOption, if at all

  bool given() const { return lat != nullptr && lat->count() > 0; }
  /// The site the flags give (source "flags"), when given.
  std::optional<SiteInput> given_site() const {
    if (!given()) return std::nullopt;
    return SiteInput{lat_deg, lon_deg, height_m, "flags"};
  }
  /// The --gravity value when given.
  std::optional<double> fixed_gravity() const {
    if (gravity == nullptr || gravity->count() == 0) return std::nullopt;
    return gravity_m_s2;
  }
};

/// Registers --lat, --lon (each needing the other) and --height (needing --lat).
void AddSiteOptions(CLI::App* app, SiteArgs& args);

/// Registers --gravity (a fixed gravity magnitude instead of WGS84 normal gravity).
void AddGravityOption(CLI::App* app, SiteArgs& args);

/// The site from the flags when given (source "flags"), else from `from_log` (e.g. the log's
/// GPS), else none. `gravity_m_s2`, when set, replaces the gravity magnitude (still pointing
/// down); without a site it is the fixed gravity of Site::Unknown.
geo::Site ResolveSite(const SiteArgs& args, const std::optional<SiteInput>& from_log,
                      std::optional<double> gravity_m_s2);

}  // namespace plumb::cli

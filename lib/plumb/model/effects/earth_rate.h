// earth_rate — the Earth's rotation as a candidate effect when the site is not known (SPEC
// section 4). With a site, Earth rate is part of the base model (geo::Site::omega_ie_n, from
// GeographicLib) and this effect must not be added.
//
//   y_g += E R_b_n (omega_N, 0, omega_D)
//
// on still segments, R_b_n the segment's attitude (NED into body; SensorInput::R_b_n). In the
// heading gauge of the fit (the first still pose's x axis north unless stated), omega_N =
// Omega cos(lat) and omega_D = -Omega sin(lat): the fit measures the latitude. Over motion
// intervals the term is left out (R_b_n is zero there): 7.3e-5 rad/s against the turn.
//
// Parameter block (2 values, zero = no Earth rate): omega.north, omega.down in rad/s.
// Residual signature: a still gyroscope residual fixed in the level frame, which turns with
// the heading and flips with the pose.
#pragma once

#include <string>

#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/model/effect.h"

namespace plumb::model {
namespace earth_rate {

/// The catalogue entry of earth_rate (parameters, units, typical sizes); throws
/// plumb::Error on an option it does not take.
inline EffectInfo Describe(const std::string& option) {
  if (!option.empty()) throw Error("earth_rate takes no option (got '" + option + "')");
  EffectInfo info;
  info.name = "earth_rate";
  info.prefix = info.name;
  info.sensor = Sensor::kGyro;
  info.term = "y_g += E R_b_n (omega_N, 0, omega_D), still segments (candidate without a site)";
  info.parameters = {{"omega.north", "rad/s", units::kEarthRate, 0.0},
                     {"omega.down", "rad/s", units::kEarthRate, 0.0}};
  info.input_side = true;
  info.excitation.still_orientations = true;
  return info;
}

}  // namespace earth_rate

class EarthRate : public EffectBase<EarthRate> {
 public:
  explicit EarthRate(const std::string& option) : EffectBase(earth_rate::Describe(option)) {}

  template <typename T>
  void Term(const T* theta, const SensorInput<T>& in, SensorOutput<T>& out) const {
    const Vec3T<T> omega_n(theta[0], T(0), theta[1]);
    out.gyr += out.E * (in.R_b_n * omega_n);
  }
};

}  // namespace plumb::model

PLUMB_DEFINE_EFFECT(earth_rate, ::plumb::model::EarthRate)

// accel_temperature_bias — the accelerometer bias depends on temperature (SPEC section 4):
//
//   y_a += c1 dT [+ c2 dT^2 [+ c3 dT^3]],   dT = T - T_ref
//
// Option: the order, "1" (default), "2" or "3". Parameters c1.x ... c3.z in m/s^2/degC^k,
// lowest order first (layout in temperature_bias.h).
// Residual signature: accelerometer residual that follows the temperature.
#pragma once

#include "plumb/model/effects/temperature_bias.h"

namespace plumb::model::temperature {
// Typical sizes: ~0.5 mg/degC (ICM-20602 class), with a few per cent of curvature per degC.
inline constexpr Spec kAccel = {"accel_temperature_bias", Sensor::kAccel, "y_a", "m/s^2",
                                {5e-3, 1e-4, 2e-6}};
}  // namespace plumb::model::temperature

PLUMB_DEFINE_EFFECT(accel_temperature_bias,
                    ::plumb::model::temperature::TemperatureBias<::plumb::model::temperature::kAccel>)

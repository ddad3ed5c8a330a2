// gyro_temperature_bias — the gyroscope bias depends on temperature (SPEC section 4):
//
//   y_g += c1 dT [+ c2 dT^2 [+ c3 dT^3]],   dT = T - T_ref
//
// Option: the order, "1" (default), "2" or "3". Parameters c1.x ... c3.z in rad/s/degC^k,
// lowest order first (layout in temperature_bias.h).
// Residual signature: gyroscope residual that follows the temperature.
#pragma once

#include "plumb/model/effects/temperature_bias.h"

namespace plumb::model::temperature {
// Typical sizes: ~0.02 deg/s/degC (ICM-20689 class), with a few per cent of curvature per degC.
inline constexpr Spec kGyro = {"gyro_temperature_bias", Sensor::kGyro, "y_g", "rad/s",
                               {4e-4, 1e-5, 2e-7}};
}  // namespace plumb::model::temperature

PLUMB_DEFINE_EFFECT(gyro_temperature_bias,
                    ::plumb::model::temperature::TemperatureBias<::plumb::model::temperature::kGyro>)

# The built-in effects, one per line. Adding an effect: write effects/<name>.h (its class, with
# PLUMB_DEFINE_EFFECT(<name>, Class)) and add its name here. Nothing else changes: the model's
# catalogue (registry.cc) and the effects' Jet forms (plumb::autodiff) are generated from this
# list.
set(PLUMB_EFFECTS
  accel_linear
  gyro_linear
  accel_bias_drift
  gyro_bias_drift
  accel_temperature_bias
  gyro_temperature_bias
  gyro_g_sensitivity
  accel_scale_nonlinearity
  gyro_scale_nonlinearity
  accel_size_effect
  time_offset
  earth_rate
)

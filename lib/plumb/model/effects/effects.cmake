# The built-in effects, one per line. Adding an effect: write effects/<name>.cc (with
# PLUMB_DEFINE_EFFECT(<name>, Class)) and add its name here. Nothing else changes.
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

#include "plumb/model/board_mount.h"

#include <string>

#include "plumb/core/units.h"

namespace plumb::model::board_mount {

EffectInfo Describe() {
  EffectInfo info;
  info.name = "board_mount";
  info.prefix = "";
  info.sensor = Sensor::kAccel;  // the accelerometer's gravity is what shows the rotation
  info.input_side = true;        // quantities of the body, in SI whatever the outputs' unit
  info.term = "f_i = R_b_i^T (f_b + alpha x r_i + omega x (omega x r_i))(t + dt_i), "
              "omega_i = R_b_i^T omega_b(t + dt_i)";
  // Typical: a degree of mounting rotation, a few centimetres between the IMUs of a flight
  // controller, a millisecond between their stamps.
  for (const char* axis : {"x", "y", "z"}) {
    info.parameters.push_back({std::string("rotation.") + axis, "rad", units::kRadPerDeg, 0.0});
  }
  for (const char* axis : {"x", "y", "z"}) {
    info.parameters.push_back({std::string("lever_arm.") + axis, "m", 0.03, 0.0});
  }
  info.parameters.push_back({"time_offset", "s", 1e-3, 0.0});
  info.excitation.still_orientations = true;
  info.excitation.angular_acceleration = true;
  return info;
}

}  // namespace plumb::model::board_mount

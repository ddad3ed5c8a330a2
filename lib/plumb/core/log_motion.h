// plumb/core/log_motion.h — what a flight log says the vehicle did, on the samples' clock.
//
// A flight log records more than its IMU: a land detector (ArduPilot's EV NOT_LANDED /
// LAND_COMPLETE events, PX4's vehicle_land_detected) and the GPS's ground speed and climb rate.
// Where those say the vehicle flew or moved, no segment of the samples is a still pose and no
// motion between two poses is a turn of a vehicle held in the hand (estimation/gates.h:
// not_still, not_a_turn), whatever the samples' own scatter says: a smooth cruise or a quiet
// hover can look still to an IMU logged at a few tens of hertz.
#pragma once

#include <string>
#include <vector>

namespace plumb {

/// One interval during which the log says the vehicle flew or moved.
struct LogMotion {
  enum class Evidence {
    kAirborne,   ///< the log's land detector says the vehicle is not landed
    kGpsMoving,  ///< the GPS (3D fix) gives a ground speed or climb rate above kGpsMovingSpeed
  };
  double t_begin_s = 0.0;  ///< start, s, on the clock of the session's samples
  double t_end_s = 0.0;    ///< end, s, >= t_begin_s
  Evidence evidence = Evidence::kAirborne;
  /// Where the log says it: "EV NOT_LANDED .. LAND_COMPLETE", "vehicle_land_detected",
  /// "GPS", "vehicle_gps_position", "GPS_RAW_INT".
  std::string source;
  /// kGpsMoving: the largest ground speed and the largest climb or sink rate magnitude the GPS
  /// gives in the interval, m/s (the climb 0 where the message has none), and the distance it
  /// travelled over ground, m (speed integrated over the GPS samples' spacing).
  double max_ground_speed_m_s = 0.0;
  double max_climb_m_s = 0.0;
  double ground_distance_m = 0.0;

  /// True when [t0, t1] lies where the log says the vehicle flew or moved: it shares more than
  /// kLogMotionEdge_s with the interval, or lies inside it.
  bool Covers(double t0, double t1) const;
};

/// The edges of a log's word are that uncertain, s: a land detector decides with a lag and
/// says NOT_LANDED as the motors spin up, still on the ground (ArduCopter; PX4's detector
/// holds each state about a second), a GPS's speed is filtered over a few reports; a still
/// period the IMU shows may run that far into the interval.
inline constexpr double kLogMotionEdge_s = 1.0;

/// A GPS's ground speed (or climb rate) above this, m/s, is the vehicle moving: a receiver at
/// rest with a 3D fix reports 0.02-0.4 m/s (the real ArduPilot logs' 95th percentile on the
/// ground: 0.05; a copter's hover 0.4-1.3), a person walking 1.4. Two GPS samples in a row
/// must exceed it, so that one glitch is not a flight.
inline constexpr double kGpsMovingSpeed = 1.0;

/// One line for a user: "airborne 228.1-375.3 s (EV NOT_LANDED .. LAND_COMPLETE)" or "moving
/// 243.5-373.7 s by GPS (up to 5.6 m/s over ground, 6.2 m/s climb, 420 m)".
std::string Describe(const LogMotion& m);

}  // namespace plumb

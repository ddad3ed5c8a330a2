// plumb/core/units.h — the one place for physical constants and unit conversions.
//
// Inside plumb every quantity is SI (SPEC section 1): m/s^2, rad/s, s, degC. Other units
// appear only at the edges (readers, exporters, printed tables), converted with these
// constants. Multiply to convert: `angle_deg * kRadPerDeg` is in rad,
// `rate * kDegPerHourPerRadPerS` is in deg/h.
#pragma once

namespace plumb::units {

/// pi, to double precision.
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;

/// Degrees and radians.
inline constexpr double kRadPerDeg = kPi / 180.0;
inline constexpr double kDegPerRad = 180.0 / kPi;

/// Standard gravity g0 (CGPM 1901, ISO 80000-3), m/s^2: the "g" of datasheets and of
/// firmware units (mg, mG); not local gravity, which plumb takes from the site (geo::Site).
inline constexpr double kStandardGravity = 9.80665;
/// The gravity magnitudes found on Earth, m/s^2: 9.78 at the equator to 9.83 at the poles at
/// sea level, down to about 9.75 at 10 km; a fixed gravity outside this range is a typing mistake.
inline constexpr double kMinEarthGravity = 9.7;
inline constexpr double kMaxEarthGravity = 9.9;
/// The highest sample rate of an IMU's output, Hz: MEMS parts output at most 32 kHz
/// (ICM-42688-P); 1 MHz leaves room for any test rig, and a sample rate beyond it is a typing
/// mistake (1e300 Hz would make a still-detection window of 1e300 samples).
inline constexpr double kMaxImuRate_hz = 1e6;
/// m/s^2 per milli-g and per micro-g.
inline constexpr double kMilliG = kStandardGravity * 1e-3;
inline constexpr double kMicroG = kStandardGravity * 1e-6;

/// Earth's rotation rate relative to inertial space (WGS84 / GRS80 value), rad/s.
inline constexpr double kEarthRate = 7.292115e-5;

/// Seconds per hour, and deg/h per rad/s (the unit gyroscope biases are quoted in).
inline constexpr double kSecondsPerHour = 3600.0;
inline constexpr double kDegPerHourPerRadPerS = kDegPerRad * kSecondsPerHour;
/// sqrt(s) per sqrt(h): a noise density per sqrt(s) times this is per sqrt(h) (deg/sqrt(h) of
/// an angle random walk from deg/sqrt(s)).
inline constexpr double kSqrtSecondsPerSqrtHour = 60.0;

/// Centimetres per metre and milliseconds per second (a board's lever arms and clocks as shown).
inline constexpr double kCmPerM = 100.0;
inline constexpr double kMsPerS = 1e3;

}  // namespace plumb::units

// plumb/estimation/gates.h — the gates of SPEC section 3: checks that say when a calibration's
// numbers are not to be trusted as they stand, whatever chi^2/dof says.
//
//   not_converged  the solver stopped before converging (FitReport::converged false)
//   one_pose       the rank rests on segments cut out of too few poses: consecutive still
//                  segments whose gravity directions agree within the noise (and within
//                  kSamePoseMinDeg) with no turn between them are one pose; the gate fails
//                  when some segments were merged so and fewer distinct poses are left than
//                  the accelerometer model needs (one per free accel.* parameter with free
//                  attitudes, one per three when some attitude is known: 9 or 3 for base)
//   out_of_range   samples no IMU can give: |accel| > kMaxAccelG g or |gyro| >
//                  kMaxGyroDegS deg/s on any axis in SI data, |value| > kMaxCounts in raw
//                  counts, or not finite; a temperature beyond kMinTemperatureC ..
//                  kMaxTemperatureC or not finite
//   unit_or_rate   a unit or a sample rate the data contradict: the still accelerometer's
//                  norm against gravity (raw, SI data; and corrected, F^-1 (mean - b_a)), the
//                  still gyroscope's norm against Earth rate plus a plausible bias (SI data),
//                  the fitted accelerometer and gyroscope scales against 1 (SI data: a gyro
//                  scale of 10 means the turns integrate to 10 times the angles the
//                  accelerometer sees, so the sample rate is wrong by that factor); the
//                  fitted ones only on a fit that converged on enough poses (else its values
//                  are noise and the gates above say so)
//   saturated      an axis sits at its extreme value for kSaturationRun samples or more in a
//                  row outside the still segments (a clipped turn or shock)
//   nonlinear      chi^2 is far from the quadratic the covariance assumes, a few sigma out from
//                  the solution (linearity.h): the covariance does not describe the fit's
//                  error (only on a converged fit of enough poses)
//   not_still      a still segment whose samples scatter (RMS about its mean, per axis, SI; raw
//                  counts through the fitted scale) more than kNotStillAccel or kNotStillGyro, or more
//                  than kNotStillRatio times the session's quietest segment: a flight, running
//                  motors, a vehicle carried, not a pose at rest (the detector adapts to the
//                  data's own scatter, so a session that is all motion can pass it); or one
//                  during which the log says the vehicle flew or moved (its land detector,
//                  its GPS: CalibrationOptions::log_motion), however quiet its samples (a
//                  smooth cruise, a hover, logged at tens of hertz)
//   not_a_turn     motion between two poses left out of the fit as no turn (longer than
//                  CalibrationOptions::max_motion_s, or during which the log says the vehicle
//                  flew or moved: a flight, a vehicle carried; the
//                  poses after it start a chain of their own), where that leaves the
//                  gyroscope's matrix (scale and misalignment, which only turns determine)
//                  undetermined or known only to more than kNotATurnMatrixSigma
//   implausible_walk  a bias random walk estimated from the session (estimate_walk) more than
//                  10 times the typical MEMS walk: more likely a missing effect seen between
//                  the poses, which a walk that large hides from chi2 (walk_estimate.h)
//
// CheckSamples looks at the samples (before the fit: the fit itself may be garbage when they
// are), CheckFit at the fitted calibration; Calibrate (calibrator.cc) runs both and puts the
// failures in FitReport::gates. The library only reports: the command decides what a failed
// gate does (the command's exit status 3 when strict, no export unless forced).
#pragma once

#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"

namespace plumb::estimation {

/// The gates' names, in the order they are checked.
inline constexpr const char* kGateNames[] = {"out_of_range", "saturated", "not_converged",
                                             "one_pose", "nonlinear", "unit_or_rate",
                                             "not_still", "not_a_turn", "implausible_walk"};

/// not_still: a segment's per-sample scatter above kNotStillAccel (50 mg: 25 times a consumer
/// MEMS accelerometer's noise per sample at 1 kHz, 0.02 m/s^2; spinning motors and flight give
/// 1-10 m/s^2) or kNotStillGyro (5.7 deg/s: 60 times a MEMS gyroscope's 1.6e-3 rad/s at
/// 1 kHz), or above kNotStillRatio times the quietest segment's (one sensor at rest has the
/// same white noise in every pose; hand-held holds on real sessions reach 22 times it, the
/// ChanghyeonKim93 and mikoff sessions; flight 100-1000 times), the quietest taken at least
/// kStillScatterFloorAccel /
/// kStillScatterFloorGyro (below any MEMS part's noise per sample: quantised outputs can
/// scatter by zero).
inline constexpr double kNotStillAccel = 0.5;
inline constexpr double kNotStillGyro = 0.1;
inline constexpr double kNotStillRatio = 50.0;
inline constexpr double kStillScatterFloorAccel = 0.005;
inline constexpr double kStillScatterFloorGyro = 5e-4;

/// not_a_turn: a gyroscope matrix entry known only to more than this (a datasheet's scale
/// tolerance, +-3 %: a fit that cannot do better has not determined it; Earth rate alone, on the
/// still poses, gives some 0.3) counts as undetermined.
inline constexpr double kNotATurnMatrixSigma = 0.03;

/// out_of_range: per-axis limits. 32 g is twice the largest common MEMS full scale (16 g;
/// 24 g parts stay inside), 4000 deg/s twice the common 2000 deg/s; 2^20 counts holds any
/// 16- to 20-bit converter's output, signed or unsigned.
inline constexpr double kMaxAccelG = 32.0;
inline constexpr double kMaxGyroDegS = 4000.0;
inline constexpr double kMaxCounts = 1048576.0;

/// out_of_range, the temperature: a MEMS IMU operates within -40 .. 85 degC (consumer and
/// industrial parts; automotive ones to 125), its die reading some 10-20 degC above the air;
/// beyond kMinTemperatureC .. kMaxTemperatureC a reading is corrupt or not in degC.
inline constexpr float kMinTemperatureC = -60.0f;
inline constexpr float kMaxTemperatureC = 150.0f;

/// saturated: samples in a row at the axis's extreme, outside the still segments; in SI data
/// the extreme must also be beyond kSaturationMinAccelG g or kSaturationMinGyroDegS deg/s
/// (below the smallest full scales, 2 g and 125 deg/s), in counts beyond 1.5 times the still
/// accelerometer's norm (the accelerometer; the gyroscope has no such reference).
inline constexpr int kSaturationRun = 4;
inline constexpr double kSaturationMinAccelG = 1.5;
inline constexpr double kSaturationMinGyroDegS = 100.0;

/// one_pose: two consecutive segments are one pose when their gravity directions differ by
/// less than max(kSamePoseSigmas sigma, kSamePoseMinDeg) (sigma of the difference of the
/// mean directions, from the noise) and the gyroscope integrated between them (less the mean
/// of their still rates) turns less than max(kSamePoseSigmas sigma, kSameTurnMinDeg) (SI; in
/// counts the noise bound alone).
inline constexpr double kSamePoseSigmas = 10.0;
inline constexpr double kSamePoseMinDeg = 0.5;
inline constexpr double kSameTurnMinDeg = 2.0;

/// unit_or_rate: the raw still accelerometer norm within kMaxNormError of gravity (raw MEMS
/// scale and bias errors are a few percent; g units read 0.10, counts hundreds and more), the
/// corrected one within kMaxCorrectedNormError, fitted scales within kMaxScaleError of 1
/// (datasheets give +-3 %), and the raw still gyroscope norm below kMaxGyroBiasDegS deg/s plus
/// Earth rate (an MPU-6000's zero-rate output may reach +-20 deg/s).
inline constexpr double kMaxNormError = 0.25;
inline constexpr double kMaxCorrectedNormError = 0.05;
inline constexpr double kMaxScaleError = 0.25;
inline constexpr double kMaxGyroBiasDegS = 25.0;

/// nonlinear: chi^2 rises by more than this times c^2 at c sigma along some direction
/// (LinearityReport::worst_ratio; a linear model gives 1, well-posed fits 1.00-1.2).
inline constexpr double kMaxLinearityRatio = 1.5;

/// The motion `m` in words: when, between which poses, and why it is not a turn.
std::string NotATurnText(const FitReport& fit, const NotATurn& m);

/// out_of_range and saturated, on the samples and the still segments (given or detected).
std::vector<Gate> CheckSamples(const ImuSeries& series, const std::vector<StillSegment>& still);

/// not_converged, one_pose, not_still, not_a_turn and unit_or_rate, on a finished fit (its
/// still segments, noise levels, parameters and fit.distinct_poses, which Calibrate counts
/// with CountDistinctPoses), and what the log says the vehicle did (`log_motion`,
/// CalibrationOptions::log_motion).
std::vector<Gate> CheckFit(const ImuSeries& series, const Calibration& calibration,
                           const std::vector<LogMotion>& log_motion, FitReport& fit);

/// CheckSamples then CheckFit: what Calibrate puts in FitReport::gates.
std::vector<Gate> CheckGates(const ImuSeries& series, const std::vector<StillSegment>& still,
                             const Calibration& calibration,
                             const std::vector<LogMotion>& log_motion, FitReport& fit);

/// Distinct poses among the fit's still segments at rest (the one_pose rule above), given the
/// noise levels the fit was whitened with: the one count of poses (FitReport::distinct_poses,
/// the advice's "found N", the one_pose gate).
int CountDistinctPoses(const ImuSeries& series, const std::vector<StillSegmentFit>& still,
                       const NoiseLevels& noise);

}  // namespace plumb::estimation

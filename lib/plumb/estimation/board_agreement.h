// plumb/estimation/board_agreement.h — how far the board's IMUs disagree at rest, before and
// after the calibration, measured as the firmware's own pre-arm check measures it (SPEC 6,
// "Several IMUs of one board"; issue 38).
//
// ArduPilot (AP_Arming::ins_accels_consistent, ins_gyros_consistent) compares each IMU's
// corrected accelerometer with the primary's, the difference's z halved, against
// ARMING_ACCTHRESH (0.75 m/s^2 by default; three times that from the third IMU on), and each
// gyroscope's against 5 deg/s; both must hold for 10 s before it arms. The vectors it compares
// are each IMU's own, turned by the one board orientation: a turn between the IMUs (R_b_k)
// reads as disagreement, g sin(angle) for the accelerometers (0.17 m/s^2 a degree).
//
// Per still pose of the fit and per IMU k, with ybar the pose's mean output:
//   before = d(ybar_k - ybar_0)                       the samples as the session has them
//   after  = d(f_k - f_0),  f = F^-1 (ybar - b)       each IMU corrected by its own linear stage
//                                                     (the gyroscopes by their offsets alone, as
//                                                     the firmware corrects them: at rest the
//                                                     rate is Earth's, which no scale error moves
//                                                     measurably, and a matrix the poses cannot
//                                                     determine would only add its arbitrariness)
//   in_body = |R_b_k f_k - f_0|                       what is left once the IMUs' turn is taken out
// with d(v) = |(v_x, v_y, kArduPilotZWeight v_z)| for the accelerometer, |v| for the gyroscope;
// each figure the largest over the poses IMU k holds samples of.
#pragma once

#include <cstddef>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/session.h"
#include "plumb/core/units.h"
#include "plumb/estimation/result.h"

namespace plumb::estimation {

/// ArduPilot's ARMING_ACCTHRESH default, m/s^2: the accelerometer disagreement it arms with.
inline constexpr double kArduPilotAccelThreshold_m_s2 = 0.75;
/// From the third IMU on (k >= 2), ArduPilot allows three times that: that IMU "runs at a
/// different temperature" and the EKF takes no acceleration from it.
inline constexpr double kArduPilotThirdImuFactor = 3.0;
/// ArduPilot halves the z difference ("EKF is less sensitive to Z-axis error").
inline constexpr double kArduPilotZWeight = 0.5;
/// ArduPilot's gyroscope disagreement it arms with, rad/s (5 deg/s).
inline constexpr double kArduPilotGyroThreshold_rad_s = 5.0 * units::kRadPerDeg;

/// One other IMU against IMU 0 at rest (board_agreement.h's figures).
struct ImuAgreement {
  int instance = 0;  ///< its number on the board
  int poses = 0;     ///< still poses compared
  /// Some accelerometer parameter of IMU 0's or this IMU's model is not determined by the
  /// poses (too few orientations): the fit matches the two IMUs at the poses by construction,
  /// and "after" says nothing of other orientations.
  bool matched_by_construction = false;
  double accel_before = 0, accel_after = 0, accel_in_body = 0;  ///< m/s^2
  double gyro_before = 0, gyro_after = 0, gyro_in_body = 0;     ///< rad/s (0 without gyros)
  bool has_gyro = false;
  /// ArduPilot's accelerometer limit for this IMU (instance 2 on, ArduPilot's IMU3:
  /// kArduPilotThirdImuFactor times).
  double accel_limit = kArduPilotAccelThreshold_m_s2;
};

/// The agreement of each of the board's other IMUs (`board`, as calibrated in
/// result.calibration.board, in order) with IMU 0 (`series0`) over the fit's still poses.
/// Empty without a board, or when a sensor's samples are not in SI units.
std::vector<ImuAgreement> BoardAgreement(const CalibrationResult& result,
                                         const ImuSeries& series0,
                                         const std::vector<BoardImu>& board);

}  // namespace plumb::estimation

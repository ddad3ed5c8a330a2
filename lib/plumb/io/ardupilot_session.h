// plumb/io/ardupilot_session.h — an ArduPilot DataFlash log (.bin) as a plumb Session: one IMU
// instance, a time window, the site from the GPS, and ArduPilot's own correction undone.
//
// ArduPilot logs IMU samples already corrected with the INS_* parameters of the same log
// (../shared/data/README.md, AP_InertialSensor): in the board frame, after the sensor's own
// rotation and the temperature correction,
//   acc_logged = R_ahrs ((acc_board - INS_ACCOFFS) .* INS_ACCSCAL),
//   gyr_logged = R_ahrs (gyr_board - INS_GYROFFS),
// R_ahrs the AHRS_ORIENTATION rotation (identity for 0), per instance INS_ACC/ACC2/ACC3 and
// INS_GYR/GYR2/GYR3. With AHRS_ORIENTATION = 0 the sensor's own output is recovered as
//   acc_board = acc_logged ./ INS_ACCSCAL + INS_ACCOFFS,  gyr_board = gyr_logged + INS_GYROFFS,
// so that plumb calibrates the sensor, not the corrected signal. Not undone (and said in the
// session's warnings): a non-zero AHRS_ORIENTATION, and the temperature calibration when
// INS_TCALn_ENABLE is 1.
#pragma once

#include <optional>
#include <string>

#include "plumb/core/session.h"
#include "plumb/io/dataflash.h"

namespace plumb::io {

struct ArdupilotSessionOptions {
  int imu = 0;                    ///< IMU instance, 0-based (IMU = 0, IMU2 = 1, ...), >= 0
  std::optional<double> from_s;   ///< keep samples at or after this log time, s
  std::optional<double> to_s;     ///< keep samples at or before this log time, s
  bool undo_correction = true;    ///< recover the sensor's output from the INS_* parameters
};

/// The site from GPS messages with a 3D fix (Status >= 3): the median latitude, longitude and
/// altitude (Alt, m above mean sea level, used as the height: the geoid separation, tens of
/// metres, changes gravity by about 1e-5 relative). nullopt without such fixes.
std::optional<SiteInput> SiteFromDataflash(const DataflashLog& log);

/// The session of one IMU instance of a decoded log. Throws plumb::InputError naming the log
/// when the instance is absent or the window holds fewer than 2 samples.
Session ArdupilotSession(const DataflashLog& log, const ArdupilotSessionOptions& options);

/// True when the file starts with a DataFlash record header (0xA3 0x95).
bool LooksLikeDataflash(const std::string& path);

}  // namespace plumb::io

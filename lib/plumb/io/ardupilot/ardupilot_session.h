// plumb/io/ardupilot/ardupilot_session.h — an ArduPilot DataFlash log (.bin or text .log) as a
// plumb Session: one IMU stream (FlightLogSelection), a time window, the site from the GPS, and
// ArduPilot's own correction undone.
//
// ArduPilot logs IMU samples (IMU, ACC/GYR, ISBD) already corrected with the parameters of the
// same log (ardupilot_correction.h has the exact steps): temperature calibration INS_TCALn
// (when INS_TCALn_ENABLE = 1), offsets and scales INS_ACC*OFFS/SCAL, INS_GYR*OFFS, and the
// board rotation R_board of AHRS_ORIENTATION:
//   acc_logged = R_board ((acc_board - Ptc_a(T)) - INS_ACCOFFS) .* INS_ACCSCAL)
//   gyr_logged = R_board (gyr_board - Ptc_g(T) - INS_GYROFFS)
// with Ptc(T) = P(clamp(T) - 35) - P(clamp(T_cal) - 35). Undone in reverse order:
//   a = R_board^T acc_logged;  a = a ./ INS_ACCSCAL + INS_ACCOFFS;  acc_board = a + Ptc_a(T)
//   g = R_board^T gyr_logged;  g = g + INS_GYROFFS;                gyr_board = g + Ptc_g(T)
// so that plumb calibrates the sensor, not the corrected signal. Not undone, and said in the
// session's warnings with the reason: a custom or unknown AHRS_ORIENTATION (then nothing is
// undone), missing parameters (that step is skipped), the temperature step for a stream
// without temperature (ACC/GYR/ISBD) or with INS_TCALn_* parameters missing. Every undone
// step is stated in the warnings with the parameter values used.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "plumb/core/session.h"
#include "plumb/io/ardupilot/dataflash.h"
#include "plumb/io/common/flight_log.h"

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

/// Where the log says the vehicle flew or moved (core/log_motion.h), on the IMU's clock (time
/// since boot): airborne from its EV records (NOT_LANDED until LAND_COMPLETE or DISARMED, or
/// until `t_end_s`, the log's last time), moving from its first GPS's Spd and VZ
/// (io/common/log_common.h GpsMotion).
std::vector<LogMotion> DataflashMotion(const DataflashLog& log, double t_end_s);

/// The session of one IMU stream of a decoded log (see DataflashStream for the selection and
/// ArdupilotSession's file comment for the undo). Throws plumb::InputError naming the log when
/// the stream is absent or gyroscope-only, or the window holds fewer than 2 samples.
/// `chosen` (optional): set to the description of the stream read (its name and instance).
Session ArdupilotSession(const DataflashLog& log, const FlightLogSelection& selection,
                         ImuStreamInfo* chosen = nullptr);

/// Compatibility: the default stream of options.imu (same as the selection with stream "").
Session ArdupilotSession(const DataflashLog& log, const ArdupilotSessionOptions& options);

/// True when the file starts with a DataFlash record header (0xA3 0x95).
bool LooksLikeDataflash(const std::string& path);

/// The DataFlash types a session and `plumb info` read the values of (the format tables FMT,
/// FMTU, UNIT, MULT; PARM; GPS; the IMU messages IMU*, ACC*, GYR*, ISBH, ISBD): the filter
/// FlightLog reads .bin and .log files with, so a big log keeps only these bodies in memory.
/// Its `decode` names IMU, IMU2, IMU3, ...: the binary reader decodes their samples in its pass
/// and keeps those instead of the bodies (DataflashType::imu; the text reader keeps bodies).
RecordFilter ArdupilotSessionRecords();

}  // namespace plumb::io

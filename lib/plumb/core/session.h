// plumb/core/session.h — what a reader produces and the calibrator consumes.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/log_motion.h"
#include "plumb/core/notice.h"
#include "plumb/core/segment.h"

namespace plumb {

/// Where the IMU was, as the user or the log's GPS stated it.
struct SiteInput {
  double lat_deg = 0.0;   ///< geodetic latitude, degrees, [-90, 90]
  double lon_deg = 0.0;   ///< longitude, degrees, [-180, 180]
  double height_m = 0.0;  ///< height above the WGS84 ellipsoid, m
  std::string source;     ///< "flags", "gps" or "file"
};

/// The firmware's identity of an IMU's two sensors, where the log records it (PX4's device
/// ids: bus type, bus, address and device type packed in one number). PX4 matches a
/// calibration slot to a sensor by it (CAL_ACCn_ID, CAL_GYROn_ID, TC_An_ID, TC_Gn_ID), not by
/// the sensor's instance.
struct DeviceIds {
  std::optional<double> accel;  ///< the accelerometer's, unset when the input does not say
  std::optional<double> gyro;   ///< the gyroscope's
};

/// Another IMU of the same board (SPEC 6, "Several IMUs of one board"): its samples on its own
/// stamps and in its own frame, as read.
struct BoardImu {
  int instance = 0;   ///< the log's sensor instance, or k of a native CSV's acc{k}_x columns
  std::string name;   ///< where it was read from, e.g. "IMU2", "SCALED_IMU3", "acc1_x.."
  ImuSeries series;
  /// What the firmware applied to these samples that the reader did not undo (as
  /// Session::firmware_left).
  std::vector<std::string> firmware_left;
  DeviceIds device_ids;  ///< its sensors' device ids, as Session::device_ids
};

/// A recorded session: samples, where they came from, optional segments and site.
struct Session {
  std::string source;              ///< file name(s) it was read from
  ImuSeries series;                ///< IMU 0's samples: its accelerometer defines the body frame
  /// The board's other IMUs (IMU 1, 2, ...) where the input has them (a native CSV's acc{k}_x
  /// columns, a simulated board); empty otherwise. The fit calibrates IMU 0 (`series`).
  std::vector<BoardImu> other_imus;
  std::vector<StillSegment> given_segments;  ///< stated by the user; empty means detect
  std::optional<SiteInput> site;
  /// What the reader skipped, repaired or assumed (notice.h lists the codes).
  std::vector<Notice> warnings;
  /// What a flight controller applied to these samples that the reader did not undo (e.g.
  /// "ArduPilot INS_ACC2OFFS/INS_ACC2SCAL"); empty when the samples are the sensor's own
  /// output, raw or fully reconstructed. Firmware parameters calibrated from samples that
  /// still carry a correction would replace it instead of adding to it.
  std::vector<std::string> firmware_left;
  /// The firmware's parameters as a flight log records them (empty for other inputs): what
  /// the exports say about the vehicle (INS_GYR_CAL, SENS_IMU_AUTOCAL, the device ids).
  std::map<std::string, double> log_params;
  /// IMU 0's sensors' device ids where the log records them: which calibration slot of the
  /// firmware an export writes (PX4's CAL_ACCn_*, matched by CAL_ACCn_ID).
  DeviceIds device_ids;
  /// The vehicle's MAVLink system id, when the log says it (SYSID_THISMAV, MAV_SYS_ID, or the
  /// system that sent a tlog's IMU frames).
  std::optional<int> system_id;
  /// Where the log says the vehicle flew or moved (its land detector, its GPS), on the
  /// samples' clock, in time order per evidence; empty for inputs that say nothing of it.
  std::vector<LogMotion> log_motion;
};

}  // namespace plumb

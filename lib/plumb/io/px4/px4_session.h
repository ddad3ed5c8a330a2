// plumb/io/px4/px4_session.h — a PX4 ULog (.ulg) as plumb IMU streams and Sessions: one stream, a
// time window, the site from the GPS, and PX4's own calibration undone when the log says what
// it was.
//
// IMU streams (FRD body frame, SI):
//  * "sensor_combined", instance 0: the primary IMU as the estimator sees it. accel =
//    accelerometer_m_s2[3] (m/s^2), gyro = gyro_rad[3] (rad/s; "gyro_rad_s" in some 2016
//    logs), time = timestamp (us since boot; the accelerometer's own time differs by
//    accelerometer_timestamp_relative, normally 0). Calibrated by PX4.
//  * "vehicle_imu", instance = multi_id: integrated samples; accel = delta_velocity /
//    (delta_velocity_dt * 1e-6) and gyro = delta_angle / (delta_angle_dt * 1e-6), i.e. the mean
//    specific force (m/s^2) and mean rate (rad/s) over each interval (dt fields in us); time =
//    timestamp_sample when present, else timestamp. Calibrated by PX4.
//  * "sensor_accel", instance = multi_id: the driver's output (already rotated by the driver's
//    fixed mounting rotation and scaled to m/s^2, NOT calibrated: raw for plumb), temperature
//    from its "temperature" field. When sensor_gyro has the same multi_id, each accel sample is
//    paired with the gyro sample nearest in time (timestamp_sample) within half the median
//    accel interval; unpaired accel samples are dropped. When fewer than half pair up, the
//    stream is accelerometer-only. sensor_gyro alone is not a stream (a Session needs accel).
//
// PX4's correction of sensor_combined and vehicle_imu (px4_correction.h has the equations:
// CAL_*n offsets and scales, the board rotation, the TC_*n thermal offsets) is undone with the
// parameters of the sensor's device id: vehicle_imu's accel_device_id/gyro_device_id; for
// sensor_combined CAL_ACC_PRIME/CAL_GYRO_PRIME (2016 logs) or vehicle_imu instance 0's ids.
// The temperature of the thermal term is the latest logged temperature of that device at or
// before the sample (sensor_accel / sensor_gyro "temperature", vehicle_imu_status
// "temperature_accel"/"temperature_gyro"). When a parameter or the temperature is missing,
// that part is left in the samples and the session's warnings say so.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/session.h"
#include "plumb/io/common/flight_log.h"
#include "plumb/io/px4/ulog.h"

namespace plumb::io {

/// Every IMU stream of `log` (see the file comment), sensor_combined first, then vehicle_imu
/// and sensor_accel by multi_id. `applied` names the CAL_* parameters PX4 applied (empty for
/// sensor_accel: raw); `undoable` is true when those parameters are in the log.
std::vector<ImuStreamInfo> ULogImuStreams(const ULog& log);

/// The site from vehicle_gps_position or sensor_gps messages with fix_type >= 3: the median
/// latitude, longitude and altitude. Old layout: lat/lon int32 in 1e-7 degrees, alt int32 mm
/// above mean sea level; new layout: latitude_deg/longitude_deg (double, degrees),
/// altitude_msl_m (m). The MSL altitude is used as the height (the geoid separation changes
/// gravity by about 1e-5 relative). nullopt without such fixes.
std::optional<SiteInput> SiteFromULog(const ULog& log);

/// Where the log says the vehicle flew or moved (core/log_motion.h), on the samples' clock
/// (us since boot * 1e-6): airborne while vehicle_land_detected says not landed (until it says
/// landed, or `t_end_s`), moving by its first GPS (vehicle_gps_position, else sensor_gps:
/// vel_m_s and vel_d_m_s with a 3D fix; io/common/log_common.h GpsMotion).
std::vector<LogMotion> ULogMotion(const ULog& log, double t_end_s);

/// The calibration parameters of the log's initial parameter set (names starting with
/// CAL_ACC, CAL_GYRO, TC_A, TC_G or SENS_BOARD_), firmware names and units.
std::map<std::string, double> ULogParams(const ULog& log);

/// The session of one stream (selection.stream, or the default stream for selection.imu: the
/// one with both accel and gyro at the highest rate) in SI FRD, t_s = time (us since boot) *
/// 1e-6, windowed to [from_s, to_s]; PX4's correction undone when selection.undo_correction
/// and the parameters are in the log (see the file comment). Samples whose time does not
/// increase are dropped. Warnings say which inputs were taken raw and which were
/// reconstructed, with the parameter values. Throws plumb::InputError naming the log when the
/// stream is absent or the window holds fewer than 2 samples.
/// `chosen` (optional): set to the description of the stream read (its name and instance).
Session ULogSession(const ULog& log, const FlightLogSelection& selection,
                    ImuStreamInfo* chosen = nullptr);

/// The log as `plumb info` shows it: format "px4-ulog", format_detail "ULog version N, K
/// subscriptions[, data appended at M offset(s)]", the IMU streams, the GPS site, ULogParams(),
/// D message counts per "topic/multi_id" and the reader's warnings (dropouts included).
FlightLogSummary ULogSummary(const ULog& log);

/// True when the file starts with the ULog magic 'U' 'L' 'o' 'g' 0x01 0x12 0x35.
bool LooksLikeULog(const std::string& path);

/// The ULog topics a session and `plumb info` read the values of (sensor_combined,
/// vehicle_imu, vehicle_imu_status, sensor_accel, sensor_gyro, sensor_gps,
/// vehicle_gps_position, vehicle_land_detected): the filter FlightLog reads .ulg files with, so a big log keeps only
/// these bodies in memory. Its `decode` names sensor_combined: the reader decodes its samples
/// in its pass and keeps those instead of the bodies (ULogTopic::imu).
RecordFilter Px4SessionTopics();

}  // namespace plumb::io

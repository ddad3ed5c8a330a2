// plumb/export/board_export.h — the exports of a board fit (SPEC 6, "Several IMUs of one
// board"): every IMU's parameters under its own instance's names, in one file per format.
//
//   ardupilot  one .param: INS_ACC*/INS_GYR* for IMU 0's instance, INS_ACC2*/INS_GYR2* and
//              INS_ACC3*/INS_GYR3* for the others' (formats.h), each with its device id
//   px4        one .params: CAL_ACC{i}_*, CAL_GYRO{i}_* (and TC_*) per instance, with its ids
//   kalibr     Kalibr's multi-IMU yaml (kalibr.h KalibrImuSetYaml): imu0 (IMU 0), imu1, ...
//   json       the three above
// Each IMU is exported as Export() exports one (export.h), from its calibration alone
// (estimation/board_alone.h), and its report measures the file on that IMU's own still
// samples. Where each IMU sits in the body has no firmware parameter (both firmwares rotate
// every IMU by the one board orientation): the firmware files carry the offsets and scales
// only, and the report says so.
#pragma once

#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/session.h"
#include "plumb/estimation/calibration.h"
#include "plumb/estimation/fit_report.h"
#include "plumb/export/export.h"

namespace plumb::exporter {

/// One IMU of a board as ExportBoard takes it.
struct BoardImuExport {
  int instance = 0;                     ///< the firmware instance its parameters are named for
  DeviceIds device_ids;                 ///< its sensors' (PX4's slots follow them: Px4SlotsOf)
  estimation::Calibration calibration;  ///< the IMU alone (IMU 0: the fit's own, board cleared)
  const ImuSeries* series = nullptr;    ///< its samples
  std::vector<estimation::StillSegmentFit> still;  ///< the fit's still segments in its samples
  Quat R_b_i = Quat::Identity();        ///< its frame into the body (IMU 0's: identity)
  Vec3 lever_arm_m = Vec3::Zero();      ///< from IMU 0, m, body frame
  double time_offset_s = 0.0;           ///< added to its stamps, s
  bool mount_determined = true;         ///< the session determines R_b_i (not held)
};

/// IMU 0 (`calibration` without its board, `series0`, the fit's `still`, firmware instance
/// `imu0_instance`, device ids `imu0_device_ids`), then every IMU of calibration.board with its samples from `board` (the
/// session's, in the same order; BoardImu::instance is its firmware instance). `series0` and
/// `board` must outlive the result. Throws plumb::Error when `board` does not match.
std::vector<BoardImuExport> BoardImuExports(const estimation::Calibration& calibration,
                                            const ImuSeries& series0,
                                            const std::vector<estimation::StillSegmentFit>& still,
                                            const std::vector<BoardImu>& board,
                                            int imu0_instance, const DeviceIds& imu0_device_ids);

/// Export() of `format` for every IMU of `imus` (IMU 0 first) in one output: the firmware
/// formats' parameters in one file (a parameter two IMUs write alike, such as INS_GYR_CAL,
/// once), Kalibr's IMU set, or json of the three; the report lines per IMU, headed by it; JSON:
/// IMU 0's as Export() gives it, with "imus": every IMU's (its "instance" added). Throws what
/// Export() throws for any IMU, naming it.
ExportOutput ExportBoard(const std::string& format, const std::vector<BoardImuExport>& imus,
                         const ExportOptions& options);

}  // namespace plumb::exporter

// plumb/report/board_agreement_text.h — the board's IMUs against IMU 0 at rest, before and after
// the calibration, as the firmware's pre-arm check measures them (estimation/board_agreement.h):
// text for `calibrate --imus` and its JSON key "board_agreement".
//
// JSON: [{instance, poses, accel {before, after, in_body, limit}, gyro {before, after,
//         in_body, limit} or null, within_before, within_after,
//         matched_by_construction}]
//   SI (m/s^2, rad/s)
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "plumb/estimation/board_agreement.h"

namespace plumb::report {

/// One line per other IMU: accelerometer and gyroscope disagreement before -> after, what is
/// left once the IMUs' turn is taken out, and whether ArduPilot's check would pass.
std::string BoardAgreementText(const std::vector<estimation::ImuAgreement>& agreement);

nlohmann::json BoardAgreementJson(const std::vector<estimation::ImuAgreement>& agreement);

}  // namespace plumb::report

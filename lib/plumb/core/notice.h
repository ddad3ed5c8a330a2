// plumb/core/notice.h — a warning or piece of advice as data: a stable code for the situation,
// the message in words, and the options the message points the user to (option_name.h), as
// errors (error.h, options()) and gates (estimation/gates.h) carry them. A front end prints
// the message; a program reads the code and the options, and the CLI and Python each spell
// those options their own way.
//
// The codes, one per situation, snake_case and stable (a message's words may change, its code
// does not). Beside each, where it is made.
//
// The session's warnings (Session::warnings: what a reader skipped, repaired or assumed; a
// log's summary, FlightLogSummary::warnings, has log_damaged and records_dropped):
//   nan_rows_skipped        io/text/text_table.cc: rows with NaN or infinite values skipped
//   log_damaged             io/*/*_session.cc: what a log reader skipped or found malformed
//                           (bytes, records, messages, checksums), from its counts
//   records_dropped         io/*/*_session.cc: records left out by their time, or the
//                           logger's dropouts
//   samples_out_of_order    io/mavlink/mavlink_session.cc: samples whose time did not increase
//   gyro_unpaired           io/px4/px4_session.cc: a gyroscope topic too few accelerometer
//                           samples pair with (accelerometer only)
//   other_senders           io/mavlink/mavlink_session.cc: other systems sent IMU messages
//   sample_source           io/mavlink/mavlink_session.cc: the system, component and units;
//                           io/ros/ros_session.cc: a bag topic's frame, units, what is unused
//   sample_times            io/mavlink/mavlink_session.cc, io/ros/ros_session.cc: which clock
//                           gave the times
//   raw_sensor              io/px4, io/mavlink: the samples are the sensor's raw output
//   correction_kept         io/*: a flight controller's correction taken as logged
//   correction_undone       io/*: a correction taken out of the samples, with its values
//   correction_not_undone   io/*: part of a correction left in (its parameters missing, or
//                           no temperature) or nothing to undo (learning)
//   correction_changed      io/*: the correction's parameters changed during the log
//   inputs_overlap          io/input/open_inputs.cc: a further input's clock shifted to follow
//                           the previous one (each input's own notices keep their code)
//   clock_uniform           io/input/open_inputs.cc: times from a uniform clock fitted through
//                           the stamps
//   clock_kept              io/input/open_inputs.cc: no uniform clock fits; the stamps kept
//   gravity_fixed           pipeline/fit_setup.cc: a fixed gravity instead of WGS84's (kGravity;
//                           a calibration document's input warnings)
//
// The fit's warnings (estimation::FitReport::warnings: what the user must know of the fit):
//   no_gyroscope            estimation/calibrator.cc: the accelerometer alone is calibrated
//   undetermined            estimation/advice.cc: parameters the data cannot determine, and
//                           what to record
//   turns_above_noise       estimation/advice.cc: the turns' velocity residuals above their band
//   site_unknown            estimation/advice.cc: no site (kSite)
//   heading_assumed         estimation/advice.cc: the first pose's heading held at 0
//                           (kHeading, kLevelNorth)
//   covariance_singular     estimation/covariance.cc: sigmas from the pseudo-inverse
//   walk_not_estimated      estimation/walk_estimate.cc: too few holds to estimate the walk
//   sigma_rests_on_wander   estimation/wander_sensitivity.cc, calibrator.cc: the sigmas rest on
//                           the typical MEMS wander (kNoiseFrom)
//
// The fit's notes (estimation::FitReport::notes: how the fit was made):
//   allan_too_short         estimation/wander_levels.cc: no Allan deviation of the still data
//   wander_levels           estimation/wander_levels.cc: the wander levels and where they came
//                           from (kAccelWalk, kGyroWalk, kAccelInstability, kGyroInstability,
//                           kNoiseFrom, and kEstimateWalk when the session can estimate them)
//   walk_estimated          estimation/walk_estimate.cc: the levels the session's holds resolved
//   not_a_turn              estimation/advice.cc: motion between poses left out of the fit
//
// Elsewhere, each beside the struct that holds them: the exports' notes (export/export.h),
// a comparison's and a peer's (peers/comparison.h, peers/forward_calibration.h), the paper's
// methods' (paper/benchmark.h, paper/static_procedure.h).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "plumb/core/option_name.h"

namespace plumb {

/// A warning or piece of advice: Notice{"site_unknown", text, {Option::kSite}}.
struct Notice {
  /// The situation, stable and snake_case (the list above), e.g. "site_unknown". A program
  /// tests this, never the message.
  std::string code;
  /// The notice in words, as the user reads it (the options spelled by the front end's
  /// OptionText); what the text and JSON reports print.
  std::string message;
  /// The options `message` points the user to (through OptionText), in its order; empty when
  /// it names none.
  std::vector<Option> options;

  friend bool operator==(const Notice& a, const Notice& b) {
    return a.code == b.code && a.message == b.message && a.options == b.options;
  }
  friend bool operator!=(const Notice& a, const Notice& b) { return !(a == b); }
};

/// The messages of `notices`, in order: what the reports print and the JSON writes.
inline std::vector<std::string> Messages(const std::vector<Notice>& notices) {
  std::vector<std::string> out;
  out.reserve(notices.size());
  for (const Notice& n : notices) out.push_back(n.message);
  return out;
}

/// `message` as a notice with `code` that names no option (the readers' correction notes).
inline void AddNotice(std::vector<Notice>& to, std::string code, std::string message) {
  to.push_back(Notice{std::move(code), std::move(message), {}});
}

/// Each of `messages` as a notice with `code` (a reader's lines of one kind).
inline void AddNotices(std::vector<Notice>& to, const std::string& code,
                       std::vector<std::string> messages) {
  for (std::string& m : messages) to.push_back(Notice{code, std::move(m), {}});
}

}  // namespace plumb

// What every reader's fuzz target does after parsing: select each IMU stream the log lists
// (the session a user would get: samples, window, the firmware's correction undone), where
// a plumb::Error is an accepted answer and anything else (a crash, a sanitizer report, another
// exception) is a finding.
#pragma once

#include <vector>

#include "plumb/core/error.h"
#include "plumb/io/common/flight_log.h"

namespace plumb::fuzz {

/// Calls `select(selection)` for every stream of `streams`, each inside try/catch(plumb::Error).
template <typename Select>
void SelectEveryStream(const std::vector<io::ImuStreamInfo>& streams, Select select) {
  for (const io::ImuStreamInfo& info : streams) {
    io::FlightLogSelection selection;
    selection.imu = info.instance;
    selection.stream = info.name;
    try {
      select(selection);
    } catch (const Error&) {
    }
  }
}

}  // namespace plumb::fuzz

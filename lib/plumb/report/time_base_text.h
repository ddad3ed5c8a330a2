// plumb/report/time_base_text.h — what the stamps are (signal/time_base.h), as `plumb info` and
// `plumb diagnose` print it and write it in their JSON.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "plumb/signal/time_base.h"

namespace plumb::report {

/// One line, e.g. "time base: a host's arrival clock, jitter RMS 1.46 ms (14.6 % of the
/// interval; max 5.1 ms); uniform clock 100.000 Hz fitted; 0 samples dropped; intervals median
/// 10.22 ms, 230 long, 229 short: try --clock uniform", ending in a newline.
std::string TimeBaseLine(const signal::TimeBase& base);

/// {"clock": "uniform"|"host_arrival"|"irregular"|"too_short", "rate_hz", "interval_s", "jitter_rms_s",
/// "jitter_max_s", "median_interval_s", "dropped", "drop_places", "first_drop_s",
/// "long_intervals", "short_intervals"}.
nlohmann::json TimeBaseJson(const signal::TimeBase& base);

}  // namespace plumb::report

// plumb/report/time_base_text.cc — see time_base_text.h.
#include "plumb/report/time_base_text.h"

#include <sstream>

#include "plumb/report/json_report.h"

namespace plumb::report {
namespace {

const char* ClockName(signal::ClockKind kind) {
  switch (kind) {
    case signal::ClockKind::kUniform: return "uniform";
    case signal::ClockKind::kHostArrival: return "host_arrival";
    case signal::ClockKind::kIrregular: return "irregular";
    case signal::ClockKind::kTooShort: break;
  }
  return "too_short";
}

}  // namespace

std::string TimeBaseLine(const signal::TimeBase& b) {
  std::ostringstream out;
  out << "time base: ";
  if (b.kind == signal::ClockKind::kTooShort) {
    out << "not judged (" << b.samples << " samples)\n";
    return out.str();
  }
  const double ms = 1e3;
  if (b.kind == signal::ClockKind::kIrregular) {
    out.precision(3);
    out << "irregular: no sample clock fits the stamps (intervals median "
        << b.median_interval_s * ms << " ms; a fitted clock would leave " << b.jitter_rms_s * ms
        << " ms RMS); the stamps are the only time\n";
    return out.str();
  }
  out << (b.kind == signal::ClockKind::kUniform ? "a uniform sample clock"
                                                : "a host's arrival clock")
      << ", " << std::fixed;
  out.precision(3);
  out << b.rate_hz() << " Hz fitted, jitter RMS ";
  out.unsetf(std::ios::floatfield);
  out.precision(3);
  out << b.jitter_rms_s * ms << " ms (" << 100.0 * b.jitter_rms_s / b.interval_s
      << " % of the interval; max " << b.jitter_max_s * ms << " ms); " << b.dropped
      << " samples dropped";
  if (b.dropped > 0) {
    out << " at " << b.drop_places << " places (first before " << std::fixed;
    out.precision(3);
    out << b.first_drop_s << " s)";
    out.unsetf(std::ios::floatfield);
    out.precision(3);
  }
  out << "; intervals median " << b.median_interval_s * ms << " ms, " << b.long_intervals
      << " long (> 1.25 x) and " << b.short_intervals << " short (< 0.75 x)";
  if (b.kind == signal::ClockKind::kHostArrival) {
    out << ": the samples' own times are the fitted clock's (--clock uniform)";
  }
  out << "\n";
  return out.str();
}

nlohmann::json TimeBaseJson(const signal::TimeBase& b) {
  return {{"clock", ClockName(b.kind)},
          {"samples", b.samples},
          {"rate_hz", Number(b.rate_hz())},
          {"interval_s", Number(b.interval_s)},
          {"jitter_rms_s", Number(b.jitter_rms_s)},
          {"jitter_max_s", Number(b.jitter_max_s)},
          {"median_interval_s", Number(b.median_interval_s)},
          {"dropped", b.dropped},
          {"drop_places", b.drop_places},
          {"first_drop_s", b.drop_places > 0 ? Number(b.first_drop_s) : nlohmann::json(nullptr)},
          {"long_intervals", b.long_intervals},
          {"short_intervals", b.short_intervals}};
}

}  // namespace plumb::report

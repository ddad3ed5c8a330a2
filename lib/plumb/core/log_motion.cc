// See log_motion.h.
#include "plumb/core/log_motion.h"

#include <algorithm>

#include "plumb/core/number_text.h"

namespace plumb {
namespace {

/// A time or speed to a tenth, as a user reads it ("228.1").
std::string Tenth(double v) { return FixedText(v, 1); }

}  // namespace

bool LogMotion::Covers(double t0, double t1) const {
  const double shared = std::min(t1, t_end_s) - std::max(t0, t_begin_s);
  if (!(shared > 0.0)) return false;
  return shared > kLogMotionEdge_s || (t0 >= t_begin_s && t1 <= t_end_s);
}

std::string Describe(const LogMotion& m) {
  const std::string span = Tenth(m.t_begin_s) + "-" + Tenth(m.t_end_s) + " s";
  if (m.evidence == LogMotion::Evidence::kAirborne) {
    return "airborne " + span + " (" + m.source + ")";
  }
  std::string what = "up to " + Tenth(m.max_ground_speed_m_s) + " m/s over ground";
  if (m.max_climb_m_s > 0.0) what += ", " + Tenth(m.max_climb_m_s) + " m/s climb or sink";
  return "moving " + span + " by " + m.source + " (" + what + ", " +
         FixedText(m.ground_distance_m, 0) + " m)";
}

}  // namespace plumb

// apps/plumb/paper_methods.h — `plumb calibrate --method paper-benchmark|paper-static`: the
// seed paper's two procedures as printed (plumb/paper), printed and written as JSON in the
// paper's convention and in plumb's forward one (SPEC section 1).
#pragma once

#include <string>
#include <vector>

#include "plumb/core/segment.h"
#include "plumb/core/session.h"
#include "plumb/geo/site.h"
#include "plumb/paper/benchmark.h"

namespace plumb::cli {

/// Runs paper-benchmark on the series with the given still periods and turn sections (empty:
/// the gaps between still periods of the same pose); prints both conventions; writes
/// `json_path` when not empty. Returns the exit code: kExitGateFailed, before writing, when
/// `strict` and the backend's fit failed a gate (estimation/gates.h).
int RunPaperBenchmark(const Session& session, const std::vector<StillSegment>& still,
                      const std::vector<paper::MotionRange>& motion, const geo::Site& site,
                      const std::vector<std::string>& inputs, const std::string& json_path,
                      bool strict);

/// Runs paper-static on samples [begin, end) at `site` (must be known); prints both
/// conventions; writes `json_path` when not empty. Returns the exit code, as above.
int RunPaperStatic(const Session& session, std::size_t begin, std::size_t end,
                   const geo::Site& site, const std::vector<std::string>& inputs,
                   const std::string& json_path, bool strict);

}  // namespace plumb::cli

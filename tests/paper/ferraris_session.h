// tests/paper/ferraris_session.h — imucal's real Ferraris session (../shared/data/ferraris),
// read as the paper tests need it: rad/s gyroscope, its section list split into still and turn
// ranges. Tests call SkipUnlessFerrarisData() first: the shared data is optional.
#pragma once

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "plumb/io/text/segments_file.h"
#include "plumb/io/text/text_table.h"
#include "plumb/paper/benchmark.h"

namespace plumb::paper::testing {

/// Path of a file of imucal's example in the shared data.
inline std::string FerrarisFile(const std::string& name) {
  return std::string(PLUMB_SHARED_DATA_DIR) + "/ferraris/imucal/" + name;
}

/// The first of the session's files that is missing, or "" when all are there.
inline std::string MissingFerrarisFile() {
  for (const char* name : {"example_ferraris_session.csv", "example_ferraris_session_list.json",
                           "example_ferraris_session_cal_102.4Hz.json"}) {
    if (!std::filesystem::exists(FerrarisFile(name))) return FerrarisFile(name);
  }
  return "";
}

struct FerrarisSession {
  Session session;
  std::vector<StillSegment> still;   ///< x_p, x_a, y_p, y_a, z_p, z_a
  std::vector<MotionRange> motion;   ///< x_rot, y_rot, z_rot
};

/// Reads the session (102.4 Hz, gyroscope in deg/s converted to rad/s) and its sections.
inline FerrarisSession ReadFerrarisSession() {
  io::TextTableOptions o;
  o.header_row = true;
  o.time = "n_samples";
  o.time_unit_s = 1.0 / 102.4;
  o.acc.axes = {"acc_x", "acc_y", "acc_z"};
  o.gyr.axes = {"gyr_x", "gyr_y", "gyr_z"};
  o.gyr.SetScale(M_PI / 180.0);
  FerrarisSession f;
  f.session = io::ReadTextTable(FerrarisFile("example_ferraris_session.csv"), o);
  const io::GivenSections given =
      io::ReadGivenSections(FerrarisFile("example_ferraris_session_list.json"), f.session.series);
  f.still = given.still;
  for (const io::MotionSection& m : given.motion) f.motion.push_back({m.begin, m.end, m.label});
  return f;
}

}  // namespace plumb::paper::testing

/// Skips the calling test, naming the missing file, when imucal's session is absent.
#define SKIP_UNLESS_FERRARIS_DATA()                                                   \
  do {                                                                               \
    const std::string missing = ::plumb::paper::testing::MissingFerrarisFile();      \
    if (!missing.empty()) GTEST_SKIP() << "shared data absent: " << missing;         \
  } while (false)

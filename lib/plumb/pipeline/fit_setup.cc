// See fit_setup.h.
#include "plumb/pipeline/fit_setup.h"

#include <algorithm>
#include <utility>

#include "plumb/core/error.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/gates.h"
#include "plumb/io/text/segments_file.h"
#include "plumb/segmentation/given_segments.h"

namespace plumb::pipeline {

segmentation::SegmentationResult FindSegments(const ImuSeries& series,
                                              const SegmentRequest& request) {
  if (!request.segments_path.empty()) {
    return segmentation::UseGivenSegments(series, io::ReadSegments(request.segments_path, series));
  }
  segmentation::StillDetectorOptions detector = request.detector;
  detector.use_gyro = !request.still_accel_only;
  detector.acc_unit = series.acc_unit;
  detector.gyr_unit = series.gyr_unit;
  return segmentation::DetectStillSegments(series, detector);
}

namespace {

/// FitSetup::board_models: each other IMU's model of `own` (by instance), else `model`; none
/// when `own` is empty.
std::vector<model::Model> BoardModels(const std::vector<BoardImu>& board,
                                      const std::map<int, model::Model>& own,
                                      const model::Model& model) {
  std::vector<model::Model> models;
  if (own.empty()) return models;
  std::string instances;
  for (const BoardImu& imu : board) {
    instances += (instances.empty() ? "" : ", ") + std::to_string(imu.instance);
  }
  for (const auto& [instance, m] : own) {
    if (std::none_of(board.begin(), board.end(),
                     [&](const BoardImu& imu) { return imu.instance == instance; })) {
      throw Error("a model is given for imu" + std::to_string(instance) +
                  ", which is not among the board's other IMUs fitted (" +
                  (instances.empty() ? std::string("none") : instances) + ")");
    }
  }
  for (const BoardImu& imu : board) {
    const auto it = own.find(imu.instance);
    models.push_back(it == own.end() ? model : it->second);
  }
  return models;
}

}  // namespace

FitSetup PrepareFit(const Session& session, const segmentation::SegmentationResult& segmentation,
                    FitRequest request) {
  FitSetup out;
  out.segments = segmentation.segments;
  if (request.level_north && !out.segments.empty()) {
    out.segments.front().known_R_n_b = Quat::Identity();
  }
  out.site = geo::ResolveSite(request.site, session.site, request.gravity_m_s2);
  out.input_warnings = session.warnings;
  if (request.gravity_m_s2 && out.site.known) {
    out.input_warnings.push_back(Notice{"gravity_fixed",
                                        "gravity fixed at " +
                                            std::to_string(*request.gravity_m_s2) + " m/s^2 by " +
                                            OptionText(Option::kGravity) +
                                            " instead of WGS84 normal gravity",
                                        {Option::kGravity}});
  }
  out.model = std::move(request.model);
  out.model.t_ref_s = session.series.t_s.front();
  out.model.temp_ref_c = request.temp_ref_c;
  out.board_models = BoardModels(session.other_imus, request.imu_models, out.model);
  out.options = std::move(request.options);
  out.options.log_motion = session.log_motion;
  return out;
}

estimation::CalibrationResult CalibrateSession(const Session& session, const FitSetup& fit) {
  try {
    return estimation::CalibrateBoard(session.series, session.other_imus, fit.segments, fit.model,
                                      fit.site, fit.options, fit.board_models);
  } catch (const Error& e) {
    const std::vector<estimation::Gate> gates =
        estimation::CheckSamples(session.series, fit.segments);
    if (gates.empty()) throw;
    std::string text = e.what();
    for (const auto& g : gates) {
      text += "\ngate failed: " + g.name + ": " + session.source + ": " + g.message;
    }
    throw Error(text);
  }
}

std::string GateFailure(const estimation::FitReport& fit, const std::string& source) {
  std::string names;
  for (const auto& g : fit.gates) names += (names.empty() ? "" : ", ") + g.name;
  const std::size_t n = fit.gates.size();
  return "the fit of " + source + " failed " +
         (n == 1 ? std::string("a gate") : std::to_string(n) + " gates") + " (" + names + ")";
}

}  // namespace plumb::pipeline

// See board_diagnosis.h.
#include "plumb/diagnostics/board_diagnosis.h"

#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/still_set.h"
#include "plumb/estimation/uncertainty.h"

namespace plumb::diagnostics {
namespace {

/// IMU 0's still segments as `series` samples them; those it holds fewer than 2 samples of are
/// left out (the board's fit refuses them: StillSetOnBoardImu).
std::vector<StillSegment> SegmentsOnBoardImu(const std::vector<StillSegment>& segments,
                                             const ImuSeries& series0, const ImuSeries& series) {
  std::vector<StillSegment> own;
  for (const StillSegment& s : segments) {
    StillSegment on = estimation::SegmentOnBoardImu(s, series0, series);
    if (on.count() >= 2) own.push_back(std::move(on));
  }
  return own;
}

/// The chi^2 test of one fit alone: the upper edge of its band, and whether it is above it.
void TestOwnMisfit(ImuDiagnosis& imu) {
  const estimation::FitReport& fit = imu.diagnosis.fit.fit;
  if (fit.dof <= 0) return;
  imu.chi2_limit = estimation::Chi2BandUpper(fit.dof) * fit.dof;
  imu.own_misfit = estimation::Chi2AboveBand(fit);
}

/// Sums the fits alone of `test.imus` into it, and says why there is nothing to test.
void SumAlone(const std::vector<ImuDiagnosis>& imus, RigidBoardTest& test) {
  for (std::size_t k : test.imus) {
    const estimation::FitReport& fit = imus[k].diagnosis.fit.fit;
    // Nested only when an other IMU's fit alone has no residual the board's lacks (its
    // velocity residuals: the board has IMU 0's alone).
    if (k > 0 && fit.velocity_segments > 0) {
      test.untested = "IMU " + std::to_string(k) + "'s fit alone has velocity residuals, which the "
                      "board's fit has for IMU 0 only";
    }
    test.chi2_alone += fit.chi2;
    test.dof_alone += fit.dof;
  }
}

}  // namespace

bool FitsAlone(const ImuDiagnosis& imu) {
  return !imu.own_misfit && imu.diagnosis.fit.fit.gates.empty();
}

RigidBoardTest TestRigidBoard(const std::vector<ImuDiagnosis>& imus,
                              const estimation::FitReport& board) {
  RigidBoardTest t;
  if (imus.front().own_misfit) {
    t.untested = "IMU 0's own misfit enters every pose's attitude, which the IMUs share";
    return t;
  }
  if (!FitsAlone(imus.front())) {
    t.untested = "IMU 0's fit alone failed a gate (" +
                 imus.front().diagnosis.fit.fit.gates.front().name + ")";
    return t;
  }
  for (std::size_t k = 0; k < imus.size(); ++k) {
    if (FitsAlone(imus[k])) t.imus.push_back(k);
  }
  if (t.imus.size() < 2) {
    t.untested = "no other IMU fits within its noise alone and passes its gates";
    t.imus.clear();
    return t;
  }
  t.chi2_board = board.chi2;
  t.dof_board = board.dof;
  SumAlone(imus, t);
  if (t.untested.empty() && t.constraints() <= 0) {
    t.untested = "sharing the attitudes adds no constraint these data can test (too few "
                 "poses and turns)";
  }
  if (!t.untested.empty()) {
    t.imus.clear();
    return t;
  }
  t.limit = estimation::Chi2BandUpper(t.constraints()) * t.constraints();
  return t;
}


std::optional<std::vector<model::Model>> NextBoardModels(const std::vector<ImuDiagnosis>& imus,
                                                         const std::vector<model::Model>& models) {
  std::vector<model::Model> next = models;
  bool changed = false;
  for (std::size_t k = 0; k < imus.size(); ++k) {
    if (!imus[k].own_misfit) continue;
    const Candidate* advised = Recommended(imus[k].diagnosis);
    if (advised == nullptr || advised->kind != CandidateKind::kEffect) continue;
    const std::optional<std::string> spec = NextModelSpec(imus[k].diagnosis);
    if (!spec) continue;
    const model::Model& was = models[k];
    next[k] = model::Model::Parse(*spec);
    next[k].t_ref_s = was.t_ref_s;
    next[k].temp_ref_c = was.temp_ref_c;
    changed = true;
  }
  if (!changed) return std::nullopt;
  return next;
}

BoardDiagnosis DiagnoseBoard(const ImuSeries& series0, const std::vector<BoardImu>& board,
                             const std::vector<StillSegment>& segments, const model::Model& model,
                             const geo::Site& site, const DiagnoseOptions& options,
                             const std::vector<model::Model>& board_models) {
  BoardDiagnosis d;
  d.models.push_back(model);
  for (std::size_t k = 0; k < board.size(); ++k) {
    d.models.push_back(board_models.empty() ? model : board_models.at(k));
  }
  if (options.on_stage) options.on_stage("board fit");
  d.board = estimation::CalibrateBoard(series0, board, segments, model, site, options.calibration,
                                       board_models);

  ImuDiagnosis& imu0 = d.imus.emplace_back();
  if (options.on_stage) options.on_stage("IMU 0 alone");
  imu0.diagnosis = Diagnose(series0, segments, model, site, options);
  for (std::size_t k = 0; k < board.size(); ++k) {
    const BoardImu& imu = board[k];
    ImuDiagnosis& alone = d.imus.emplace_back();
    alone.instance = imu.instance;
    alone.name = imu.name;
    model::Model own = d.models[k + 1];
    if (!imu.series.has_gyro()) own.DropGyro();
    if (options.on_stage) options.on_stage(imu.name + " alone");
    alone.diagnosis =
        Diagnose(imu.series, SegmentsOnBoardImu(segments, series0, imu.series), own, site, options);
  }
  for (ImuDiagnosis& imu : d.imus) TestOwnMisfit(imu);

  // Across: the IMUs within their noise alone, together (refitted when some are left out).
  std::vector<BoardImu> fitting;
  std::vector<model::Model> fitting_models;
  for (std::size_t k = 1; k < d.imus.size(); ++k) {
    if (!FitsAlone(d.imus[k])) continue;
    fitting.push_back(board[k - 1]);
    fitting_models.push_back(d.models[k]);
  }
  const estimation::FitReport* together = &d.board.fit;
  if (FitsAlone(d.imus.front()) && !fitting.empty() && fitting.size() < board.size()) {
    if (options.on_stage) options.on_stage("board fit of the IMUs within their noise");
    d.rigid_board = estimation::CalibrateBoard(series0, fitting, segments, model, site,
                                               options.calibration, fitting_models);
    together = &d.rigid_board->fit;
  }
  d.rigid = TestRigidBoard(d.imus, *together);

  // The board's next fit: each IMU's own advice, refitted together (advised only if better).
  if (std::optional<std::vector<model::Model>> next = NextBoardModels(d.imus, d.models)) {
    if (options.on_stage) options.on_stage("board refit with each IMU's advice");
    BoardDiagnosis::Next n;
    n.models = std::move(*next);
    n.board = estimation::CalibrateBoard(
        series0, board, segments, n.models.front(), site, options.calibration,
        std::vector<model::Model>(n.models.begin() + 1, n.models.end()));
    n.advised = n.board.fit.gates.empty() && n.board.fit.dof > 0 && d.board.fit.dof > 0 &&
                n.board.fit.chi2_dof() < d.board.fit.chi2_dof();
    d.next = std::move(n);
  }
  return d;
}

}  // namespace plumb::diagnostics

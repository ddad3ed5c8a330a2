#include "plumb/estimation/calibrator.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/core/units.h"
#include "plumb/estimation/advice.h"
#include "plumb/estimation/board.h"
#include "plumb/estimation/calibration_problem.h"
#include "plumb/estimation/covariance.h"
#include "plumb/estimation/fitted_problem.h"
#include "plumb/estimation/linearity.h"
#include "plumb/estimation/gates.h"
#include "plumb/estimation/initialization.h"
#include "plumb/estimation/noise_model.h"
#include "plumb/estimation/solve.h"
#include "plumb/estimation/still_set.h"
#include "plumb/estimation/walk_estimate.h"
#include "plumb/estimation/wander_levels.h"
#include "plumb/estimation/wander_sensitivity.h"

namespace plumb::estimation {
namespace {

/// The model as this session can fit it: without gyroscope terms when the input has no
/// gyroscope (said in `warnings`). Throws when an effect needs data the input lacks.
model::Model ModelForSession(const model::Model& requested, const ImuSeries& series,
                             const geo::Site& site, std::vector<Notice>& warnings) {
  model::Model model = requested;
  if (!series.has_gyro() && model.has_gyro()) {
    model.DropGyro();
    warnings.push_back(
        Notice{"no_gyroscope", "the input has no gyroscope: calibrating the accelerometer only", {}});
  }
  if (site.known && model.has_effect("earth_rate")) {
    throw Error("earth_rate is a candidate only without a site: with " +
                OptionText(Option::kSite) +
                " Earth rate is already in the model (from GeographicLib); drop it from the "
                "model",
                {Option::kSite});
  }
  for (const auto& term : model.terms()) {
    const auto& info = term.effect->info();
    if (info.excitation.temperature && !series.has_temperature()) {
      throw InsufficientDataError(info.name + " needs the sensor temperature, but the input has "
                                  "no temperature column; record it (temp_c) or drop the effect");
    }
  }
  return model;
}

/// Each of the board's other IMUs' model (its own of `board_models`, else IMU 0's `model`, with
/// IMU 0's references) checked against its samples as ModelForSession checks IMU 0's; the
/// warnings prefixed with the IMU.
std::vector<model::Model> BoardModelsForSession(const std::vector<BoardImu>& board,
                                                const std::vector<model::Model>& board_models,
                                                const model::Model& model, const geo::Site& site,
                                                std::vector<Notice>& warnings) {
  if (!board_models.empty() && board_models.size() != board.size()) {
    throw Error("calibrate: " + std::to_string(board_models.size()) + " models for the board's " +
                std::to_string(board.size()) + " other IMUs; give one per IMU, or none");
  }
  std::vector<model::Model> models;
  for (std::size_t k = 0; k < board.size(); ++k) {
    model::Model requested = board_models.empty() ? model : board_models[k];
    requested.t_ref_s = model.t_ref_s;
    requested.temp_ref_c = model.temp_ref_c;
    std::vector<Notice> own;
    models.push_back(ModelForSession(requested, board[k].series, site, own));
    for (Notice& n : own) {
      n.message = "imu" + std::to_string(board[k].instance) + ": " + n.message;
      warnings.push_back(std::move(n));
    }
  }
  return models;
}

}  // namespace

FittedProblem FitProblem(const ImuSeries& series, const std::vector<StillSegment>& segments,
                         const model::Model& model_in, const geo::Site& site,
                         const CalibrationOptions& options, CalibrationResult& result,
                         const std::vector<BoardImu>& board,
                         const std::vector<model::Model>& board_models) {
  options.Validate();
  Calibration& cal = result.calibration;
  FitReport& fit = result.fit;
  cal.method = options.method;
  cal.site = site;
  cal.model = ModelForSession(model_in, series, site, fit.warnings);
  cal.has_gyro = cal.model.has_gyro();
  cal.acc_unit = series.acc_unit;
  cal.gyr_unit = series.gyr_unit;

  // 1. The still set; 2. the noise model; 3. starting values.
  const bool earth_rate_seen = site.known && cal.has_gyro && options.use_still_gyro;
  const bool motion_on = options.use_motion && cal.has_gyro;
  StillSet still = MakeStillSet(series, segments, earth_rate_seen, motion_on, options);
  FittedProblem out;
  out.noise = EstimateNoise(series, still, cal.has_gyro, options);
  model::ParameterBlocks theta = cal.model.ZeroParameters();
  out.start = Initialize(series, cal.model, site.gravity(), cal.has_gyro,
                         options.first_heading_deg, still, theta, options.run_jobs);
  AssignHeadingGauge(still, cal.has_gyro);
  if (options.ModelsWander()) {
    // 2a. The wander's levels: given, from the still data's Allan deviation, or typical;
    // 2b. those the still data cannot resolve estimated over the fit (walk_estimate.h).
    std::vector<const signal::StillNoise*> measured;
    const std::optional<signal::StillNoise> own =
        MeasureStillNoise(series, still, options.instability_time_s, fit.notes, options.run_jobs);
    if (own) measured.push_back(&*own);
    for (const signal::StillNoise& other : options.other_still_noise) measured.push_back(&other);
    WanderLevels levels =
        AssignWanderLevels(out.noise, measured, out.start, cal.has_gyro, series.duration_s(),
                           options, static_cast<int>(still.poses.size()));
    fit.notes.insert(fit.notes.end(), levels.notes.begin(), levels.notes.end());
    out.wander_bounds = levels.bounds;
    WalkEstimate wander =
        ResolveWander(series, cal.model, site, still, theta, levels, out.start, options);
    out.noise = wander.noise;
    fit.notes.insert(fit.notes.end(), wander.notes.begin(), wander.notes.end());
    fit.warnings.insert(fit.warnings.end(), wander.warnings.begin(), wander.warnings.end());
    out.implausible_walk = wander.implausible;
  }
  cal.noise = out.noise.Levels();

  // 1-3 for the board's other IMUs (board.h), each model checked against its own samples.
  std::vector<BoardImuInput> others =
      PrepareBoard(board, BoardModelsForSession(board, board_models, cal.model, site, fit.warnings),
                   series, still, site, options, fit);

  // 4. The problem; 5. the solve (the problem stays where Ceres points into its values).
  out.problem = std::make_unique<CalibrationProblem>(series, cal.model, site, std::move(still),
                                                     std::move(theta), out.noise, out.start,
                                                     options, std::move(others));
  out.solution = SolveWithGauge(*out.problem, options, fit);
  return out;
}

// The method, as docs/reference/model.md describes it: the still set, the noise model,
// starting values, the problem, the solve with a gauge for unobservable directions (stages
// 1-5, FitProblem), then the analysis of the solution with every unknown free, the
// covariance, the fit's residuals and chi^2, and what the data cannot determine.
CalibrationResult Calibrate(const ImuSeries& series, const std::vector<StillSegment>& segments,
                            const model::Model& model_in, const geo::Site& site,
                            const CalibrationOptions& options) {
  return CalibrateBoard(series, {}, segments, model_in, site, options);
}

CalibrationResult CalibrateBoard(const ImuSeries& series, const std::vector<BoardImu>& board,
                                 const std::vector<StillSegment>& segments,
                                 const model::Model& model_in, const geo::Site& site,
                                 const CalibrationOptions& options,
                                 const std::vector<model::Model>& board_models) {
  CalibrationResult result;
  FittedProblem fitted =
      FitProblem(series, segments, model_in, site, options, result, board, board_models);
  FinishCalibration(series, segments, options, fitted, result);
  // 9. How far the sigmas rest on wander levels the session could not measure.
  if (const std::optional<CalibrationOptions> at_bound = OptionsAtTheWanderBound(
          fitted.noise, fitted.wander_bounds, result.fit.still_segments, options)) {
    const CalibrationResult bound =
        CalibrateBoard(series, board, segments, model_in, site, *at_bound, board_models);
    if (const std::optional<std::string> w = SigmaRestsOnTheTypicalWander(result, bound)) {
      result.fit.warnings.push_back(Notice{"sigma_rests_on_wander", *w, {Option::kNoiseFrom}});
    }
  }
  return result;
}

void FinishCalibration(const ImuSeries& series, const std::vector<StillSegment>& segments,
                       const CalibrationOptions& options, FittedProblem& fitted,
                       CalibrationResult& result) {
  CalibrationProblem& problem = *fitted.problem;
  Solution& solution = fitted.solution;
  Calibration& cal = result.calibration;
  FitReport& fit = result.fit;
  if (!solution.analysed) {
    solution.analysed = AnalyseSolution(problem, *solution.all_free.problem, options);
  }
  const AnalysedSolution& at = *solution.analysed;
  const ObservabilityAnalysis& analysis = at.analysis;
  const UnknownColumns& columns = at.columns;
  cal.observability = analysis.summary;

  // 6. Parameters and their covariance.
  std::vector<Eigen::Index> column_of;
  cal.theta = problem.theta();
  cal.parameters = ReportParameters(cal.model, cal.theta, series, columns, analysis, column_of);
  ComputeCovariance(solution.fitted(), problem.ModelBlocks(), analysis, column_of, options, cal,
                    fit.warnings);
  ReportBoard(problem, solution.all_free, columns, analysis, column_of, cal);

  // 7. The fit: chi^2, degrees of freedom and the residuals.
  fit.chi2 = 2.0 * at.cost;
  fit.num_residuals = static_cast<int>(at.residuals.size());
  fit.dof = fit.num_residuals - analysis.summary.rank - analysis.summary.wander_states;
  fit.still_segments = static_cast<int>(problem.still().poses.size());
  fit.motion_segments = static_cast<int>(problem.still().motions.size());
  for (const MotionInterval& m : problem.still().not_turns) {
    fit.not_turns.push_back({m.from, m.from + 1, series.t_s[m.first], series.t_s[m.last],
                             options.max_motion_s, m.flown, m.gap, options.max_turn_gap_s});
  }
  problem.ReportResiduals(solution.all_free, fit);
  // Counted once: the advice, the one_pose gate and the JSON all say this number.
  fit.distinct_poses = CountDistinctPoses(series, fit.still, cal.noise);

  // 8. What the data cannot determine; diagnose's probe columns.
  AddAdvice(cal, problem.still(), options, fit);
  if (cal.model.has_probes()) {
    fit.probes = problem.ProbeColumns(problem.Build({}, true), columns);
  }
  if (options.check_linearity) {
    // The analysis's Jacobian is the fitted problem's when no parameter is held.
    const bool same = solution.gauge.empty();
    fit.linearity = CheckLinearity(problem, solution.fitted(), solution.gauge.parameters,
                                   kLinearityStepSigmas, same ? &at.jacobian : nullptr, at.cost,
                                   same ? at.eliminated.get() : nullptr, options.run_jobs);
  }
  // What says not to trust it (gates.h).
  fit.gates = CheckGates(series, segments, cal, options.log_motion, fit);
  if (!fitted.implausible_walk.empty()) {
    fit.gates.push_back(Gate{"implausible_walk", fitted.implausible_walk,
                             {Option::kEstimateWalk, Option::kAccelWalk, Option::kGyroWalk}});
  }
}

}  // namespace plumb::estimation

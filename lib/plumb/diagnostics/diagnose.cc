// plumb/diagnostics/diagnose.cc — see diagnose.h.
#include "plumb/diagnostics/diagnose.h"

#include <Eigen/SVD>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <iomanip>
#include <memory>
#include <sstream>

#include "plumb/core/error.h"
#include "plumb/estimation/calibrator.h"
#include "plumb/estimation/elimination.h"
#include "plumb/estimation/uncertainty.h"
#include "plumb/model/registry.h"
#include "plumb/signal/chi_square.h"
#include "plumb/signal/time_base.h"

namespace plumb::diagnostics {
namespace {

void Tell(const DiagnoseOptions& options, const std::string& stage);

/// Like with like: a refit is advised only when its chi^2/dof is below the user's fit's.
bool LowersTheUsersFit(const estimation::CalibrationResult& refit,
                       const estimation::CalibrationResult& user) {
  return refit.fit.dof > 0 && user.fit.dof > 0 && refit.fit.chi2_dof() < user.fit.chi2_dof();
}

bool TurnsAboveTheirNoise(const estimation::CalibrationResult& refit) {
  return estimation::VelocityFit(refit.fit).above_band();
}

struct CandidateSpec {
  std::string name;
  std::string option;
};

CandidateSpec ParseCandidate(const std::string& text) {
  const auto colon = text.find(':');
  return {text.substr(0, colon), colon == std::string::npos ? "" : text.substr(colon + 1)};
}

/// Why the data cannot carry this effect, or "" when it can.
std::string Unsupported(const model::EffectInfo& info, const ImuSeries& series,
                        const geo::Site& site, const model::Model& model) {
  if (info.linear_stage) return "part of the base model";
  if (info.sensor == model::Sensor::kGyro && !model.has_gyro()) return "needs a gyroscope";
  if (info.excitation.temperature && !series.has_temperature()) {
    return "needs a temperature column";
  }
  if (info.name == "earth_rate" && site.known) {
    return "in the base model: the site is known";
  }
  return "";
}

/// Factor from a parameter's SI unit to the unit it has in this fit: additive terms on
/// unscaled output (counts) are in output units (estimation reports "counts per m/s^2" for a
/// catalogue "rad/s per m/s^2"), so their typical size scales with the output's sensitivity,
/// the mean diagonal of the fitted F or E (output units per SI unit).
double OutputScale(const model::EffectInfo& info, std::size_t i, const ImuSeries& series,
                   const estimation::CalibrationResult& fit) {
  const bool accel = info.sensor == model::Sensor::kAccel;
  const std::string& out = accel ? series.acc_unit : series.gyr_unit;
  const std::string in = accel ? "m/s^2" : "rad/s";
  if (out == in || !info.ScalesWithOutput(static_cast<int>(i))) return 1.0;
  const Mat3 M = accel ? fit.calibration.AccelMatrix() : fit.calibration.GyroMatrix();
  return M.diagonal().cwiseAbs().mean();
}

/// The fit with the probe terms taken out (they are held at zero: the model's own fit).
estimation::CalibrationResult StripProbes(estimation::CalibrationResult fit,
                                          const model::Model& model) {
  const auto n = static_cast<Eigen::Index>(model.num_parameters());
  fit.calibration.parameters.resize(static_cast<std::size_t>(n));
  fit.calibration.covariance = Eigen::MatrixXd(fit.calibration.covariance.topLeftCorner(n, n));
  fit.calibration.theta.resize(static_cast<std::size_t>(model.num_terms()));
  model::Model own = model;
  own.t_ref_s = fit.calibration.model.t_ref_s;
  own.temp_ref_c = fit.calibration.model.temp_ref_c;
  fit.calibration.model = own;
  fit.fit.probes.reset();
  return fit;
}

/// The catalogue candidates asked for: options.candidates (the time base aside), or the whole
/// catalogue.
std::vector<CandidateSpec> WantedCandidates(const DiagnoseOptions& options) {
  std::vector<CandidateSpec> wanted;
  if (options.candidates.empty()) {
    for (const auto& name : model::Registry::Global().CatalogueNames()) {
      wanted.push_back({name, ""});
    }
  } else {
    for (const auto& text : options.candidates) {
      if (text != kTimeBaseCandidate && text != kWanderCandidate) {
        wanted.push_back(ParseCandidate(text));
      }
    }
  }
  return wanted;
}

/// Whether a candidate that is not a catalogue effect (the time base, the bias wander) is to
/// be tested: every candidate is when none is named.
bool Wanted(const DiagnoseOptions& options, const char* name) {
  return options.candidates.empty() ||
         std::find(options.candidates.begin(), options.candidates.end(), name) !=
             options.candidates.end();
}

/// A candidate that adds no parameter and is tested by its refit (the time base, the bias
/// wander): the refit's actual fall from the user's `fit` stands for LM, on `dof` degrees of
/// freedom (what the refit chose); evidence and significance as for a score test.
Candidate RefitCandidate(CandidateKind kind, const char* name,
                         estimation::CalibrationResult refit,
                         const estimation::CalibrationResult& fit, int dof, int observations,
                         double significance) {
  Candidate c;
  c.kind = kind;
  c.effect = name;
  c.refit = std::move(refit);
  c.refit_drop = fit.fit.chi2 - c.refit->fit.chi2;
  c.lm = *c.refit_drop;
  c.dof = dof;
  c.evidence = c.lm - dof * std::log(std::max(1.0, static_cast<double>(observations)));
  c.threshold = signal::ChiSquareQuantileExact(1.0 - significance, dof);
  c.significant = c.lm > c.threshold;
  return c;
}

/// The time-base candidate: the model refitted on the uniform clock fitted through the stamps,
/// when they are a host's arrival clock (else skipped, with why). `fit` is the user's.
std::optional<Candidate> TestTimeBase(const ImuSeries& series,
                                      const std::vector<StillSegment>& segments,
                                      const model::Model& model, const geo::Site& site,
                                      const DiagnoseOptions& options,
                                      const estimation::CalibrationResult& fit, int observations,
                                      std::vector<Skipped>& skipped) {
  const signal::TimeBase base = signal::AnalyseTimeBase(series.t_s);
  switch (base.kind) {
    case signal::ClockKind::kTooShort:
      skipped.push_back({kTimeBaseCandidate, "too few samples to judge the stamps"});
      return std::nullopt;
    case signal::ClockKind::kUniform:
      skipped.push_back({kTimeBaseCandidate, "the stamps are a uniform sample clock already"});
      return std::nullopt;
    case signal::ClockKind::kIrregular:
      skipped.push_back({kTimeBaseCandidate, "no uniform clock fits the stamps (irregular)"});
      return std::nullopt;
    case signal::ClockKind::kHostArrival:
      break;
  }
  Tell(options, "refit on the uniform clock");
  ImuSeries uniform = series;
  signal::ApplyUniformClock(base, uniform.t_s);
  // The choice of clock stands for one degree of freedom.
  Candidate c = RefitCandidate(
      CandidateKind::kTimeBase, kTimeBaseCandidate,
      estimation::Calibrate(uniform, segments, model, site, options.calibration), fit, 1,
      observations, options.significance);
  c.recommended = c.significant && LowersTheUsersFit(*c.refit, fit);
  return c;
}

/// Whether a level of the fit's wander was assumed rather than given or measured.
bool AnyLevelAssumed(const estimation::NoiseLevels& noise) {
  for (const auto* from : {&noise.from.walk_acc, &noise.from.walk_gyr,
                           &noise.from.instability_acc, &noise.from.instability_gyr}) {
    for (const estimation::LevelSource s : *from) {
      if (s == estimation::LevelSource::kTypical || s == estimation::LevelSource::kBounded) {
        return true;
      }
    }
  }
  return false;
}

/// Sensors whose wander the refit moved from the user's fit's levels.
int SensorsMoved(const estimation::NoiseLevels& user, const estimation::NoiseLevels& refit) {
  const bool acc = refit.walk_acc != user.walk_acc || refit.instability_acc != user.instability_acc;
  const bool gyr = refit.walk_gyr != user.walk_gyr || refit.instability_gyr != user.instability_gyr;
  return (acc ? 1 : 0) + (gyr ? 1 : 0);
}

/// The bias-wander candidate (file comment): the model refitted with the wander levels
/// estimated from the session, when the user's fit assumed them on a session with holds
/// enough (else skipped, with why). `fit` is the user's.
std::optional<Candidate> TestWander(const ImuSeries& series,
                                    const std::vector<StillSegment>& segments,
                                    const model::Model& model, const geo::Site& site,
                                    const DiagnoseOptions& options,
                                    const estimation::CalibrationResult& fit, int observations,
                                    std::vector<Skipped>& skipped) {
  const estimation::CalibrationOptions& calibration = options.calibration;
  auto skip = [&](const std::string& why) {
    skipped.push_back({kWanderCandidate, why});
    return std::nullopt;
  };
  if (!calibration.ModelsWander()) return skip("the bias is held constant");
  if (calibration.estimate_walk) return skip("the wander levels are estimated from the session already");
  if (!AnyLevelAssumed(fit.calibration.noise)) return skip("the wander levels are given or measured");
  if (fit.fit.still_segments < calibration.walk_min_poses) {
    return skip("fewer than " + std::to_string(calibration.walk_min_poses) +
                " still segments to compare");
  }
  Tell(options, "refit with the wander levels from the session");
  estimation::CalibrationOptions estimated = calibration;
  estimated.estimate_walk = true;
  estimation::CalibrationResult refit = estimation::Calibrate(series, segments, model, site, estimated);
  // Each sensor whose level moved stands for a degree of freedom.
  const int dof = SensorsMoved(fit.calibration.noise, refit.calibration.noise);
  if (dof == 0) return skip("the session's holds cannot estimate the levels (their wander "
                            "factors are absorbed by the fit)");
  Candidate c = RefitCandidate(CandidateKind::kWander, kWanderCandidate, std::move(refit), fit,
                               dof, observations, options.significance);
  // Advised only where the estimate reads a wander, not a misfit (file comment).
  c.recommended = c.significant && c.refit->fit.gates.empty() && LowersTheUsersFit(*c.refit, fit);
  return c;
}

/// The candidates to test, as probes of two fits: those seen by the model's own residuals,
/// and those that need the accelerometer during motion (velocity residuals), tested in a fit
/// that has them.
struct ProbePlan {
  model::Model probed;
  model::Model probed_motion;
  std::vector<CandidateSpec> tested;
  std::vector<bool> needs_motion;  ///< per tested candidate: probed in probed_motion
};

/// Adds each wanted candidate the data can carry as a probe; the others go to `skipped`.
ProbePlan PlanProbes(const std::vector<CandidateSpec>& wanted, const ImuSeries& series,
                     const geo::Site& site, const model::Model& model,
                     std::vector<Skipped>& skipped) {
  ProbePlan plan{model, model, {}, {}};
  for (const auto& c : wanted) {
    const auto effect = model::Registry::Global().Make(c.name, c.option);
    if (model.has_effect(c.name)) continue;
    const std::string why = Unsupported(effect->info(), series, site, model);
    if (!why.empty()) {
      skipped.push_back({c.name, why});
      continue;
    }
    const bool motion = effect->info().excitation.angular_acceleration;
    (motion ? plan.probed_motion : plan.probed).AddProbe(c.name, c.option);
    plan.tested.push_back(c);
    plan.needs_motion.push_back(motion);
  }
  return plan;
}

/// A scored candidate and its basis (the residual directions it explains; empty when it was
/// not tested).
struct Scored {
  Candidate candidate;
  Eigen::MatrixXd basis;
};

/// A candidate its probe fit could not test (no motion between the poses: nothing excites
/// it): not identifiable, every parameter unexcited.
Scored Unexcited(const CandidateSpec& c) {
  Candidate cand;
  cand.effect = c.name;
  cand.option = c.option;
  cand.identifiable = false;
  const auto effect = model::Registry::Global().Make(c.name, c.option);
  cand.num_parameters = effect->info().size();
  for (int i = 0; i < effect->info().size(); ++i) {
    Confounding n;
    n.parameter = effect->info().ParameterName(i);
    n.excited = false;
    n.typical = effect->info().parameters[static_cast<std::size_t>(i)].typical;
    n.unit = effect->info().parameters[static_cast<std::size_t>(i)].unit;
    cand.not_identifiable.push_back(n);
  }
  return {std::move(cand), Eigen::MatrixXd()};
}

/// The velocity residuals' chi^2 per residual in a probe fit when above 1, else 1.
double VelocityDispersion(const estimation::ProbeJacobian& p) {
  double ss = 0.0;
  int rows = 0;
  for (std::size_t row = 0; row < p.row_kind.size(); ++row) {
    if (p.row_kind[row] != estimation::ProbeJacobian::RowKind::kVelocity) continue;
    ss += p.r(static_cast<Eigen::Index>(row)) * p.r(static_cast<Eigen::Index>(row));
    ++rows;
  }
  return rows > 0 ? std::max(1.0, ss / rows) : 1.0;
}

/// The score test of one candidate in its probe fit `source`: its columns of the probe
/// Jacobian Z with their typical sizes (in the fit's units), LM (divided by the velocity
/// residuals' dispersion when tested with them), evidence and significance.
Scored Score(const CandidateSpec& c, const estimation::CalibrationResult& source,
             const estimation::JacobianRange& range, bool with_velocity, const ImuSeries& series,
             const DiagnoseOptions& options) {
  const estimation::ProbeJacobian& p = *source.fit.probes;
  // N counts the observations: the bias-wander factors are priors, not measurements.
  const auto observations = std::count_if(p.row_kind.begin(), p.row_kind.end(), [](auto kind) {
    return kind != estimation::ProbeJacobian::RowKind::kBiasWalk;
  });
  const double log_n = std::log(std::max(1.0, static_cast<double>(observations)));
  const double dispersion = with_velocity ? VelocityDispersion(p) : 1.0;
  const int term = source.calibration.model.FindTerm(c.name);
  std::vector<Eigen::Index> cols;
  for (std::size_t j = 0; j < p.probe_term.size(); ++j) {
    if (p.probe_term[j] == term) cols.push_back(static_cast<Eigen::Index>(j));
  }
  Eigen::MatrixXd Z(p.Z.rows(), static_cast<Eigen::Index>(cols.size()));
  std::vector<std::string> names, units;
  std::vector<double> typical;
  const auto& info = source.calibration.model.terms()[static_cast<std::size_t>(term)].effect->info();
  for (std::size_t k = 0; k < cols.size(); ++k) {
    Z.col(static_cast<Eigen::Index>(k)) = p.Z.col(cols[k]);
    names.push_back(p.probe_names[static_cast<std::size_t>(cols[k])]);
    const double scale = OutputScale(info, k, series, source);
    typical.push_back(info.parameters[k].typical * scale);
    units.push_back(scale == 1.0 ? info.parameters[k].unit : std::string());
  }
  const ScoreTestResult s = ScoreTest(p.r, range, Z, p.unknown_names, names, typical, options.score);
  Candidate cand;
  cand.effect = c.name;
  cand.option = c.option;
  cand.lm = s.lm / dispersion;
  cand.dispersion = dispersion;
  cand.dof = s.dof;
  cand.num_parameters = s.num_parameters;
  cand.identifiable = s.identifiable;
  cand.not_identifiable = s.not_identifiable;
  for (Confounding& n : cand.not_identifiable) {
    const auto at = std::find(names.begin(), names.end(), n.parameter);
    if (at != names.end()) n.unit = units[static_cast<std::size_t>(at - names.begin())];
  }
  cand.evidence = cand.lm - s.dof * log_n;
  cand.threshold = s.dof > 0 ? signal::ChiSquareQuantileExact(1.0 - options.significance, s.dof) : 0.0;
  cand.significant = s.identifiable && s.dof > 0 && cand.lm > cand.threshold;
  cand.with_velocity = with_velocity;
  return {std::move(cand), s.basis};
}

/// Scores the candidates of `plan` tested in one probe fit (`motion`: the one with velocity
/// residuals), `source`, into their slots of `scored` (plan order); all unexcited when
/// `source` is null or has no probe columns. Its Jacobian is factorised once for all of them.
void ScoreInFit(const ProbePlan& plan, bool motion, const estimation::CalibrationResult* source,
                const ImuSeries& series, const DiagnoseOptions& options,
                std::vector<Scored>& scored) {
  std::unique_ptr<estimation::JacobianRange> range;
  if (source != nullptr && source->fit.probes) {
    range = estimation::ProbeRange(*source->fit.probes, options.score.rank_tolerance);
  }
  for (std::size_t ci = 0; ci < plan.tested.size(); ++ci) {
    if (plan.needs_motion[ci] != motion) continue;
    scored[ci] = range ? Score(plan.tested[ci], *source, *range, motion, series, options)
                       : Unexcited(plan.tested[ci]);
  }
}

/// Candidates whose explained directions lie within another's: the smallest cosine of the
/// principal angles between the spans (`bases`, per candidate) is at least 0.999.
void MarkIndistinguishable(const std::vector<Eigen::MatrixXd>& bases,
                           std::vector<Candidate>& candidates) {
  for (std::size_t a = 0; a < candidates.size(); ++a) {
    for (std::size_t b = 0; b < candidates.size(); ++b) {
      if (a == b || bases[a].cols() == 0 || bases[b].cols() == 0) continue;
      if (bases[a].rows() != bases[b].rows()) continue;  // from the two probe fits
      const Eigen::MatrixXd cosines = bases[a].transpose() * bases[b];
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(cosines);
      const auto& sv = svd.singularValues();
      const bool within = sv.size() == bases[a].cols() && sv(sv.size() - 1) >= 0.999;
      if (within) candidates[a].indistinguishable_from.push_back(candidates[b].effect);
    }
  }
}

/// The ranking's order: identifiable before not, then best evidence first.
bool RanksBefore(const Candidate& a, const Candidate& b) {
  if (a.identifiable != b.identifiable) return a.identifiable;
  return a.evidence > b.evidence;
}

/// Best evidence first; the ones not identifiable last (a stable sort: ties keep their order).
void Rank(std::vector<Candidate>& candidates) {
  std::stable_sort(candidates.begin(), candidates.end(), RanksBefore);
}

/// Tells options.on_stage, when set, that `stage` begins.
void Tell(const DiagnoseOptions& options, const std::string& stage) {
  if (options.on_stage) options.on_stage(stage);
}

/// A refit of the model plus one candidate: its result, or the error it threw; neither when
/// it was not made.
struct Refit {
  std::optional<estimation::CalibrationResult> result;
  std::exception_ptr error;
  bool made() const { return result.has_value() || error != nullptr; }
};

/// The plan slot of a tested candidate.
std::size_t SlotOf(const ProbePlan& plan, const Candidate& cand) {
  const auto at = std::find_if(plan.tested.begin(), plan.tested.end(), [&](const CandidateSpec& c) {
    return c.name == cand.effect && c.option == cand.option;
  });
  return static_cast<std::size_t>(at - plan.tested.begin());
}

Refit RefitWith(const ImuSeries& series, const std::vector<StillSegment>& segments,
                const model::Model& model, const geo::Site& site, const DiagnoseOptions& options,
                const Candidate& cand) {
  Refit out;
  try {
    model::Model with = model;
    with.Add(cand.effect, cand.option);
    // As the user's model SPEC+EFFECT fits: velocity residuals on when the effect needs
    // them, otherwise as in the user's fit (unset: when its model needs them).
    estimation::CalibrationOptions refit_options = options.calibration;
    if (cand.with_velocity) refit_options.accel_in_motion = true;
    out.result = estimation::Calibrate(series, segments, with, site, refit_options);
  } catch (...) {
    out.error = std::current_exception();
  }
  return out;
}

/// The candidates of one probe fit (`motion`: the one with velocity residuals) that the
/// ranking of all candidates may choose to refit, in plan slots: its significant ones in
/// ranking order, at most options.confirm. Whatever the other fit's candidates, those of this
/// one that are chosen are the start of this list (the ranking keeps their order).
std::vector<std::size_t> RefitOrder(const ProbePlan& plan, bool motion,
                                    const std::vector<Scored>& scored, int confirm) {
  std::vector<std::size_t> order;
  for (std::size_t ci = 0; ci < plan.tested.size(); ++ci) {
    if (plan.needs_motion[ci] == motion && scored[ci].candidate.significant) order.push_back(ci);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return RanksBefore(scored[a].candidate, scored[b].candidate);
  });
  if (static_cast<int>(order.size()) > confirm) order.resize(static_cast<std::size_t>(confirm));
  return order;
}

/// Refits the model plus each of the best `options.confirm` significant candidates: the
/// actual fall of chi^2 from its probe fit (`fit` or, with velocity residuals, `fit_motion`).
/// `early` holds, per plan slot, the refits already made while the probe fits ran (kept only
/// for the candidates chosen here). The others are independent: options.run_jobs may run them
/// at once. A refit's error is thrown after all have ended (the first candidate's, in ranking
/// order).
void ConfirmBest(const ImuSeries& series, const std::vector<StillSegment>& segments,
                 const model::Model& model, const geo::Site& site, const DiagnoseOptions& options,
                 const ProbePlan& plan, std::vector<Refit>& early,
                 const estimation::CalibrationResult& fit,
                 const std::optional<estimation::CalibrationResult>& fit_motion,
                 std::vector<Candidate>& candidates) {
  std::vector<Candidate*> chosen;
  int confirmed = 0;  // the time base is confirmed already (its refit is its test)
  for (auto& cand : candidates) {
    if (confirmed >= options.confirm) break;
    if (!cand.significant) continue;
    ++confirmed;
    if (!cand.refit) chosen.push_back(&cand);
  }
  if (chosen.empty()) return;
  std::vector<Refit> refits(chosen.size());
  std::vector<std::size_t> pending;  // chosen ones not refitted yet
  std::string specs;
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    const Candidate& cand = *chosen[k];
    Refit& made_early = early[SlotOf(plan, cand)];
    if (made_early.made()) {
      refits[k] = std::move(made_early);
      continue;
    }
    pending.push_back(k);
    specs += (specs.empty() ? "" : ", ") + SpecWith(model, cand.effect, cand.option);
  }
  const auto refit = [&](int job) {
    const std::size_t k = pending[static_cast<std::size_t>(job)];
    refits[k] = RefitWith(series, segments, model, site, options, *chosen[k]);
  };
  if (!pending.empty()) Tell(options, "refit with " + specs);
  // A lone refit is run directly, so that its own work may still use the threads.
  if (pending.size() == 1) {
    refit(0);
  } else {
    RunJobs(options.run_jobs, static_cast<int>(pending.size()), refit);
  }
  for (const Refit& r : refits) {
    if (r.error) std::rethrow_exception(r.error);
  }
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    Candidate& cand = *chosen[k];
    const double before = cand.with_velocity ? fit_motion->fit.chi2 : fit.fit.chi2;
    cand.refit_drop = before - refits[k].result->fit.chi2;
    cand.refit = std::move(refits[k].result);
    // Like with like: advised only when the user's own fit gets better, and, for an effect
    // seen only in the turns, when its refit brings their velocity residuals to their noise
    // (else the turns carry more than the effect explains: estimation/turn_noise.h).
    cand.recommended = LowersTheUsersFit(*cand.refit, fit) &&
                       !(cand.with_velocity && TurnsAboveTheirNoise(*cand.refit));
  }
}

/// The probe fits and, while the one with velocity residuals runs, refits of the other's best
/// candidates (see Diagnose).
struct ProbeFits {
  estimation::CalibrationResult fit;                      ///< own residuals
  std::optional<estimation::CalibrationResult> fit_motion;  ///< with velocity residuals
  std::vector<Scored> scored;                             ///< per plan slot
  std::vector<Refit> early;                               ///< per plan slot
};

/// Fits the model with the probes of `plan`, once with its own residuals (job 0) and, when
/// some candidate needs them, once with velocity residuals (job 1); the two are independent
/// and run through options.run_jobs (each fit then on one thread). Job 0 then scores its
/// candidates and, while job 1 is still running on another thread, refits its best ones one
/// at a time (RefitOrder): the core would otherwise wait. Which of them it refits depends on
/// timing, the diagnosis does not (ConfirmBest refits what is missing and drops the rest). A
/// lone fit is run directly, so that its own work may still use options.calibration.run_jobs.
/// The second fit is kept only when the first has motion intervals; the first's error first.
ProbeFits FitProbes(const ImuSeries& series, const std::vector<StillSegment>& segments,
                    const model::Model& model, const geo::Site& site, const ProbePlan& plan,
                    const DiagnoseOptions& options) {
  // The user's fit as `calibrate` makes it: its probes need no velocity residuals, so these
  // are on only when asked for or when the model itself needs them.
  const estimation::CalibrationOptions& own = options.calibration;
  estimation::CalibrationOptions with = options.calibration;
  with.accel_in_motion = true;
  with.check_linearity = false;  // its columns score candidates; its covariance is not shown
  const bool try_motion = plan.probed_motion.has_probes();
  Tell(options, "probe fit of " + plan.probed.spec() +
                    (try_motion ? " and with velocity residuals" : ""));
  ProbeFits out;
  out.scored.resize(plan.tested.size());
  out.early.resize(plan.tested.size());
  enum MotionFit { kNotStarted, kRunning, kDone };
  std::atomic<int> motion_fit{kNotStarted};
  std::exception_ptr errors[2];
  const auto own_fit = [&] {
    out.fit = estimation::Calibrate(series, segments, plan.probed, site, own);
    ScoreInFit(plan, false, &out.fit, series, options, out.scored);
    for (std::size_t ci : RefitOrder(plan, false, out.scored, options.confirm)) {
      if (motion_fit.load() != kRunning) break;
      const Candidate& cand = out.scored[ci].candidate;
      Tell(options, "refit with " + SpecWith(model, cand.effect, cand.option) +
                        " and the probe fit with velocity residuals");
      out.early[ci] = RefitWith(series, segments, model, site, options, cand);
    }
  };
  RunJobs(try_motion ? options.run_jobs : JobRunner{}, try_motion ? 2 : 1, [&](int job) {
    try {
      if (job == 0) {
        own_fit();
      } else {
        motion_fit.store(kRunning);
        out.fit_motion = estimation::Calibrate(series, segments, plan.probed_motion, site, with);
      }
    } catch (...) {
      errors[job] = std::current_exception();
    }
    if (job == 1) motion_fit.store(kDone);
  });
  if (errors[0]) std::rethrow_exception(errors[0]);
  if (out.fit.fit.motion_segments == 0) {
    out.fit_motion.reset();
  } else if (errors[1]) {
    std::rethrow_exception(errors[1]);
  }
  return out;
}

}  // namespace

std::string SpecWith(const model::Model& model, const std::string& effect,
                     const std::string& option) {
  return model.spec() + "+" + effect + (option.empty() ? "" : ":" + option);
}

const Candidate* Recommended(const Diagnosis& d) {
  for (const Candidate& c : d.candidates) {
    if (!c.recommended) continue;
    // The wander reads every disagreement between holds as wander: an effect whose refit
    // explains the session better comes first.
    if (c.kind == CandidateKind::kWander) {
      const bool better = std::any_of(d.candidates.begin(), d.candidates.end(), [&](const Candidate& o) {
        return o.recommended && &o != &c && o.refit->fit.chi2_dof() < c.refit->fit.chi2_dof();
      });
      if (better) continue;
    }
    return &c;
  }
  return nullptr;
}

const Candidate* BestRefitted(const Diagnosis& d) {
  for (const Candidate& c : d.candidates) {
    // Confirmed: significant and refitted (the time base's and the wander's refit is their
    // test, made whether significant or not).
    if (c.refit && c.significant) return &c;
  }
  return nullptr;
}

bool UniformClockNext(const Diagnosis& d) {
  const Candidate* c = Recommended(d);
  return c != nullptr && c->kind == CandidateKind::kTimeBase;
}

bool EstimateWanderNext(const Diagnosis& d) {
  const Candidate* c = Recommended(d);
  return c != nullptr && c->kind == CandidateKind::kWander;
}

std::optional<std::string> NextModelSpec(const Diagnosis& d) {
  const Candidate* c = Recommended(d);
  if (c == nullptr) return std::nullopt;
  if (c->kind != CandidateKind::kEffect) return d.fit.calibration.model.spec();
  return SpecWith(d.fit.calibration.model, c->effect, c->option);
}

Diagnosis Diagnose(const ImuSeries& series, const std::vector<StillSegment>& segments,
                   const model::Model& model, const geo::Site& site,
                   const DiagnoseOptions& options) {
  if (!(options.significance > 0.0 && options.significance < 0.5)) {
    throw Error("diagnose: significance must be in (0, 0.5)");
  }
  Diagnosis d;
  d.significance = options.significance;

  // 1. Probe fits: the model with the candidates as probes (held at zero), once with its own
  // residuals and, for the candidates that need them, once with velocity residuals; the first
  // fit's candidates scored (and some refitted) while the second runs.
  const std::vector<CandidateSpec> wanted = WantedCandidates(options);
  const ProbePlan plan = PlanProbes(wanted, series, site, model, d.skipped);
  ProbeFits probes = FitProbes(series, segments, model, site, plan, options);
  const estimation::CalibrationResult& fit = probes.fit;
  const std::optional<estimation::CalibrationResult>& fit_motion = probes.fit_motion;
  d.fit = StripProbes(fit, model);
  if (fit_motion) d.fit_with_velocity = StripProbes(*fit_motion, model);
  if (!fit.fit.probes && !fit_motion) return d;
  d.num_residuals = fit.fit.probes
                        ? static_cast<int>(std::count_if(
                              fit.fit.probes->row_kind.begin(), fit.fit.probes->row_kind.end(),
                              [](auto kind) {
                                return kind != estimation::ProbeJacobian::RowKind::kBiasWalk;
                              }))
                        : 0;

  // 2. Score the other candidates in the fit with velocity residuals.
  ScoreInFit(plan, true, fit_motion ? &*fit_motion : nullptr, series, options, probes.scored);
  std::vector<Eigen::MatrixXd> bases;
  for (Scored& s : probes.scored) {
    d.candidates.push_back(std::move(s.candidate));
    bases.push_back(std::move(s.basis));
  }

  // 3. The time base and the bias wander, then rank: which candidates this data cannot tell
  // apart, then by evidence.
  MarkIndistinguishable(bases, d.candidates);
  if (Wanted(options, kTimeBaseCandidate)) {
    if (auto c = TestTimeBase(series, segments, model, site, options, d.fit, d.num_residuals,
                              d.skipped)) {
      d.candidates.push_back(std::move(*c));
    }
  }
  if (Wanted(options, kWanderCandidate)) {
    if (auto c = TestWander(series, segments, model, site, options, d.fit, d.num_residuals,
                            d.skipped)) {
      d.candidates.push_back(std::move(*c));
    }
  }
  Rank(d.candidates);

  // 4. Confirm the best significant candidates by refitting.
  ConfirmBest(series, segments, model, site, options, plan, probes.early, d.fit, fit_motion,
              d.candidates);
  return d;
}

}  // namespace plumb::diagnostics

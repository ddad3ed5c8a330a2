// plumb/diagnostics/diagnose.h — which catalogue effects is the model missing (SPEC section 5)?
//
// 1. Fit the model once with every candidate effect added as a probe (model::Model::AddProbe:
//    held at zero, so the fit is the model's own), and take the whitened residuals r, the
//    Jacobian J over the fit's free unknowns and Z over each candidate's parameters.
// 2. For each candidate, the score test (score_test.h): LM, the predicted fall of chi^2, with q
//    degrees of freedom; evidence = LM - q ln N (N residuals), a BIC-like penalty, ranks them;
//    significant when LM exceeds the chi^2(q) quantile at 1 - significance and the candidate is
//    identifiable. Not identifiable (confounded with the fit's parameters, or not excited by
//    the data) is said as such, never "absent".
// 3. Confirm the best significant ones by refitting the model plus that effect: the actual fall
//    of chi^2, and the new parameters with their sigma.
// 4. Advise like with like: a confirmed candidate is recommended only when its refit, made as
//    the user would make it (the model SPEC+EFFECT, velocity residuals included when the effect
//    needs them), has a lower chi^2/dof than the user's own fit (Diagnosis::fit). A candidate
//    judged in the fit with velocity residuals (lever arms, time offset) is scored against that
//    fit (Diagnosis::fit_with_velocity, shown beside the user's), but advised against the
//    user's: where those residuals are not modelled to the noise (hand-held turns), following
//    it would make the user's fit worse, and it is not advised.
//
// Candidates: every registered effect that is not in the model and not part of the base, with
// its default option, when the data can carry it (temperature effects need a temperature
// column; gyroscope effects a gyroscope; earth_rate only without a site). And the time base
// (`time_base`, CandidateKind::kTimeBase): when the stamps are a host's arrival clock
// (signal/time_base.h), the same model refitted on the uniform clock fitted through them. It
// adds no parameter, so it has no score test: its LM is the refit's actual fall of chi^2, tested
// as one degree of freedom (the choice of clock), and it is advised by the same rule.
// And the bias wander (`bias_wander`, CandidateKind::kWander): when the fit's wander levels
// were assumed (the typical sensor's, or the still data's bound) on a session with holds
// enough to estimate them, the same model refitted with the levels estimated from the session
// (estimation/walk_estimate.h, CalibrationOptions::estimate_walk). A sensor that wanders more than typical
// leaves a misfit between its holds that the score tests would otherwise pin on some catalogue
// effect (a simulated sensor at 5 times the typical wander: g-sensitivity "advised", chi2/dof
// 16.2 -> 12.9; the wander's refit: 0.85). Its LM is the refit's fall, one degree of freedom
// per sensor whose level it moved. The estimate reads any misfit between holds as wander, so
// it is advised only when its refit also passes every gate: a wander read more than 10 times
// the typical one (implausible_walk) is an effect the catalogue lacks, not wander.
//
// Example:
//   Diagnosis d = Diagnose(series, segments, model::Model::Parse("base"), site, {});
//   std::cout << report::DiagnosisText(d);   // plumb/report/diagnosis_text.h
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/jobs.h"
#include "plumb/core/segment.h"
#include "plumb/diagnostics/score_test.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/result.h"
#include "plumb/geo/site.h"
#include "plumb/model/model.h"

namespace plumb::diagnostics {

struct DiagnoseOptions {
  /// Level of the score test: the chance that a candidate which is not missing is called
  /// significant, in (0, 0.5).
  double significance = 0.01;
  /// How many of the best significant candidates to confirm by refitting, >= 0.
  int confirm = 3;
  /// Candidate effects ("name" or "name:option", kTimeBaseCandidate for the time base,
  /// kWanderCandidate for the bias wander); empty: the whole catalogue, the time base and the
  /// bias wander.
  std::vector<std::string> candidates;
  /// Options of every fit (the probe fit and the refits).
  estimation::CalibrationOptions calibration;
  ScoreTestOptions score;
  /// Told what Diagnose starts next ("probe fit", "refit with base+EFFECT (1 of 3)"), for a
  /// command's progress display; empty: nobody is told. The library itself never prints.
  /// Called from the thread of the job that starts the stage.
  std::function<void(const std::string& stage)> on_stage;
  /// Runs job(0), ..., job(count - 1): independent fits (the two probe fits, own residuals and
  /// with velocity residuals, then the refits), each writing only its own
  /// result, so the diagnosis is the same bit for bit whatever the order. Empty: one after
  /// another. A command may run them at once (plumb's does, on OpenMP); the library starts
  /// no thread itself. The jobs throw nothing (Diagnose keeps their errors). When the two
  /// probe fits run at once, the first, once done, refits its own best candidates while the
  /// second still runs (those the ranking may choose; how many depends on timing, the
  /// diagnosis does not).
  JobRunner run_jobs;
};

/// What a candidate changes: the model (a catalogue effect added), the time base (the
/// samples' times from the uniform clock fitted through their stamps) or the bias wander's
/// levels (estimated from the session).
enum class CandidateKind { kEffect, kTimeBase, kWander };

/// The name of the time-base candidate.
inline constexpr const char* kTimeBaseCandidate = "time_base";
/// The name of the bias-wander candidate.
inline constexpr const char* kWanderCandidate = "bias_wander";

/// One candidate effect.
struct Candidate {
  CandidateKind kind = CandidateKind::kEffect;
  std::string effect;   ///< catalogue name, e.g. "gyro_g_sensitivity"
  std::string option;   ///< the option it was tested with ("" = default)
  double lm = 0.0;      ///< score statistic: predicted fall of chi^2
  int dof = 0;          ///< q, identifiable directions
  int num_parameters = 0;
  double evidence = 0.0;   ///< lm - dof ln(N); the ranking
  double threshold = 0.0;  ///< chi^2(dof) quantile at 1 - significance
  bool significant = false;
  bool identifiable = true;
  std::vector<Confounding> not_identifiable;  ///< parameters the data cannot separate
  /// Other candidates that this data cannot tell from this one: the residual directions this
  /// one explains lie (cosine >= 0.999) within theirs, e.g. a temperature term and a drift
  /// when the temperature rose steadily.
  std::vector<std::string> indistinguishable_from;
  /// Tested in the fit with velocity residuals (the accelerometer during motion: lever arms,
  /// time offset), whose chi^2 is then the "before" of its refit.
  bool with_velocity = false;
  /// For those: the velocity residuals' own chi^2 per residual in that fit, when above 1 (the
  /// accelerometer during motion is then not modelled to its noise: hand-held vibration,
  /// sampling jitter, clipping); lm and evidence are divided by it (a quasi-likelihood score
  /// test), so such misfit is not taken for a lever arm or a time offset. 1 otherwise.
  double dispersion = 1.0;
  /// Refit with the effect added (only for confirmed candidates).
  std::optional<double> refit_drop;  ///< actual fall of chi^2 from the fit it was scored in
  std::optional<estimation::CalibrationResult> refit;
  /// Confirmed, and its refit's chi^2/dof is below the user's fit's (Diagnosis::fit): adding
  /// it makes the user's own fit better. Only recommended candidates are advised.
  bool recommended = false;
};

/// An effect that was not tested, and why.
struct Skipped {
  std::string effect;
  std::string reason;  ///< e.g. "needs a temperature column"
};

struct Diagnosis {
  estimation::CalibrationResult fit;    ///< the model's own fit (probes removed)
  /// The model's fit with velocity residuals (the accelerometer during motion), when some
  /// candidate needed them: the "before" of those candidates' refits.
  std::optional<estimation::CalibrationResult> fit_with_velocity;
  std::vector<Candidate> candidates;    ///< best evidence first; not identifiable ones last
  std::vector<Skipped> skipped;
  double significance = 0.01;
  int num_residuals = 0;                ///< N of the evidence penalty
};

/// Runs the diagnosis. Throws what estimation::Calibrate throws, and plumb::Error for an
/// unknown candidate name.
Diagnosis Diagnose(const ImuSeries& series, const std::vector<StillSegment>& segments,
                   const model::Model& model, const geo::Site& site,
                   const DiagnoseOptions& options = {});

/// The spec of `model` plus one effect, e.g. "base+gyro_g_sensitivity".
std::string SpecWith(const model::Model& model, const std::string& effect,
                     const std::string& option);

/// The model to fit next: the spec of the diagnosed model plus its best recommended candidate
/// (the model as it is when that is the time base: see UniformClockNext)
/// (the first recommended one in the ranking: confirmed by a refit whose chi^2/dof is below
/// the user's fit's), or nullopt when none is. What `plumb diagnose` suggests and `plumb
/// report` shows as the next command.
std::optional<std::string> NextModelSpec(const Diagnosis& diagnosis);

/// The candidate NextModelSpec advises, or null: the first recommended one in the ranking,
/// passing over the bias wander when another recommended candidate's refit has a lower
/// chi^2/dof (the wander can absorb any misfit between holds; an effect that explains them
/// better comes first).
const Candidate* Recommended(const Diagnosis& diagnosis);

/// Whether the advised next fit is on the uniform clock (the time base is recommended).
bool UniformClockNext(const Diagnosis& diagnosis);

/// Whether the advised next fit estimates the wander levels (the bias wander is recommended).
bool EstimateWanderNext(const Diagnosis& diagnosis);

/// The best confirmed candidate (the first significant refitted one in the ranking),
/// recommended or not; null when none was. What the before/after comparison shows.
const Candidate* BestRefitted(const Diagnosis& diagnosis);

}  // namespace plumb::diagnostics

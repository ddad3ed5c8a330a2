// plumb/report/diagnosis_json.h — the JSON document that `plumb diagnose --json` writes (SPEC
// section 6) and the per-sample residual CSV of `--residuals`; `plumb report` writes the same
// two files (diagnose.json, residuals.csv).
//
// Every number is SI (series units for residuals, rad for motion); non-finite values are null.
// Top-level keys of DiagnosisJson():
//   model, fit {... as calibrate's ...},
//   fit_with_velocity {... as fit ...} or null (where the with_velocity candidates are scored),
//   recommendation: the model spec to fit next (diagnostics::NextModelSpec) or null,
//   recommendation_options: what else that fit takes (["--clock", "uniform"] or []),
//   significance, num_residuals,
//   candidates [{kind ("effect" | "time_base"), effect, option, lm, dof, parameters, evidence, threshold, significant,
//                predicted_drop, refit_drop, identifiable, with_velocity, recommended, dispersion,
//                not_identifiable [...], indistinguishable_from [...], refit {...}}]
//                                                   best evidence first (Diagnosis order)
//   skipped [{effect, reason}],
//   compare {still [...], motion [...], worst [...], signatures [...], p_threshold, allan [...]}
//   site {...}, warnings [...], gates [{name, message}] (the diagnosed fit's)
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "plumb/diagnostics/diagnose.h"
#include "plumb/diagnostics/residual_analysis.h"

namespace plumb::report {

/// One candidate of the ranking, with its refit when it was confirmed.
nlohmann::json ToJson(const diagnostics::Candidate& candidate);

/// The comparison of the model with the measurements (the "compare" key).
nlohmann::json ToJson(const diagnostics::ResidualAnalysis& analysis);

/// The whole `diagnose --json` document (see the file comment).
nlohmann::json DiagnosisJson(const diagnostics::Diagnosis& diagnosis,
                             const diagnostics::ResidualAnalysis& analysis);

/// The per-sample still residuals as CSV: header time_s,segment,acc_res_x..z,gyr_res_x..z,
/// acc_norm_x..z,gyr_norm_x..z (residual = measured - predicted in the series' units; norm =
/// residual / the fit's per-sample noise, dimensionless), one row per sample, 9 digits.
std::string ResidualsCsv(const diagnostics::SampleResiduals& samples);

}  // namespace plumb::report

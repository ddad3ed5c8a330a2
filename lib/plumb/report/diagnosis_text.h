// plumb/report/diagnosis_text.h — what `plumb diagnose` prints on a terminal (the library
// formats; only the command prints): where the model fails and which effect it misses.
#pragma once

#include <cstddef>
#include <string>

#include "plumb/diagnostics/diagnose.h"
#include "plumb/diagnostics/residual_analysis.h"

namespace plumb::report {

/// The candidates of a diagnosis, a summary a person reads in ten seconds: the user's fit (and,
/// beside it, the fit with velocity residuals where candidates marked * are scored), the ranked
/// identifiable candidates with LM, evidence, refit drop and the refit's chi2/dof, the ones
/// this data cannot judge and why, and AdviceText.
std::string DiagnosisText(const diagnostics::Diagnosis& diagnosis);

/// What to do next: the significant candidates ranked above the recommended one that are not
/// advised, each with its refit's chi2/dof against the user's fit's; then the recommended
/// candidate's refit command (diagnostics::NextModelSpec), or why nothing is advised.
std::string AdviceText(const diagnostics::Diagnosis& diagnosis);

/// Where the model fails: the worst ranges, the significant signatures (strongest first, at
/// most `max_signatures`) and the Allan ratios above 3.
std::string ResidualAnalysisText(const diagnostics::ResidualAnalysis& analysis,
                                 std::size_t max_signatures = 6);

}  // namespace plumb::report

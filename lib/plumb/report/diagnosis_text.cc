#include "plumb/report/diagnosis_text.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <vector>

#include "plumb/core/number_text.h"
#include "plumb/estimation/uncertainty.h"

namespace plumb::report {
namespace {


}  // namespace

std::string AdviceText(const diagnostics::Diagnosis& d) {
  using diagnostics::Candidate;
  std::ostringstream out;
  const double user = d.fit.fit.chi2_dof();
  const Candidate* advised = diagnostics::Recommended(d);
  int significant = 0, unconfirmed = 0;
  for (const Candidate& c : d.candidates) {
    if (&c == advised) break;
    if (!c.significant) continue;
    ++significant;
    const std::string name = c.effect + (c.option.empty() ? "" : ":" + c.option);
    if (!c.refit) {
      ++unconfirmed;
      continue;
    }
    if (c.kind == diagnostics::CandidateKind::kWander && c.recommended && advised != nullptr) {
      out << "not advised yet: " << name << " (its refit: chi2/dof " << FixedText(user, 3) << " -> "
          << FixedText(c.refit->fit.chi2_dof(), 3) << "): " << advised->effect
          << "'s refit explains the holds better (" << FixedText(advised->refit->fit.chi2_dof(), 3)
          << "); the wander would absorb what an effect explains: add the effect, then "
             "diagnose again\n";
      continue;
    }
    if (c.kind == diagnostics::CandidateKind::kWander && !c.refit->fit.gates.empty()) {
      const std::string& gate = c.refit->fit.gates.front().name;
      out << "not advised: " << name << " is significant, but its refit fails the gate " << gate
          << " (chi2/dof " << FixedText(user, 3) << " -> " << FixedText(c.refit->fit.chi2_dof(), 3)
          << "): "
          << (gate == "implausible_walk"
                  ? "the holds disagree by more than any MEMS sensor wanders, so what they show "
                    "is a misfit, not wander"
                  : "that fit is not to be trusted as it stands")
          << "\n";
      continue;
    }
    const estimation::TurnVelocityFit turns = estimation::VelocityFit(c.refit->fit);
    if (c.with_velocity && turns.above_band() && c.refit->fit.chi2_dof() < user) {
      out << "not advised: " << name << " is significant and its refit lowers your fit's chi2/dof ("
          << FixedText(user, 3) << " -> " << FixedText(c.refit->fit.chi2_dof(), 3)
          << "), but leaves the turns' velocity residuals at chi2 " << FixedText(turns.per_residual(), 2)
          << " per residual, above their band (" << FixedText(estimation::Chi2BandUpper(turns.residuals), 2)
          << "): the accelerometer during the turns carries more than this effect explains\n";
      continue;
    }
    out << "not advised: " << name << " is significant, but the refit with it has chi2/dof "
        << FixedText(c.refit->fit.chi2_dof(), 3) << ", not below your fit's " << FixedText(user, 3);
    if (c.refit->fit.velocity_segments > d.fit.fit.velocity_segments) {
      out << " (the refit adds the velocity residuals of the turns, which this session does not"
             " fit to their noise)";
    }
    out << "\n";
  }
  if (advised != nullptr && advised->kind == diagnostics::CandidateKind::kTimeBase) {
    out << "best: " << advised->effect << " (its refit: chi2/dof " << FixedText(user, 3) << " -> "
        << FixedText(advised->refit->fit.chi2_dof(), 3)
        << ": the stamps are a host's arrival clock) -> refit with --clock uniform\n";
  } else if (advised != nullptr && advised->kind == diagnostics::CandidateKind::kWander) {
    out << "best: " << advised->effect << " (its refit: chi2/dof " << FixedText(user, 3) << " -> "
        << FixedText(advised->refit->fit.chi2_dof(), 3)
        << ": the holds show the bias wandering more than the levels your fit assumed) -> refit "
           "with --estimate-rw\n";
  } else if (advised != nullptr) {
    out << "best: " << advised->effect << (advised->option.empty() ? "" : ":" + advised->option)
        << " (its refit: chi2/dof " << FixedText(user, 3) << " -> "
        << FixedText(advised->refit->fit.chi2_dof(), 3) << ") -> refit with --model "
        << diagnostics::NextModelSpec(d).value_or("") << "\n";
  } else if (significant == 0) {
    out << "no candidate is significant: nothing in the catalogue is missing at this level\n";
  } else if (unconfirmed > 0) {
    out << "nothing advised: " << unconfirmed << " significant candidate"
        << (unconfirmed > 1 ? "s were" : " was")
        << " not refitted (raise --confirm to check whether it lowers your fit's chi2/dof)\n";
  } else {
    out << "nothing advised: no significant candidate lowers your fit's chi2/dof\n";
  }
  return out.str();
}

std::string DiagnosisText(const diagnostics::Diagnosis& d) {
  using diagnostics::Confounding;
  using diagnostics::Candidate;
  std::ostringstream out;
  const auto& f = d.fit.fit;
  out << "model " << d.fit.calibration.model.spec() << ": chi2 " << FixedText(f.chi2, 1) << " on " << f.dof
      << " dof, chi2/dof " << FixedText(f.chi2_dof(), 3) << "\n";
  if (d.fit_with_velocity && d.fit_with_velocity->fit.velocity_segments > f.velocity_segments) {
    // Like with like: the candidates that need velocity residuals are scored in this fit, so
    // it stands beside the user's.
    const auto& v = d.fit_with_velocity->fit;
    out << "  with velocity residuals (the accelerometer during the turns), where the candidates"
           " marked * are scored: chi2 "
        << FixedText(v.chi2, 1) << " on " << v.dof << " dof, chi2/dof " << FixedText(v.chi2_dof(), 3)
        << "\n";
  }
  out << "candidates (score test at the current fit; significant at " << d.significance
      << "; evidence = LM - q ln N, N = " << d.num_residuals << "):\n";
  out << "  " << std::left << std::setw(26) << "effect" << std::right << std::setw(11) << "LM"
      << std::setw(5) << "q" << std::setw(11) << "evidence" << std::setw(13) << "significant"
      << std::setw(13) << "refit drop" << std::setw(16) << "chi2/dof after" << "\n";
  for (const auto& c : d.candidates) {
    if (!c.identifiable) continue;
    const std::string name =
        c.effect + (c.option.empty() ? "" : ":" + c.option) + (c.with_velocity ? " *" : "");
    out << "  " << std::left << std::setw(26) << name << std::right << std::setw(11)
        << FixedText(c.lm, 1) << std::setw(5) << c.dof << std::setw(11) << FixedText(c.evidence, 1)
        << std::setw(13) << (c.significant ? "yes" : "no") << std::setw(13)
        << (c.refit_drop ? FixedText(*c.refit_drop, 1) : std::string("-")) << std::setw(16)
        << (c.refit ? FixedText(c.refit->fit.chi2_dof(), 3) : std::string("-"));
    for (const auto& other : c.indistinguishable_from) out << "  (same as " << other << " here)";
    if (c.kind == diagnostics::CandidateKind::kTimeBase) {
      out << "  (the times from the uniform clock fitted through the stamps; LM is the refit's"
             " fall)";
    }
    if (c.kind == diagnostics::CandidateKind::kWander) {
      out << "  (the wander levels estimated from the session; LM is the refit's fall)";
    }
    if (c.dispersion > 1.0) {
      out << "  (LM / " << std::setprecision(3) << c.dispersion
          << ": the velocity residuals' misfit)";
    }
    out << "\n";
  }
  bool header = false;
  for (const auto& c : d.candidates) {
    if (c.identifiable) continue;
    if (!header) out << "not identifiable from this data (cannot be judged here; not absent):\n";
    header = true;
    out << "  " << c.effect << ": ";
    std::vector<std::string> unexcited, confounders, weak;
    std::vector<const Confounding*> weak_columns;
    for (const auto& n : c.not_identifiable) {
      if (!n.excited) unexcited.push_back(n.parameter);
      if (n.too_weak) weak_columns.push_back(&n);
      for (const auto& k : n.confounders) {
        if (std::find(confounders.begin(), confounders.end(), k) == confounders.end()) {
          confounders.push_back(k);
        }
      }
    }
    if (weak_columns.size() <= 2) {
      for (const Confounding* n : weak_columns) {
        std::ostringstream w;
        const std::string unit = n->unit.empty() || n->unit == "1" ? "" : " " + n->unit;
        w << n->parameter << " only to +-" << std::setprecision(2) << n->sigma << unit
          << " (typical " << n->typical << unit << ")";
        weak.push_back(w.str());
      }
    } else {
      double least = weak_columns.front()->sigma / weak_columns.front()->typical;
      for (const Confounding* n : weak_columns) least = std::min(least, n->sigma / n->typical);
      std::ostringstream w;
      w << weak_columns.size() << " of " << c.num_parameters << " parameters only to "
        << std::setprecision(2) << least << " times their typical size or worse";
      weak.push_back(w.str());
    }
    if (!unexcited.empty()) {
      out << unexcited.size() << " of " << c.num_parameters << " parameters not excited by this data";
    }
    if (!confounders.empty()) {
      out << (unexcited.empty() ? "" : "; ") << "confounded with";
      for (const auto& k : confounders) out << " " << k;
    }
    if (!weak.empty()) {
      out << (unexcited.empty() && confounders.empty() ? "" : "; ") << "this data determines";
      for (std::size_t k = 0; k < weak.size(); ++k) out << (k ? ", " : " ") << weak[k];
    }
    out << "\n";
  }
  for (const auto& s : d.skipped) out << "skipped " << s.effect << ": " << s.reason << "\n";
  out << AdviceText(d);
  return out.str();
}

std::string ResidualAnalysisText(const diagnostics::ResidualAnalysis& ra,
                                 std::size_t max_signatures) {
  using diagnostics::ResidualKindName;
  using diagnostics::Signature;
  std::ostringstream out;
  out << std::setprecision(3);
  const char* axes = "xyz";
  out << "where the model fails (whitened residual, ~N(0,1) per axis when it is complete):\n";
  for (const auto& w : ra.worst) {
    out << "  " << w.name << ": " << ResidualKindName(w.residual) << "." << axes[w.axis] << " "
        << w.score << " sigma\n";
  }
  std::vector<const Signature*> sig;
  for (const auto& s : ra.signatures) {
    if (s.significant) sig.push_back(&s);
  }
  std::sort(sig.begin(), sig.end(), [](const Signature* a, const Signature* b) {
    return std::abs(a->correlation) > std::abs(b->correlation);
  });
  if (sig.empty()) {
    out << "no residual signature is significant (" << ra.num_tests << " tests, p < "
        << ra.p_threshold << " each)\n";
  } else {
    out << "residual signatures (" << sig.size() << " of " << ra.num_tests
        << " significant, p < " << ra.p_threshold << " each; strongest first):\n";
    for (std::size_t k = 0; k < sig.size() && k < max_signatures; ++k) {
      const Signature& s = *sig[k];
      out << "  " << ResidualKindName(s.residual) << "." << axes[s.axis] << " against "
          << s.regressor << ": r = " << s.correlation << ", slope " << s.slope_residual
          << " +- " << s.slope_residual_sigma << " per " << s.unit << " (" << s.points
          << " points)\n";
    }
  }
  for (const auto& a : ra.allan) {
    if (a.ratio <= 3.0) continue;
    out << "  Allan deviation of the " << ResidualKindName(a.residual) << "." << axes[a.axis]
        << " residual is " << a.ratio << " x the white-noise line at "
        << (a.tau_s.empty() ? 0.0 : a.tau_s.back())
        << " s: a slow effect (drift, temperature, random walk) is left\n";
  }
  return out.str();
}

}  // namespace plumb::report

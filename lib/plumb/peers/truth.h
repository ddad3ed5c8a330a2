// plumb/peers/truth.h — a calibration (its document, report::CalibrationJson) against the truth
// of a simulated session (its truth document, Option::kTruthJson): the error of every parameter in
// units of its sigma, and the normalised estimation error squared over the full covariance,
//
//   NEES = e^T C^-1 e,   e = estimate - truth over covariance.parameters, C = covariance.matrix
//
// which follows chi^2 with as many degrees of freedom as parameters when the sigmas are honest
// (one session is one draw: its 95 % band is wide; the test suite averages hundreds). C is
// solved by Eigen's LDLT; a C that is not positive definite is said, not inverted.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "plumb/peers/plumb_result.h"

namespace plumb::peers {

/// One true parameter of a simulated session, in plumb's names and units.
struct TrueParameter {
  std::string name;  ///< e.g. "accel.bias.x"
  std::string unit;
  double value = 0.0;
};

/// Reads "parameters" of a simulation's truth document. Throws plumb::InputError naming `path`
/// and the key when the file is not such a document.
std::vector<TrueParameter> ReadSimulationTruth(const std::string& path);

struct TruthRow {
  std::string name, unit;  ///< a parameter's, or a determined combination's text
  bool combination = false;  ///< a combination the data determines (its truth: the sum)
  double estimate = 0.0, truth = 0.0;
  std::optional<double> sigma;  ///< none when the calibration gives none (fixed, unobservable)
  double error() const { return estimate - truth; }
};

struct TruthComparison {
  std::string result_path, truth_path;
  /// The calibration's determined parameters that the truth has, in its order, then the
  /// combinations it determines where the parameters are not (a single pose's gauge).
  std::vector<TruthRow> rows;
  /// Parameters the data does not determine (held at their gauge values): not scored.
  std::vector<std::string> undetermined;
  int beyond_3_sigma = 0;      ///< rows with |error| > 3 sigma
  /// NEES over the covariance's parameters, or over the determined combinations when the
  /// parameters have none; nullopt (with `nees_note` saying why) when the file has no
  /// covariance, a parameter of it has no truth, or it is not positive definite.
  std::optional<double> nees;
  int nees_dof = 0;
  double band_low = 0.0, band_high = 0.0;  ///< chi^2(nees_dof) 2.5 % and 97.5 % quantiles
  std::string nees_note;
  bool nees_over_combinations = false;  ///< the NEES is over the determined combinations
  bool sigma_scaled_by_chi2 = false;  ///< the covariance was scaled by chi^2/dof
};

TruthComparison CompareWithTruth(const PlumbResult& result, const std::vector<TrueParameter>& truth,
                                 const std::string& truth_path);

/// The table and the NEES line; `table` false: the NEES line alone.
std::string TruthComparisonText(const TruthComparison& comparison, bool table = true);
nlohmann::json TruthComparisonJson(const TruthComparison& comparison);

}  // namespace plumb::peers

// plumb/core/calibration_checks.h — what a calibration read from a file must be before anything
// is computed from it: names once each, matrices a sensor can have, a covariance that is one.
// The one reader of the calibration document (document/calibration_document.h, under
// correction/calibration_file.h for apply, export and Python and peers/plumb_result.h for
// compare) refuses a file that fails them, naming the key.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "plumb/core/types.h"

namespace plumb {

/// A sensor's matrix (F, E: output units per SI unit) with a condition number above this is
/// refused: a MEMS part's is within a few percent of a scaled rotation (condition about 1.1),
/// and inverting one of 1e3 multiplies the samples' noise a thousandfold.
inline constexpr double kMaxSensorMatrixCondition = 1e3;

/// A value more than this many times its parameter's typical magnitude (model::ParameterInfo::
/// typical, SI) is no sensor's: a raw-count calibration's values exceed their SI typical by the
/// counts per unit, at most some 1e5 (a 24-bit converter at 1 deg/s); a float overflow
/// (1.7e308) is far beyond.
inline constexpr double kMaxTypicals = 1e9;

/// Why `value` (a parameter's value or sigma, `nominal` its value without error, `typical`
/// and `unit` its typical magnitude and unit) is no sensor's ("" when it can be): more than
/// kMaxTypicals typical magnitudes from nominal, with the figures.
std::string NoSensorsProblem(double value, double nominal, double typical, const std::string& unit);

/// The first repeated name: (index of the repeat, index of its first use); nullopt when every
/// name is given once.
std::optional<std::pair<std::size_t, std::size_t>> FirstRepeat(
    const std::vector<std::string>& names);

/// Why `m` cannot be a sensor's matrix ("" when it can), to follow "the matrix is": "not
/// finite", "singular (...)", or "near-singular (condition number N, ...)" above
/// kMaxSensorMatrixCondition.
std::string SensorMatrixProblem(const Mat3& m);

/// Why `c` is not a covariance ("" when it is): not square, not finite, not symmetric (beyond
/// rounding: 1e-9 of its largest entry), a negative variance, or not positive semidefinite
/// (an eigenvalue below -1e-9 of the largest), with the row or the figure.
std::string CovarianceProblem(const Eigen::MatrixXd& c);

}  // namespace plumb

// plumb/peers/comparison.h — plumb's calibration set beside another tool's, parameter by
// parameter in plumb's forward form, and both scored with imu_tk's gravity-norm cost.
//
// A difference is plumb - peer, in the units of plumb's result; d/sigma divides it by plumb's
// own standard deviation (the peers give none). When plumb's chi^2/dof exceeds 1 the formal
// sigma is optimistic if the misfit were white noise; d/(sigma sqrt(chi^2/dof)) is given too.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "plumb/peers/forward_calibration.h"
#include "plumb/peers/imu_tk.h"
#include "plumb/peers/plumb_result.h"

namespace plumb::peers {

/// One forward parameter of both answers.
struct ComparisonRow {
  std::string name;             ///< plumb's name, e.g. "accel.matrix.xy"
  std::string unit;             ///< plumb's unit text; "" when plumb has no such parameter
  bool in_plumb_model = true;   ///< false: plumb's model has no such term (its value is 0)
  double plumb_value = 0.0;     ///< plumb's estimate (0 when not in its model)
  std::optional<double> plumb_sigma;  ///< plumb's sigma; none when fixed or unobservable
  bool plumb_fixed = false;     ///< plumb held the parameter fixed
  bool plumb_observable = true; ///< false: plumb's data cannot determine it
  double peer_value = 0.0;      ///< the peer's value in plumb's form and units
  double difference = 0.0;      ///< plumb_value - peer_value (0 when not compared)
  /// Why the two values cannot be set against each other (units or sign conventions that
  /// differ); "" when they are compared. Then difference, z and z_scaled are left out.
  std::string not_compared;
  std::optional<double> z;      ///< difference / plumb_sigma
  std::optional<double> z_scaled;  ///< z / sqrt(max(1, chi^2/dof))
};

/// imu_tk's accelerometer cost of both calibrations on plumb's still segments.
struct GravityNormComparison {
  bool available = false;
  std::string unavailable_reason;  ///< why not, when not available
  double gravity_m_s2 = 0.0;       ///< g of the cost, m/s^2
  std::string gravity_source;      ///< the option giving g (OptionText) or "the result's site.gravity"
  int segments = 0;                ///< still segments in plumb's result
  ImuTkCost plumb_means;           ///< plumb's calibration, one residual per segment mean
  ImuTkCost peer_means;            ///< the peer's calibration, the same
  bool has_sample_estimate = false;  ///< noise.accel known: the per-sample estimate exists
  ImuTkCost plumb_samples;         ///< ImuTkSampleCostEstimate of plumb's calibration
  ImuTkCost peer_samples;          ///< ImuTkSampleCostEstimate of the peer's calibration
};

struct Comparison {
  std::string result_path;  ///< plumb's JSON
  std::string method, model;
  double chi2_dof = 0.0;    ///< plumb's chi^2/dof (NaN when unknown)
  long dof = 0;
  ForwardCalibration peer;
  std::vector<ComparisonRow> rows;
  std::vector<std::string> plumb_only;  ///< plumb's parameters the peer has no value for
  GravityNormComparison cost;
  /// Warnings, and why rows are not compared (codes: scales_differ, units_differ,
  /// gyro_sign_differs; core/notice.h).
  std::vector<Notice> notes;
};

struct CompareOptions {
  /// g of imu_tk's cost, m/s^2, > 0; 0 = the result's site.gravity.
  double gravity_m_s2 = 0.0;
};

/// Sets `peer` beside `result` (see the file comment). A sensor's rows are not compared
/// (ComparisonRow::not_compared, and a note) when its units differ: SI on one side and not on
/// the other (ForwardCalibration::acc_unit / gyr_unit against the unit of plumb's bias), or
/// every diagonal of the matrix 180/pi apart (deg/s read as rad/s); the gyroscope matrix's rows
/// also when a diagonal has the opposite sign in the two (a sign convention of the rate).
Comparison Compare(const PlumbResult& result, const ForwardCalibration& peer,
                   const CompareOptions& options = {});

/// The comparison as a text table with the cost section and the notes.
std::string ComparisonText(const Comparison& comparison);

/// The comparison as JSON: {result, plumb {method, model, chi2_dof, dof}, peer {name, sources,
/// notes, R_peer_b, accel {matrix, bias}, gyro {matrix, bias}, g_sensitivity}, rows [{name,
/// unit, in_plumb_model, plumb, sigma, fixed, observable, peer, difference, not_compared, z, z_scaled}],
/// plumb_only [],
/// gravity_norm_cost {available, reason, gravity, gravity_source, segments, formula,
/// means {plumb, peer}, samples_estimate {plumb, peer} | null}, notes []}; non-finite
/// numbers are null. Each cost is {cost, rms, max_abs, terms, weight}.
nlohmann::json ComparisonJson(const Comparison& comparison);

}  // namespace plumb::peers

// plumb/paper/backend.h — the seed paper's two procedures again, as configurations of the one
// least-squares backend (SPEC section 3), so that each also gets chi^2, sigma, rank and the
// directions its data cannot determine.
//
// Benchmark (section 4) on the backend:
//   - every still period that the closed form classified (an axis within max_tilt_rad of
//     gravity) keeps the paper's assumption as a known TILT: that axis exactly along (or
//     against) gravity. Its heading about the vertical is not known on a hand-turned platform
//     and is estimated through Earth rate when a site is given (StillSegment::heading_free);
//   - every turn becomes a segment turning at a known mean rate, nominal angle / duration about
//     its axis (the paper's "integrate and divide by the total angle", written as a residual:
//     mean(y_g) - (E omega_known + b_g)); it is used for the gyroscope only;
//   - model `accel_linear:full+gyro_linear+gyro_bias_drift`: F full (the faces define the
//     frame), E full, b_g(t) = b0 + b1 (t - t0) as the paper's Eq. (5);
//   - no motion integration between segments (the paper has none), Earth rate and WGS84 gravity
//     at the site when one is given (the paper ignores Earth rate; here it is in the model).
// Static (section 5) on the backend:
//   - the samples [begin, end) as one still segment with the known attitude level, x north;
//   - model `paper` with the paper's fixed values held: accel F_xx = F_yy = 1 (the paper's -1 in
//     its gravity-vector convention), F_xy = alpha = 0; gyro E_xx = E_yy = 1, E_xy = sigma = 0,
//     E lower triangle 0. Estimated: b_a, beta = F_xz, gamma = F_yz, mu = F_zz, b_g,
//     tau = E_xz, xi = E_yz, nu = E_zz — of which one pose determines only three combinations
//     per sensor: the backend reports which;
//   - and the same with the paper's fixed values freed, to show which of them the data could
//     not have determined either (the reason the paper had to fix them).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/segment.h"
#include "plumb/core/units.h"
#include "plumb/estimation/options.h"
#include "plumb/estimation/result.h"
#include "plumb/geo/site.h"
#include "plumb/paper/benchmark.h"

namespace plumb::paper {

/// The benchmark configuration: its segments, model spec and the backend's result.
struct PaperBenchmarkBackend {
  std::string model_spec;                 ///< "accel_linear:full+gyro_linear+gyro_bias_drift"
  std::vector<StillSegment> segments;     ///< known-tilt still periods and known-rate turns
  estimation::CalibrationResult result;   ///< fit, sigma, observability
};

/// Builds the benchmark configuration from the closed form's classification (`closed`, from
/// CalibratePaperBenchmark on the same series) and fits it. `max_tilt_rad` as in
/// PaperBenchmarkOptions: the still periods used are those within it of an axis. Throws what
/// estimation::Calibrate throws.
PaperBenchmarkBackend CalibratePaperBenchmarkOnBackend(
    const ImuSeries& series, const PaperBenchmarkResult& closed, const geo::Site& site,
    double max_tilt_rad = 20.0 * units::kRadPerDeg);

/// The static configuration: the paper's model with its constants held, and the same freed.
struct PaperStaticBackend {
  estimation::CalibrationResult fixed;  ///< the paper's constants held (what it estimates)
  estimation::CalibrationResult freed;  ///< its constants freed: which it had to fix
  /// The paper's fixed parameters (names) that the freed fit finds unobservable.
  std::vector<std::string> fixed_unobservable;
  /// The paper's fixed parameters that the data would have determined.
  std::vector<std::string> fixed_observable;
};

/// Fits the static configuration to samples [begin, end) (still, level, x north). Needs a known
/// site for the gyroscope (Earth rate); without one the gyroscope is left out (the model's spec
/// says "accelerometer only"). Throws plumb::Error for a bad range and what estimation::Calibrate throws.
PaperStaticBackend CalibratePaperStaticOnBackend(const ImuSeries& series, std::size_t begin,
                                                 std::size_t end, const geo::Site& site);

/// An entry (row, col) of F (model::Sensor::kAccel) or E (kGyro); a model places it with
/// model::Model::MatrixEntry.
struct MatrixEntryRef {
  model::Sensor sensor;
  int row, col;
};

/// The entries the paper's static procedure fixes (section 5: the first two diagonal elements
/// of F and E, alpha = F_xy and sigma = E_xy), in that order.
const std::vector<MatrixEntryRef>& PaperStaticFixedEntries();

}  // namespace plumb::paper

// plumb/paper/evaluation.h — the seed paper's results and evaluation (its sections 6 and 7):
// Tables 1-4 (benchmark against proposed, with % error), the datasheet check of Table 5, and
// the true inputs reconstructed from the benchmark data by both calibrations (Figures 1-6).
//
// % error. The paper's tables are not consistent: Tables 1-3 print 100 (proposed - benchmark) /
// benchmark (Table 3, x: -0.1015 against -0.0060 gives +1.58E3), Table 4 prints 100 (benchmark
// - proposed) / benchmark (its diagonal -0.9650 against -1 gives -3.622) and 100 where the
// proposed value is 0 (which either formula makes -100 or +100). plumb uses one formula
// everywhere, 100 (proposed - benchmark) / |benchmark|: the sign says whether the proposed
// value is above or below, and a zero benchmark gives NaN ("undefined").
#pragma once

#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/types.h"
#include "plumb/paper/benchmark.h"
#include "plumb/paper/static_procedure.h"

namespace plumb::paper {

/// 100 (proposed - benchmark) / |benchmark|, %; NaN when benchmark is 0 or either is not finite.
double PercentError(double proposed, double benchmark);

/// One quantity of the paper's tables: the benchmark's value, the proposed one, and
/// PercentError element by element.
template <typename T>
struct Compared {
  T benchmark = T::Zero();
  T proposed = T::Zero();
  T error_pct = T::Zero();
};

/// Tables 1-4 in the paper's convention (its coupling matrices ~ -I for the accelerometer).
struct PaperTables {
  Compared<Vec3> gyro_bias;             ///< Table 1: gyroscope bias, output units
  Vec3 gyro_bias_b1_benchmark = Vec3::Zero();  ///< Table 1: the benchmark's b1, units per s
  Compared<Mat3> gyro_coupling;         ///< Table 2: gyroscope coupling matrix, dimensionless
  Compared<Vec3> accel_bias;            ///< Table 3: accelerometer bias, output units
  Compared<Mat3> accel_coupling;        ///< Table 4: accelerometer coupling, dimensionless
  bool has_gyro = false;  ///< Tables 1 and 2 filled (the static result has a gyroscope part)
};

/// Tables 1-4 from the two closed forms.
PaperTables MakePaperTables(const PaperBenchmarkResult& benchmark,
                            const PaperStaticResult& proposed);

/// Error limits of one IMU part from its datasheet (initial, 25 degC), for the Table 5 check.
/// Fractions are relative (0.03 = 3 %); NaN where the datasheet gives no figure.
struct PartLimits {
  std::string name;                    ///< e.g. "MPU-6000"
  double gyro_bias_rad_s = 0.0;        ///< initial zero-rate output tolerance, +-, rad/s
  double gyro_scale = 0.0;             ///< sensitivity scale factor tolerance, +-, fraction
  double gyro_cross_axis = 0.0;        ///< cross-axis sensitivity, +-, fraction
  double accel_bias_xy_m_s2 = 0.0;     ///< zero-g offset tolerance of x and y, +-, m/s^2
  double accel_bias_z_m_s2 = 0.0;      ///< zero-g offset tolerance of z, +-, m/s^2
  double accel_scale = 0.0;            ///< sensitivity tolerance, +-, fraction
  double accel_cross_axis = 0.0;       ///< cross-axis sensitivity, +-, fraction
  std::string source;                  ///< the datasheet the figures come from
};

/// The parts plumb knows (MPU-6000 first: the paper's Table 5).
const std::vector<PartLimits>& KnownParts();

/// The part named `name` (case-insensitive, "-" optional: "mpu6000" finds "MPU-6000"); throws
/// plumb::Error listing the known names.
const PartLimits& FindPart(const std::string& name);

/// One value checked against a datasheet limit.
struct LimitCheck {
  std::string quantity;  ///< e.g. "accel.bias.x", "gyro scale x", "accel cross-axis xy"
  double value = 0.0;    ///< |value| compared, SI (bias) or fraction (scale, cross-axis)
  double limit = 0.0;    ///< the datasheet's +- limit, same unit; NaN: no figure
  bool within = true;    ///< |value| <= limit (true when the limit is NaN)
};

/// Checks a forward calibration (SPEC section 1: y_a = F f + b_a, y_g = E omega + b_g, SI)
/// against a part's limits: biases; scale = F_ii - 1; cross-axis = F_ij / F_ii (i != j).
/// `has_gyro` false skips E and b_g.
std::vector<LimitCheck> CheckDatasheet(const PartLimits& part, const Mat3& F, const Vec3& b_a,
                                       const Mat3& E, const Vec3& b_g, bool has_gyro);

/// The true inputs reconstructed from the benchmark data (the paper's Figures 1-6): specific
/// force f = F^-1 (y_a - b_a), m/s^2, and rate omega = E^-1 (y_g - b_g(t)), rad/s, by the
/// benchmark (section 4) and the proposed (section 5) calibrations, in plumb's forward
/// convention (the paper plots a_p = -f, the gravity vector).
struct ReconstructedInputs {
  std::vector<double> t_s;                   ///< sample times, s
  std::vector<Vec3> f_benchmark, f_proposed;  ///< m/s^2
  std::vector<Vec3> omega_benchmark, omega_proposed;  ///< rad/s (empty without a gyroscope)
  Vec3 rms_f_difference = Vec3::Zero();      ///< RMS of f_proposed - f_benchmark, m/s^2
  Vec3 rms_omega_difference = Vec3::Zero();  ///< RMS of omega_proposed - omega_benchmark, rad/s
  std::vector<std::string> notes;            ///< e.g. a singular matrix (its inputs are NaN)
};

/// Applies both calibrations to every `stride`-th sample of `series` (stride >= 1).
ReconstructedInputs ReconstructInputs(const ImuSeries& series,
                                      const PaperBenchmarkResult& benchmark,
                                      const PaperStaticResult& proposed, std::size_t stride = 1);

}  // namespace plumb::paper

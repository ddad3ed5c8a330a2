// plumb/paper/static_procedure.h — the seed paper's proposed static calibration (its section
// 5): about a minute still, level, x north, z along gravity.
//
// Accelerometer (steps 1-10, as printed, with the readings below where the text is ambiguous):
//   1. m = mean output of each axis.
//   2. n = |m|; the z output minus gravity: y_z - s n, s = sign(m_z). The paper says "subtracted
//      from the output along z"; its Table 3 (z bias 0.0007 m/s^2) shows the subtraction removed
//      gravity, which for a specific-force log (FRD, z reads -g level) means adding n. With
//      s = sign(m_z) the step does that in either sign convention.
//   3. R = mean of the step-2 output (R_x = m_x, R_y = m_y, R_z = m_z - s n).
//   4. Step-2 output through a 0.5 Hz high-pass filter: signal::ButterworthHighPass (second-
//      order Butterworth, bilinear transform, RBJ cookbook formula), applied once forward from
//      a zero state; the paper names no design, this is the standard one.
//   5. R_f = mean of the filtered output.
//   6. b = R - R_f (a_s = F a_p + b with F = I, a_s = R, a_p = R_f). The filter has a double
//      zero at DC, so R_f is ~0 (the response to the constant part sums to zero; what is left
//      is noise and the end of the record): the bias step reduces to b ~ R, the plain mean.
//   7. g = n.
//   8-9. F = [[c, 0, beta], [0, c, gamma], [0, 0, mu]], c = accel_diagonal (-1, the paper's
//      discussion: +1 "leads to inversion of the x- and y-inputs"), alpha = 0.
//   10. m = F (0, 0, g) + b for beta, gamma, mu: beta = (m_x - b_x)/g, gamma = (m_y - b_y)/g,
//      mu = (m_z - b_z)/g, with a_s the step-1 means m (its Table 4's mu = -1.000 with b_z ~ 0;
//      the step-3 means would give mu = R_fz / g ~ 0). So beta, gamma ~ R_f/g ~ 0.
// Gyroscope (steps 1-7): m = mean; R_f = mean of the 0.5 Hz high-passed output; b = m - R_f;
//   E = [[d, 0, tau], [0, d, xi], [0, 0, nu]], d = gyro_diagonal (+1), sigma = 0;
//   omega_p = C_ecef^ned (0, 0, Omega) = Earth rate in NED, C from GeographicLib
//   (geo::Site::C_ned_ecef), Omega = 7.292115e-5 rad/s;
//   m = E omega_p + b: tau = (m_x - b_x - d omega_N) / omega_D, xi = (m_y - b_y - d omega_E) /
//   omega_D, nu = (m_z - b_z) / omega_D (undefined at the equator, where omega_D = 0).
// Forward convention (SPEC section 1): a_p is the gravity vector, f_b = -a_p, so F = -F_paper,
// b_a = b; E = E_paper, b_g = b.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plumb/core/imu_series.h"
#include "plumb/core/notice.h"
#include "plumb/core/types.h"
#include "plumb/core/units.h"
#include "plumb/geo/site.h"

namespace plumb::paper {

struct PaperStaticOptions {
  double cutoff_hz = 0.5;        ///< high-pass cut-off, Hz, in (0, rate/2); the paper: 0.5
  double accel_diagonal = -1.0;  ///< the constant of F_xx and F_yy (paper convention), finite
  double gyro_diagonal = 1.0;    ///< the constant of E_xx and E_yy, finite
  double earth_rate = units::kEarthRate;  ///< Omega, rad/s, > 0 (the paper's 7.292115e-5)
};

/// The accelerometer part of the static procedure (paper convention; units of the output).
struct PaperStaticAccel {
  Vec3 mean = Vec3::Zero();           ///< step 1: m, accelerometer units
  double norm = 0.0;                  ///< step 2 and 7: n = |m| = g, accelerometer units
  Vec3 step2_mean = Vec3::Zero();     ///< step 3: R
  Vec3 filtered_mean = Vec3::Zero();  ///< step 5: R_f
  Vec3 bias = Vec3::Zero();           ///< step 6: b = R - R_f
  double beta = 0.0;                  ///< step 10, dimensionless
  double gamma = 0.0;                 ///< step 10, dimensionless
  double mu = 0.0;                    ///< step 10, dimensionless (~ -1)
  Mat3 F_paper = Mat3::Identity();    ///< [[c, 0, beta], [0, c, gamma], [0, 0, mu]]
};

/// The gyroscope part of the static procedure (paper convention; units of the output).
struct PaperStaticGyro {
  Vec3 mean = Vec3::Zero();           ///< step 1: R, gyroscope units
  Vec3 filtered_mean = Vec3::Zero();  ///< step 3: R_f
  Vec3 bias = Vec3::Zero();           ///< step 4: b = R - R_f
  Vec3 omega_p = Vec3::Zero();        ///< step 6: C_ecef^ned (0, 0, Omega), rad/s (NED)
  double tau = 0.0;                   ///< step 7, dimensionless
  double xi = 0.0;                    ///< step 7, dimensionless
  double nu = 0.0;                    ///< step 7, dimensionless
  Mat3 E_paper = Mat3::Identity();    ///< [[d, 0, tau], [0, d, xi], [0, 0, nu]]
};

struct PaperStaticResult {
  PaperStaticAccel accel;  ///< the paper's convention
  PaperStaticGyro gyro;    ///< the paper's convention (only when the series has a gyroscope)
  bool has_gyro = false;
  // plumb's forward convention
  Mat3 F = Mat3::Identity();  ///< -F_paper, accelerometer units per m/s^2
  Vec3 b_a = Vec3::Zero();    ///< accel.bias
  Mat3 E = Mat3::Identity();  ///< gyro.E_paper
  Vec3 b_g = Vec3::Zero();    ///< gyro.bias
  double rate_hz = 0.0;       ///< sample rate the filter was designed for (1 / median dt), Hz
  std::size_t count = 0;      ///< samples used
  /// What was fixed or left out (codes: accel_entries_fixed, gyro_entries_fixed, site_unknown
  /// with kSite).
  std::vector<Notice> notes;
};

/// Runs the static procedure on samples [begin, end) of the series (the still, level, x-north
/// minute). The gyroscope part needs a known site off the equator: without a site it is left
/// out (has_gyro false, with a note). Throws plumb::Error for an empty or out-of-range sample
/// range, fewer than 3 samples or bad options, and plumb::InsufficientDataError at the equator
/// (|lat| < 1e-6 rad).
PaperStaticResult CalibratePaperStatic(const ImuSeries& series, std::size_t begin,
                                       std::size_t end, const geo::Site& site,
                                       const PaperStaticOptions& options);

}  // namespace plumb::paper

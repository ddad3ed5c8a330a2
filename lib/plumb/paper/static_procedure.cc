// plumb/paper/static_procedure.cc — see static_procedure.h.
#include "plumb/paper/static_procedure.h"

#include <cmath>
#include <string>

#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/signal/high_pass.h"

namespace plumb::paper {
namespace {

double Mean(const std::vector<double>& x) {
  double sum = 0.0;
  for (double v : x) sum += v;
  return sum / static_cast<double>(x.size());
}

/// One axis of a triad over [begin, end), in double.
std::vector<double> Axis(const std::vector<Vec3f>& triad, std::size_t begin, std::size_t end,
                         int axis) {
  std::vector<double> x;
  x.reserve(end - begin);
  for (std::size_t k = begin; k < end; ++k) x.push_back(triad[k][axis]);
  return x;
}

PaperStaticAccel Accelerometer(const ImuSeries& s, std::size_t begin, std::size_t end,
                               const signal::Biquad& hp, double diagonal) {
  PaperStaticAccel a;
  std::vector<double> axis[3];
  for (int i = 0; i < 3; ++i) {
    axis[i] = Axis(s.acc, begin, end, i);
    a.mean[i] = Mean(axis[i]);  // step 1
  }
  a.norm = a.mean.norm();  // step 2 (and step 7: g)
  if (!(a.norm > 0.0) || !std::isfinite(a.norm)) {
    throw Error("paper-static: the mean accelerometer output is zero or not finite");
  }
  const double sign = a.mean.z() < 0.0 ? -1.0 : 1.0;
  for (double& v : axis[2]) v -= sign * a.norm;
  for (int i = 0; i < 3; ++i) {
    a.step2_mean[i] = Mean(axis[i]);                                // step 3
    a.filtered_mean[i] = Mean(signal::FilterForward(hp, axis[i]));  // steps 4-5
  }
  a.bias = a.step2_mean - a.filtered_mean;  // step 6
  const double g = a.norm;                  // step 7
  a.beta = (a.mean.x() - a.bias.x()) / g;   // step 10 (alpha = 0, step 9)
  a.gamma = (a.mean.y() - a.bias.y()) / g;
  a.mu = (a.mean.z() - a.bias.z()) / g;
  a.F_paper << diagonal, 0.0, a.beta, 0.0, diagonal, a.gamma, 0.0, 0.0, a.mu;
  return a;
}

PaperStaticGyro Gyroscope(const ImuSeries& s, std::size_t begin, std::size_t end,
                          const signal::Biquad& hp, const geo::Site& site,
                          const PaperStaticOptions& o) {
  if (!site.known) {
    throw Error("paper-static gyroscope: needs the site (latitude, longitude) for C_ecef^ned");
  }
  PaperStaticGyro w;
  for (int i = 0; i < 3; ++i) {
    const std::vector<double> x = Axis(s.gyr, begin, end, i);
    w.mean[i] = Mean(x);                                    // step 1
    w.filtered_mean[i] = Mean(signal::FilterForward(hp, x));  // steps 2-3
  }
  w.bias = w.mean - w.filtered_mean;  // step 4
  w.omega_p = site.C_ned_ecef * Vec3(0.0, 0.0, o.earth_rate);  // step 6
  if (std::abs(w.omega_p.z()) < 1e-6 * o.earth_rate) {
    throw InsufficientDataError(
        "paper-static gyroscope: the vertical Earth rate is zero at the equator, so step 7 "
        "(which divides by it) has no solution; use the generalized method");
  }
  const double d = o.gyro_diagonal;
  const Vec3 rhs = w.mean - w.bias;  // step 7: E omega_p = R - b
  w.tau = (rhs.x() - d * w.omega_p.x()) / w.omega_p.z();
  w.xi = (rhs.y() - d * w.omega_p.y()) / w.omega_p.z();
  w.nu = rhs.z() / w.omega_p.z();
  w.E_paper << d, 0.0, w.tau, 0.0, d, w.xi, 0.0, 0.0, w.nu;
  return w;
}

}  // namespace

PaperStaticResult CalibratePaperStatic(const ImuSeries& series, std::size_t begin,
                                       std::size_t end, const geo::Site& site,
                                       const PaperStaticOptions& options) {
  if (end > series.size() || begin + 3 > end) {
    throw Error("paper-static: sample range [" + std::to_string(begin) + ", " +
                std::to_string(end) + ") must hold at least 3 samples of the series of " +
                std::to_string(series.size()));
  }
  if (!std::isfinite(options.accel_diagonal) || !std::isfinite(options.gyro_diagonal) ||
      !(options.earth_rate > 0.0) || !std::isfinite(options.earth_rate)) {
    throw Error("paper-static: diagonal constants must be finite and earth_rate > 0");
  }
  PaperStaticResult r;
  r.count = end - begin;
  r.rate_hz = 1.0 / series.median_dt_s();
  const signal::Biquad hp = signal::ButterworthHighPass(options.cutoff_hz, r.rate_hz);
  r.accel = Accelerometer(series, begin, end, hp, options.accel_diagonal);
  r.F = -r.accel.F_paper;
  r.b_a = r.accel.bias;
  AddNotice(r.notes, "accel_entries_fixed", "F is in the frame of the level, x-north pose; alpha = 0 and F_xx = F_yy = " +
                    std::to_string(-options.accel_diagonal) + " are fixed, not estimated");
  if (series.has_gyro() && !site.known) {
    r.notes.push_back(Notice{"site_unknown",
                             "no site: the gyroscope part (steps 5-7 need C_ecef^ned) is left "
                             "out; give " + OptionText(Option::kSite),
                             {Option::kSite}});
  } else if (series.has_gyro()) {
    r.has_gyro = true;
    r.gyro = Gyroscope(series, begin, end, hp, site, options);
    r.E = r.gyro.E_paper;
    r.b_g = r.gyro.bias;
    AddNotice(r.notes, "gyro_entries_fixed", "sigma = 0 and E_xx = E_yy = " + Number(options.gyro_diagonal) +
                      " are fixed; tau, xi, nu come from Earth rate alone");
  }
  return r;
}

}  // namespace plumb::paper

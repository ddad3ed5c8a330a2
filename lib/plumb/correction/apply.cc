#include "plumb/correction/apply.h"

#include <cmath>
#include <string>

#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/core/option_name.h"
#include "plumb/core/so3.h"

namespace plumb::correction {
namespace {

/// The checks of ApplyCalibration's comment.
void CheckFits(const CalibrationFile& c, const ImuSeries& series) {
  const bool needs_temperature = [&] {
    for (const auto& term : c.model.terms()) {
      if (term.effect->info().excitation.temperature) return true;
    }
    return false;
  }();
  if (c.model.has_gyro() && !series.has_gyro()) {
    throw Error(c.path + ": the calibration has a gyroscope model ('" + c.model.spec() +
                "') and the samples have no gyroscope");
  }
  if (needs_temperature && !series.has_temperature()) {
    throw Error(c.path + ": the model '" + c.model.spec() +
                "' has temperature terms and the samples have no temperature");
  }
  const auto unit_mismatch = [](const std::string& cal, const std::string& samples) {
    return !cal.empty() && cal != samples;
  };
  if (unit_mismatch(c.acc_unit, series.acc_unit) ||
      (series.has_gyro() && unit_mismatch(c.gyr_unit, series.gyr_unit))) {
    throw Error(c.path + ": the calibration was made on samples in " + c.acc_unit + " and " +
                c.gyr_unit + ", these are in " + series.acc_unit + " and " + series.gyr_unit +
                ": read them with the input options the calibration was made with");
  }
}

/// E^-1 d y_g / dt at sample i (central differences; one-sided at the ends).
Vec3 AngularAcceleration(const ImuSeries& s, std::size_t i, const Mat3& E_inv) {
  if (!s.has_gyro() || s.size() < 2) return Vec3::Zero();
  const std::size_t a = i == 0 ? 0 : i - 1, b = i + 1 == s.size() ? i : i + 1;
  const double dt = s.t_s[b] - s.t_s[a];
  if (!(dt > 0.0)) return Vec3::Zero();
  return E_inv * (s.gyr[b].cast<double>() - s.gyr[a].cast<double>()) / dt;
}

/// A calibration's values: its model's blocks and, for a board's IMU k, its mount's rotation
/// vector (CalibrationFile::mount_rotation).
struct Values {
  model::ParameterBlocks theta;
  Vec3 rho = Vec3::Zero();
};

/// Corrects sample i with `values` (the model's linear parts inverted once per theta), in the
/// body frame: R_b_k = Exp(rho) times IMU k's own corrected sample. `values` must outlive it.
class Corrector {
 public:
  Corrector(const CalibrationFile& c, const ImuSeries& s, const Values& values, int steps)
      : c_(c), s_(s), steps_(steps), R_b_k_(so3::Exp(values.rho)) {
    const model::ParameterBlocks& theta = values.theta;
    for (const auto& block : theta) blocks_.push_back(block.data());
    const model::SensorOutput<double> linear = c.model.Predict(blocks_.data(), model::SensorInput<double>());
    F_inv_ = linear.F.inverse();
    E_inv_ = c.model.has_gyro() ? Mat3(linear.E.inverse()) : Mat3::Identity();
  }
  std::pair<Vec3, Vec3> operator()(std::size_t i) const {
    model::SensorInput<double> in;
    in.dt_s = s_.t_s[i] - c_.model.t_ref_s;
    if (s_.has_temperature()) in.dtemp_c = static_cast<double>(s_.temp_c[i]) - c_.model.temp_ref_c;
    in.alpha_b = AngularAcceleration(s_, i, E_inv_);
    const Vec3 y_g = s_.has_gyro() ? Vec3(s_.gyr[i].cast<double>()) : Vec3::Zero();
    const auto [f, omega] = c_.model.Correct(blocks_.data(), Vec3(s_.acc[i].cast<double>()), y_g,
                                             in, F_inv_, E_inv_, steps_);
    return {R_b_k_ * f, R_b_k_ * omega};
  }

 private:
  const CalibrationFile& c_;
  const ImuSeries& s_;
  int steps_;
  Mat3 R_b_k_;
  std::vector<const double*> blocks_;
  Mat3 F_inv_, E_inv_;
};

/// Per sample and axis, sqrt(diag(J C J^T)) (apply.h). The calibration moved by +-h along each
/// parameter of the covariance is set up once; each sample's J is made and used in turn.
void Propagate(const CalibrationFile& c, const ImuSeries& s, int steps, CorrectedSeries& out) {
  const auto n = static_cast<Eigen::Index>(c.covariance_names.size());
  std::vector<Values> moved;  // +h, -h per parameter (the Correctors point in)
  std::vector<double> step;
  moved.reserve(static_cast<std::size_t>(2 * n));
  for (Eigen::Index j = 0; j < n; ++j) {
    const std::string& name = c.covariance_names[static_cast<std::size_t>(j)];
    const double h = 1e-3 * std::sqrt(std::max(c.covariance(j, j), 0.0)) + 1e-12;
    for (double sign : {1.0, -1.0}) {
      moved.push_back({c.theta, c.mount_rotation});
      if (const auto at = c.model.FindParameter(name)) {
        moved.back().theta[static_cast<std::size_t>(at->first)]
                          [static_cast<std::size_t>(at->second)] += sign * h;
      } else {  // an axis of the mount's rotation (calibration_file.h)
        moved.back().rho[*MountRotationAxis(name)] += sign * h;
      }
    }
    step.push_back(h);
  }
  std::vector<Corrector> correctors;
  for (const auto& theta : moved) correctors.emplace_back(c, s, theta, steps);
  out.f_sigma.resize(s.size());
  if (s.has_gyro()) out.omega_sigma.resize(s.size());
  Eigen::Matrix<double, 6, Eigen::Dynamic> J(6, n);
  for (std::size_t i = 0; i < s.size(); ++i) {
    for (Eigen::Index j = 0; j < n; ++j) {
      const auto [f1, w1] = correctors[static_cast<std::size_t>(2 * j)](i);
      const auto [f0, w0] = correctors[static_cast<std::size_t>(2 * j + 1)](i);
      const double h2 = 2.0 * step[static_cast<std::size_t>(j)];
      J.col(j) << (f1 - f0) / h2, (w1 - w0) / h2;
    }
    const Eigen::Matrix<double, 6, 1> var = (J * c.covariance * J.transpose()).diagonal();
    out.f_sigma[i] = var.head<3>().cwiseMax(0.0).cwiseSqrt();
    if (s.has_gyro()) out.omega_sigma[i] = var.tail<3>().cwiseMax(0.0).cwiseSqrt();
  }
}

}  // namespace

CorrectedSeries ApplyCalibration(const CalibrationFile& calibration, const ImuSeries& series,
                                 const ApplyOptions& options) {
  if (options.newton_steps < 0) throw Error("apply: newton_steps must be >= 0");
  CheckFits(calibration, series);
  const int steps = options.newton_steps + 1;  // the first step is the linear inverse
  const Values values{calibration.theta, calibration.mount_rotation};  // outlives `correct`
  const Corrector correct(calibration, series, values, steps);
  CorrectedSeries out;
  out.f_b.resize(series.size());
  if (series.has_gyro()) out.omega_b.resize(series.size());
  for (std::size_t i = 0; i < series.size(); ++i) {
    const auto [f, w] = correct(i);
    if (!f.allFinite() || (series.has_gyro() && !w.allFinite())) {
      throw NonFiniteCorrection("sample " + std::to_string(i) + " (t = " +
                                FixedText(series.t_s[i], 6) +
                  " s) corrects to a value that is not finite: the sample is beyond any "
                  "sensor's range (a corrupt row) or the calibration " + calibration.path +
                  " cannot be inverted there; nothing written");
    }
    out.f_b[i] = f;
    if (series.has_gyro()) out.omega_b[i] = w;
  }
  if (options.uncertainty) {
    if (calibration.covariance_names.empty()) {
      throw Error(calibration.path +
                  ": the calibration has no covariance over its parameters to propagate (none "
                  "in the file, or its data determined only combinations of them: see its "
                  "'observability'); apply it without the uncertainty (" +
                  OptionText(Option::kSigma) + ")",
                  {Option::kSigma});
    }
    Propagate(calibration, series, steps, out);
  }
  return out;
}

}  // namespace plumb::correction

// plumb/estimation/gates.cc — the fit's gates (gates.h: not_converged, nonlinear, one_pose,
// unit_or_rate, not_a_turn, not_still): CheckFit, and CheckGates; the samples' gates are in
// gates_samples.cc.
#include "plumb/estimation/gates.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "plumb/core/error.h"
#include "plumb/core/number_text.h"
#include "plumb/core/option_name.h"
#include "plumb/core/units.h"
#include "plumb/estimation/gates_internal.h"
#include "plumb/model/effects/gyro_linear.h"

namespace plumb::estimation {
namespace {

using gates_internal::Count;
using gates_internal::Median;
using gates_internal::SiAccel;
using gates_internal::SiGyro;

/// A time or a duration to a tenth of a second ("%.1f"): log times since boot and unix times
/// alike ("1710773367.1", not "1.711e+09").
std::string Tenth(double t) { return FixedText(t, 1); }

/// The still segments at rest (not turning at a stated rate), in time order.
std::vector<const StillSegmentFit*> AtRest(const std::vector<StillSegmentFit>& still) {
  std::vector<const StillSegmentFit*> out;
  for (const auto& s : still) {
    if (!s.segment.spinning()) out.push_back(&s);
  }
  return out;
}

/// Same gravity direction within the noise (and kSamePoseMinDeg).
bool SameGravity(const StillSegmentFit& a, const StillSegmentFit& b, const NoiseLevels& noise) {
  const double na = a.acc_mean.norm(), nb = b.acc_mean.norm();
  if (!(na > 0) || !(nb > 0)) return false;
  const double cosine = std::clamp(a.acc_mean.dot(b.acc_mean) / (na * nb), -1.0, 1.0);
  const double angle = std::acos(cosine);
  const double s = noise.acc.maxCoeff() * std::sqrt(std::max(1.0, noise.tau_acc));
  const double sa = s / std::sqrt(static_cast<double>(std::max<std::size_t>(1, a.count))) / na;
  const double sb = s / std::sqrt(static_cast<double>(std::max<std::size_t>(1, b.count))) / nb;
  const double bound =
      std::max(kSamePoseSigmas * std::hypot(sa, sb), kSamePoseMinDeg * units::kRadPerDeg);
  return angle < bound;
}

/// No turn between a and b: the gyroscope between them, less the mean of their still rates,
/// integrates to less than its noise bound (and kSameTurnMinDeg in SI).
bool NoTurn(const ImuSeries& series, const StillSegmentFit& a, const StillSegmentFit& b,
            const NoiseLevels& noise) {
  if (!series.has_gyro()) return true;
  const std::size_t first = a.segment.end, last = std::min(b.segment.begin, series.size());
  const Vec3 rate = 0.5 * (a.gyr_mean + b.gyr_mean);
  const double dt_median = series.median_dt_s();
  Vec3 turn = Vec3::Zero();
  for (std::size_t i = first; i < last; ++i) {
    const double dt = i + 1 < series.size() ? series.t_s[i + 1] - series.t_s[i] : dt_median;
    turn += (series.gyr[i].cast<double>() - rate) * dt;
  }
  const double n = static_cast<double>(last > first ? last - first : 0);
  const double tau = std::max(1.0, noise.tau_gyr);
  const double sigma = noise.gyr.maxCoeff();
  const double integral = sigma * dt_median * std::sqrt(n * tau);
  const double mean = sigma * std::sqrt(tau) * 0.5 *
                      std::sqrt(1.0 / std::max<std::size_t>(1, a.count) +
                                1.0 / std::max<std::size_t>(1, b.count)) *
                      n * dt_median;
  double bound = kSamePoseSigmas * std::sqrt(3.0) * std::hypot(integral, mean);
  if (SiGyro(series)) bound = std::max(bound, kSameTurnMinDeg * units::kRadPerDeg);
  return turn.norm() < bound;
}

Gate NotConverged(const FitReport& fit) {
  const auto at = fit.solver_report.find("Termination: ");
  const std::string why =
      at == std::string::npos ? std::string("no convergence") : fit.solver_report.substr(at);
  return Gate{"not_converged",
              "the solver did not converge: its last solve stopped after " +
                  std::to_string(fit.last_solve_iterations) + " iterations (" +
                  std::to_string(fit.iterations) + " over its " + std::to_string(fit.solves) +
                  " solves; " + why +
                  "); the values, sigmas and chi2 are not those of a minimum. Check the "
                  "segments and the input's units and rate (the other gates), or allow more "
                  "iterations (" + OptionText(Option::kMaxIterations) + ")",
              {Option::kMaxIterations}};
}

std::optional<Gate> Nonlinear(const FitReport& fit) {
  const LinearityReport& lin = fit.linearity;
  if (!lin.checked || !(lin.worst_ratio > kMaxLinearityRatio)) return std::nullopt;
  const double c2 = lin.step_sigmas * lin.step_sigmas;
  return Gate{"nonlinear",
              "the covariance does not describe this fit: " + Number(lin.step_sigmas, 4) +
                  " sigma out along " + lin.worst_direction + " (in sigma of each) chi2 rises by " +
                  Number(lin.worst_ratio * c2, 4) + " where the covariance says " + Number(c2, 4) +
                  ". The fit lies in a curved valley of near-equal fits (the data tie these "
                  "parameters together only nonlinearly): each sigma may still cover its "
                  "parameter, the combinations' do not, and the values can be far off. Record "
                  "more well-spread poses (9 or more gravity directions when the attitudes are "
                  "free) or state the attitudes"};
}

/// "1-12" style list of the runs of merged segments (1-based), at most a few.
std::string MergedRuns(const std::vector<bool>& same_as_previous) {
  std::string out;
  int shown = 0;
  std::size_t k = 0;
  while (k < same_as_previous.size()) {
    std::size_t end = k + 1;
    while (end < same_as_previous.size() && same_as_previous[end]) ++end;
    if (end - k > 1) {
      if (shown == 4) return out + ", ...";
      out += (out.empty() ? "" : ", ") + std::to_string(k + 1) + "-" + std::to_string(end);
      ++shown;
    }
    k = end;
  }
  return out;
}

std::optional<Gate> OnePose(const ImuSeries& series, const Calibration& cal,
                            const FitReport& fit) {
  const auto rest = AtRest(fit.still);
  const int segments = static_cast<int>(rest.size());
  int free_accel = 0;
  const int accel_base = cal.model.BaseTerm(model::Sensor::kAccel);
  for (const auto& p : cal.parameters) free_accel += (!p.fixed && p.place.term == accel_base) ? 1 : 0;
  const bool known = std::any_of(rest.begin(), rest.end(),
                                 [](const StillSegmentFit* s) { return s->attitude_known; });
  const int needed = known ? (free_accel + 2) / 3 : free_accel;
  if (fit.distinct_poses >= segments || fit.distinct_poses >= needed) return std::nullopt;
  std::vector<bool> same(rest.size(), false);
  for (std::size_t k = 1; k < rest.size(); ++k) {
    same[k] = SameGravity(*rest[k - 1], *rest[k], cal.noise) &&
              NoTurn(series, *rest[k - 1], *rest[k], cal.noise);
  }
  const int poses = fit.distinct_poses;
  return Gate{"one_pose",
              "the " + std::to_string(segments) + " still segments lie in " + std::to_string(poses) +
                  " distinct pose" + (poses == 1 ? "" : "s") + " (segments " + MergedRuns(same) +
                  " have the same gravity direction within the noise and no turn between "
                  "them): the rank (" + std::to_string(cal.observability.rank) + " of " +
                  std::to_string(cal.observability.num_unknowns) +
                  ") and the sigmas rest on " + std::to_string(poses) + " pose" +
                  (poses == 1 ? "" : "s") + ", and the differences between pieces of one pose "
                  "are noise, not information; the accelerometer's " + std::to_string(free_accel) +
                  " free parameters need at least " + std::to_string(needed) + " distinct poses" +
                  (known ? " (with known attitudes)" : "") +
                  ". Record more poses, or give one segment per pose"};
}

/// Mean of the sensor's fitted diagonal entries of F or E (matrix.xx/yy/zz) that are free and
/// observable; nullopt when none is.
std::optional<double> FittedScale(const Calibration& cal, model::Sensor sensor,
                                  const Mat3& m, std::string* diagonal) {
  double sum = 0;
  int n = 0;
  for (int a = 0; a < 3; ++a) {
    const auto place = cal.model.MatrixEntry(sensor, a, a);
    const auto p = std::find_if(cal.parameters.begin(), cal.parameters.end(),
                                [&](const ParameterEstimate& q) { return place && q.place == *place; });
    if (p == cal.parameters.end() || p->fixed || !p->observable) continue;
    sum += m(a, a);
    ++n;
    *diagonal += (diagonal->empty() ? "" : ", ") + Number(m(a, a), 4);
  }
  if (n == 0) return std::nullopt;
  return sum / n;
}

/// The segments whose mean is a possible reading (finite, within out_of_range's limit): a mean
/// over samples out of range says nothing about units (out_of_range says it).
std::vector<const StillSegmentFit*> Plausible(const std::vector<const StillSegmentFit*>& rest,
                                              const Calibration& cal) {
  const double acc_limit = cal.acc_unit == "m/s^2" ? kMaxAccelG * units::kStandardGravity : kMaxCounts;
  const double gyr_limit = cal.gyr_unit == "rad/s" ? kMaxGyroDegS * units::kRadPerDeg : kMaxCounts;
  std::vector<const StillSegmentFit*> out;
  for (const auto* s : rest) {
    const bool acc = s->acc_mean.allFinite() && s->acc_mean.cwiseAbs().maxCoeff() <= acc_limit;
    const bool gyr = !cal.has_gyro ||
                     (s->gyr_mean.allFinite() && s->gyr_mean.cwiseAbs().maxCoeff() <= gyr_limit);
    if (acc && gyr) out.push_back(s);
  }
  return out;
}

/// The raw still norm; then, when the fit is `usable` (converged, poses enough: otherwise its
/// values are noise), the fitted scale and the corrected still norm.
std::optional<Gate> AccelUnit(const Calibration& cal, const std::vector<const StillSegmentFit*>& rest,
                              bool usable) {
  std::vector<double> raw, corrected;
  const Mat3 F = cal.AccelMatrix();
  const Eigen::FullPivLU<Mat3> lu(F);
  for (const auto* s : rest) {
    raw.push_back(s->acc_mean.norm());
    if (lu.isInvertible()) corrected.push_back(lu.solve(s->acc_mean - cal.AccelBias()).norm());
  }
  const double g = cal.site.gravity();
  const double norm = Median(raw);
  const int n = static_cast<int>(rest.size());
  if (cal.acc_unit == "m/s^2" && std::abs(norm / g - 1.0) > kMaxNormError) {
    const double ratio = norm / g;
    const std::vector<Option> named =
        std::abs(norm - 1.0) < 0.2 ? std::vector<Option>{Option::kAccUnit}
                                   : std::vector<Option>{Option::kAccUnit, Option::kAccScale};
    const std::string hint =
        std::abs(norm - 1.0) < 0.2
            ? "the samples look like g, not m/s^2: give " + OptionText(Option::kAccUnit, "g")
        : ratio > 20.0 ? "the samples look like raw counts (or mg): give " +
                             OptionText(Option::kAccUnit, "counts") + ", or " +
                             OptionText(Option::kAccScale)
                       : "check the accelerometer's unit and scale (" +
                             OptionText(Option::kAccUnit) + ", " + OptionText(Option::kAccScale) +
                             ")";
    return Gate{"unit_or_rate", "the still accelerometer reads " + Number(norm, 4) +
                                    " m/s^2 (median norm over " + Count(n, "still segment") +
                                    ") where gravity is " + Number(g, 4) + " m/s^2: " +
                                    hint,
                named};
  }
  std::string diagonal;
  const auto scale = FittedScale(cal, model::Sensor::kAccel, F, &diagonal);
  if (!usable || !scale) return std::nullopt;
  if (cal.acc_unit == "m/s^2" && std::abs(*scale - 1.0) > kMaxScaleError) {
    return Gate{"unit_or_rate", "the accelerometer's scale came out " + Number(*scale, 4) +
                                    " (accel.matrix diagonal " + diagonal +
                                    "), more than " + Number(100 * kMaxScaleError, 4) +
                                    " % from 1: check the accelerometer's unit and scale (" +
                                    OptionText(Option::kAccUnit) + ", " +
                                    OptionText(Option::kAccScale) + ")",
                {Option::kAccUnit, Option::kAccScale}};
  }
  const double after = Median(corrected);
  if (std::isfinite(after) && std::abs(after / g - 1.0) > kMaxCorrectedNormError) {
    return Gate{"unit_or_rate", "after calibration the still accelerometer reads " + Number(after, 4) +
                                    " m/s^2 (median of |F^-1 (mean - b_a)| over " +
                                    Count(n, "still segment") + ") where gravity is " +
                                    Number(g, 4) + " m/s^2: the fit does not explain the poses"};
  }
  return std::nullopt;
}

/// The raw still norm; then, when the fit is `usable`, the fitted scale (turn angles).
std::optional<Gate> GyroUnitOrRate(const ImuSeries& series, const Calibration& cal,
                                   const std::vector<const StillSegmentFit*>& rest, bool usable) {
  if (!cal.has_gyro || cal.gyr_unit != "rad/s") return std::nullopt;
  std::vector<double> raw;
  for (const auto* s : rest) raw.push_back(s->gyr_mean.norm());
  const double norm = Median(raw);
  const double allowed = kMaxGyroBiasDegS * units::kRadPerDeg + units::kEarthRate;
  if (norm > allowed) {
    return Gate{"unit_or_rate",
                "the still gyroscope reads " + Number(norm, 4) + " rad/s (median norm over " +
                    Count(rest.size(), "still segment") + ") where Earth rate (" +
                    Number(units::kEarthRate, 4) + " rad/s) and a plausible bias (" +
                    Number(kMaxGyroBiasDegS, 4) + " deg/s) allow at most " + Number(allowed, 4) +
                    " rad/s: the samples look like deg/s or raw counts, not rad/s (give " +
                    OptionText(Option::kGyrUnit, "deg/s") + ", " +
                    OptionText(Option::kGyrUnit, "counts") + " or " +
                    OptionText(Option::kGyrScale) + ")",
                {Option::kGyrUnit, Option::kGyrScale}};
  }
  std::string diagonal;
  const auto scale = FittedScale(cal, model::Sensor::kGyro, cal.GyroMatrix(), &diagonal);
  if (!usable || !scale || std::abs(*scale - 1.0) <= kMaxScaleError) return std::nullopt;
  const std::string what = "the gyroscope's scale came out " + Number(*scale, 4) +
                           " (gyro.matrix diagonal " + diagonal + "), not about 1: ";
  if (std::abs(*scale / units::kDegPerRad - 1.0) < 0.15) {
    return Gate{"unit_or_rate", what + "the samples look like deg/s, not rad/s: give " +
                                    OptionText(Option::kGyrUnit, "deg/s"),
                {Option::kGyrUnit}};
  }
  if (std::abs(*scale * units::kDegPerRad - 1.0) < 0.15) {
    return Gate{"unit_or_rate",
                what + "the samples look like rad/s, given as deg/s: drop " +
                    OptionText(Option::kGyrUnit, "deg/s"),
                {Option::kGyrUnit}};
  }
  const double dt = series.median_dt_s();
  return Gate{"unit_or_rate",
              what + "the turns integrate to " + Number(*scale, 4) +
                  " times the angles the accelerometer sees between the poses, so the sample "
                  "times are likely wrong by that factor: the samples are " + Number(dt, 4) +
                  " s apart (" + Number(1.0 / dt, 4) + " Hz), the turns say about " +
                  Number(*scale / dt, 4) + " Hz (check " + OptionText(Option::kRate) +
                  ", or the time column's unit)",
              {Option::kRate}};
}

/// The free parameters of the gyroscope's matrix (its linear stage's block before the bias,
/// model/effects/gyro_linear.h) that the fit leaves undetermined, or determines only to more
/// than kNotATurnMatrixSigma (Earth rate alone), by name.
std::vector<std::string> UndeterminedGyroMatrix(const Calibration& cal) {
  std::vector<std::string> out;
  const int base = cal.model.BaseTerm(model::Sensor::kGyro);
  if (!cal.has_gyro || base < 0) return out;
  const auto offset = static_cast<std::size_t>(cal.model.FirstParameter(base));
  for (int i = 0; i < model::gyro_linear::kBias; ++i) {
    const std::size_t k = offset + static_cast<std::size_t>(i);
    if (k >= cal.parameters.size()) break;
    const ParameterEstimate& p = cal.parameters[k];
    if (!p.fixed && (!p.observable || !(p.sigma <= kNotATurnMatrixSigma))) out.push_back(p.name);
  }
  return out;
}

/// not_a_turn: motion left out where no turn is left to determine the gyroscope's matrix.
std::optional<Gate> NotATurnGate(const Calibration& cal, const FitReport& fit) {
  if (fit.not_turns.empty()) return std::nullopt;
  const std::vector<std::string> undetermined = UndeterminedGyroMatrix(cal);
  if (undetermined.empty()) return std::nullopt;
  std::string what;
  for (const NotATurn& m : fit.not_turns) what += (what.empty() ? "" : "; ") + NotATurnText(fit, m);
  return Gate{"not_a_turn", what + "; without it the turns left (" +
                                std::to_string(fit.motion_segments) + ") leave " +
                                Count(undetermined.size(), "parameter") +
                                " of the gyroscope's matrix undetermined or known only to more "
                                "than " + Number(kNotATurnMatrixSigma, 4) + " (" + undetermined.front() +
                                (undetermined.size() > 1 ? ", ..." : "") +
                                "): record turns of seconds between the still poses"};
}

}  // namespace

std::string NotATurnText(const FitReport& fit, const NotATurn& m) {
  auto label = [&](std::size_t k) {
    return k < fit.still.size() ? "'" + fit.still[k].segment.label + "'" : "#" + std::to_string(k);
  };
  const std::string motion = "the motion " + Tenth(m.t_begin_s) + "-" + Tenth(m.t_end_s) +
                             " s (" + Tenth(m.t_end_s - m.t_begin_s) + " s) between " +
                             label(m.from) + " and " + label(m.to) +
                             " is left out of the fit, not a turn: ";
  if (m.flown) {
    return motion + "the log says the vehicle was " + Describe(*m.flown) +
           ", a flight or a vehicle carried, whose vibration and translation logged samples "
           "do not resolve";
  }
  if (m.gap) {
    return motion + "its samples stop for " + Number(m.gap->length_s, 3) + " s at " +
           Tenth(m.gap->t_s) + " s, longer than " + Number(m.gap_limit_s, 3) +
           " s: the turn the samples miss (a dropout of the link or the logger) cannot be "
           "integrated";
  }
  return motion + "longer than " + Number(m.limit_s, 4) +
         " s, more than a MEMS gyroscope integrates to its noise (a flight, a vehicle carried)";
}

int CountDistinctPoses(const ImuSeries& series, const std::vector<StillSegmentFit>& still,
                       const NoiseLevels& noise) {
  const auto rest = AtRest(still);
  int poses = rest.empty() ? 0 : 1;
  for (std::size_t k = 1; k < rest.size(); ++k) {
    const bool same = SameGravity(*rest[k - 1], *rest[k], noise) &&
                      NoTurn(series, *rest[k - 1], *rest[k], noise);
    poses += same ? 0 : 1;
  }
  return poses;
}

namespace {

/// Per-sample scatter, the largest axis's RMS about the mean, of `v` over [begin, end).
double Scatter(const std::vector<Vec3f>& v, std::size_t begin, std::size_t end) {
  if (end <= begin + 1) return 0.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero();
  for (std::size_t k = begin; k < end; ++k) {
    const Eigen::Vector3d x = v[k].cast<double>();
    sum += x;
    sum2 += x.cwiseProduct(x);
  }
  const double n = static_cast<double>(end - begin);
  const Eigen::Vector3d mean = sum / n;
  return ((sum2 / n - mean.cwiseProduct(mean)).cwiseMax(0.0)).cwiseSqrt().maxCoeff();
}

/// One sensor's scatter per segment, SI: as logged for SI samples (`si`), else divided by the
/// fitted scale (counts per SI unit). SI samples are not divided by the fit's scale: a fit
/// left without turns (not_a_turn) or poses (one_pose) leaves it undetermined, at any value.
std::vector<double> ScatterSi(const std::vector<Vec3f>& v,
                              const std::vector<const StillSegmentFit*>& still,
                              const Mat3& matrix, bool si) {
  const double scale = si ? 1.0 : matrix.diagonal().cwiseAbs().mean();
  std::vector<double> out;
  for (const StillSegmentFit* s : still) {
    out.push_back(Scatter(v, s->segment.begin, s->segment.end) / (scale > 0 ? scale : 1.0));
  }
  return out;
}

/// Why segment k of one sensor is not still ("" when it is).
std::string Unstill(const std::vector<double>& scatter, std::size_t k, double limit,
                    double floor, const char* sensor, const char* unit) {
  const double quietest =
      std::max(floor, *std::min_element(scatter.begin(), scatter.end()));
  const bool loud = scatter[k] > limit;
  const bool apart = scatter.size() > 1 && scatter[k] > kNotStillRatio * quietest;
  if (!loud && !apart) return "";
  return std::string(sensor) + " " + Number(scatter[k], 4) + " " + unit + " (" +
         Number(scatter[k] / quietest, 4) + " times the quietest segment's" +
         (loud ? ", above " + Number(limit, 4) + " " + unit : std::string()) + ")";
}

/// The not_still gate (gates.h).
std::optional<Gate> NotStill(const ImuSeries& series, const Calibration& cal,
                             const std::vector<LogMotion>& log_motion, const FitReport& fit) {
  // At rest only: a turntable's spinning segments are meant to move.
  const std::vector<const StillSegmentFit*> rest = AtRest(fit.still);
  if (rest.empty()) return std::nullopt;
  const std::vector<double> acc = ScatterSi(series.acc, rest, cal.AccelMatrix(), SiAccel(series));
  const bool gyro = cal.has_gyro && series.has_gyro();
  const std::vector<double> gyr =
      gyro ? ScatterSi(series.gyr, rest, cal.GyroMatrix(), SiGyro(series)) : std::vector<double>();
  std::string list;
  int count = 0;
  bool flown = false;  // some segment falls where the log says the vehicle flew or moved
  for (std::size_t k = 0; k < rest.size(); ++k) {
    std::string why = Unstill(acc, k, kNotStillAccel, kStillScatterFloorAccel,
                              "accelerometer", "m/s^2");
    if (gyro) {
      const std::string g =
          Unstill(gyr, k, kNotStillGyro, kStillScatterFloorGyro, "gyroscope", "rad/s");
      if (!g.empty()) why += (why.empty() ? "" : ", ") + g;
    }
    const StillSegment& seg = rest[k]->segment;
    for (const LogMotion& m : log_motion) {
      if (!m.Covers(series.t_s[seg.begin], series.t_s[seg.end - 1])) continue;
      why += (why.empty() ? "" : ", ") + std::string("the log says the vehicle was ") + Describe(m);
      flown = true;
      break;
    }
    if (why.empty()) continue;
    ++count;
    if (count <= 3) {
      const StillSegmentFit& s = *rest[k];
      list += std::string(list.empty() ? "" : "; ") + "'" + s.segment.label + "' (" +
              Tenth(series.t_s[s.segment.begin]) + "-" + Tenth(series.t_s[s.segment.end - 1]) +
              " s): " + why;
    }
  }
  if (count == 0) return std::nullopt;
  return Gate{"not_still",
              std::to_string(count) + " of " + std::to_string(rest.size()) +
                  " still segments scatter far beyond an IMU at rest, per sample" +
                  (flown ? ", or fall where the log says the vehicle flew or moved" : "") +
                  ": " + list +
                  (count > 3 ? "; ..." : "") +
                  ". A flight, running motors or a vehicle carried is not a still pose, and "
                  "the noise measured there is motion: give the still periods (a segments "
                  "file, or the log's time window before take-off)"};
}

}  // namespace

std::vector<Gate> CheckFit(const ImuSeries& series, const Calibration& calibration,
                           const std::vector<LogMotion>& log_motion, FitReport& fit) {
  std::vector<Gate> gates;
  if (!fit.converged) gates.push_back(NotConverged(fit));
  const auto one_pose = OnePose(series, calibration, fit);
  if (one_pose) gates.push_back(*one_pose);
  if (fit.converged && !one_pose) {
    if (auto g = Nonlinear(fit)) gates.push_back(*g);
  }
  if (auto g = NotStill(series, calibration, log_motion, fit)) gates.push_back(*g);
  if (auto g = NotATurnGate(calibration, fit)) gates.push_back(*g);
  const auto rest = Plausible(AtRest(fit.still), calibration);
  if (rest.empty()) return gates;
  const bool usable = fit.converged && !one_pose;
  if (auto g = AccelUnit(calibration, rest, usable)) gates.push_back(*g);
  if (auto g = GyroUnitOrRate(series, calibration, rest, usable)) gates.push_back(*g);
  return gates;
}

std::vector<Gate> CheckGates(const ImuSeries& series, const std::vector<StillSegment>& still,
                             const Calibration& calibration,
                             const std::vector<LogMotion>& log_motion, FitReport& fit) {
  std::vector<Gate> gates = CheckSamples(series, still);
  for (auto& g : CheckFit(series, calibration, log_motion, fit)) gates.push_back(std::move(g));
  return gates;
}

}  // namespace plumb::estimation

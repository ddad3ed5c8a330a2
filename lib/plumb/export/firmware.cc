#include "plumb/export/firmware.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "plumb/core/number_text.h"
#include "plumb/core/error.h"
#include "plumb/core/option_name.h"
#include "plumb/core/units.h"
#include "plumb/model/model.h"
#include "plumb/signal/segment_stats.h"

namespace plumb::exporter {
namespace {

/// Binomial coefficient C(k, j) for k <= 3.
double Binomial(int k, int j) {
  double c = 1.0;
  for (int i = 1; i <= j; ++i) c = c * (k - j + i) / i;
  return c;
}

/// The temperature polynomial of the sensor's temperature bias term (Model::
/// TemperatureBiasTerm), about the model's reference temperature; false when absent.
bool ModelThermal(const estimation::Calibration& c, model::Sensor sensor,
                  TemperaturePolynomial& out) {
  const int term = c.model.TemperatureBiasTerm(sensor);
  if (term < 0) return false;
  const std::vector<double>& block = c.theta[static_cast<std::size_t>(term)];
  out = TemperaturePolynomial{};
  out.t0_c = c.model.temp_ref_c;
  const std::size_t order = block.size() / 3;  // 3 values per order, lowest order first
  for (std::size_t k = 0; k < order && k < 3; ++k) {
    out.c[k + 1] = Vec3(block[3 * k], block[3 * k + 1], block[3 * k + 2]);
  }
  return true;
}


/// "x 0.12 y 0.03 z 0.40 mg" style triple.
std::string Triple(const Vec3& v, double factor, int decimals) {
  return "x " + FixedText(v.x() * factor, decimals) + "  y " + FixedText(v.y() * factor, decimals) +
         "  z " + FixedText(v.z() * factor, decimals);
}

}  // namespace

Vec3 TemperaturePolynomial::At(double temp_c) const {
  const double d = temp_c - t0_c;
  return c[0] + d * (c[1] + d * (c[2] + d * c[3]));
}

TemperaturePolynomial Rebase(const TemperaturePolynomial& p, double t0_c) {
  if (!std::isfinite(t0_c)) throw Error("temperature polynomial: new reference is not finite");
  TemperaturePolynomial q;
  q.t0_c = t0_c;
  const double shift = t0_c - p.t0_c;  // T - t0_old = (T - t0_new) + shift
  for (int j = 0; j < 4; ++j) {
    Vec3 cj = Vec3::Zero();
    for (int k = j; k < 4; ++k) cj += p.c[k] * (Binomial(k, j) * std::pow(shift, k - j));
    q.c[j] = cj;
  }
  return q;
}

Vec3 DiagonalCorrection::Apply(const Vec3& y, double temp_c) const {
  Vec3 v = y - offset;
  if (has_thermal) v -= thermal.At(std::clamp(temp_c, temp_min_c, temp_max_c));
  return scale.cwiseProduct(v);
}

bool TemperatureRange::known() const {
  return std::isfinite(min_c) && std::isfinite(max_c) && min_c <= max_c;
}

TemperatureRange SessionTemperatureRange(const ImuSeries& series) {
  TemperatureRange range;
  for (float t : series.temp_c) {
    if (!std::isfinite(t)) continue;
    if (!(t >= range.min_c)) range.min_c = t;  // NaN-initialised: the first finite wins
    if (!(t <= range.max_c)) range.max_c = t;
  }
  return range;
}

FirmwareCorrection BestDiagonal(const estimation::Calibration& c,
                                const TemperatureRange& range) {
  if (c.acc_unit != "m/s^2" || (c.has_gyro && c.gyr_unit != "rad/s")) {
    throw Error("the session's samples are in " + c.acc_unit + " and " + c.gyr_unit +
                ", not m/s^2 and rad/s: firmware parameters act on SI sensor output, so "
                "plumb cannot export them; give the sensor's scale (" + OptionText(Option::kAccScale) +
                ", " + OptionText(Option::kGyrScale) + ") to calibrate in SI",
                {Option::kAccScale, Option::kGyrScale});
  }
  FirmwareCorrection fw;
  fw.has_gyro = c.has_gyro;
  const Mat3 F_inv = c.AccelMatrix().inverse();
  fw.accel.scale = F_inv.diagonal();
  fw.accel.offset = c.AccelBias();
  fw.gyro.offset = c.GyroBias();  // no gyro scale in either firmware: S = 1
  const std::pair<model::Sensor, DiagonalCorrection*> thermal[] = {
      {model::Sensor::kAccel, &fw.accel}, {model::Sensor::kGyro, &fw.gyro}};
  for (const auto& [which, sensor] : thermal) {
    if (!ModelThermal(c, which, sensor->thermal)) continue;
    if (!range.known()) {
      const int term = c.model.TemperatureBiasTerm(which);
      throw Error("the model has " + c.model.terms()[static_cast<std::size_t>(term)].effect->info().name +
                  " but the session has no temperature: no range to export it over");
    }
    sensor->has_thermal = true;
    sensor->temp_min_c = range.min_c;
    sensor->temp_max_c = range.max_c;
  }
  return fw;
}

ExportReport Evaluate(const estimation::Calibration& c, const ImuSeries& series,
                      const std::vector<estimation::StillSegmentFit>& still,
                      const FirmwareCorrection& fw, const std::string& target,
                      bool keeps_temperature) {
  ExportReport rep;
  rep.target = target;
  rep.has_gyro = c.has_gyro && fw.has_gyro;
  rep.accel_per_input = fw.accel.scale.asDiagonal() * c.AccelMatrix() - Mat3::Identity();
  rep.gyro_per_input = rep.has_gyro
                           ? Mat3(fw.gyro.scale.asDiagonal() * c.GyroMatrix() - Mat3::Identity())
                           : Mat3::Zero();

  Vec3 sum_a = Vec3::Zero(), sum_g = Vec3::Zero();
  for (const estimation::StillSegmentFit& s : still) {
    if (s.segment.spinning() || s.segment.end > series.size() || s.segment.count() == 0) continue;
    const signal::SegmentStats stats = signal::ComputeSegmentStats(series, s.segment);
    model::SensorInput<double> in;
    in.dt_s = s.t_mid_s - c.model.t_ref_s;
    in.dtemp_c = std::isfinite(stats.temp_mean_c) ? stats.temp_mean_c - c.model.temp_ref_c : 0.0;
    in.R_b_n = s.R_n_b.toRotationMatrix().transpose();
    const Vec3 y_g = rep.has_gyro ? s.gyr_mean : Vec3::Zero();
    const auto [f_b, omega_b] = c.model.Correct(c.theta, s.acc_mean, y_g, in);
    const double temp_c = std::isfinite(stats.temp_mean_c) ? stats.temp_mean_c : c.model.temp_ref_c;
    const Vec3 e_a = fw.accel.Apply(s.acc_mean, temp_c) - f_b;
    sum_a += e_a.cwiseAbs2();
    rep.accel_still.max_abs = rep.accel_still.max_abs.cwiseMax(e_a.cwiseAbs());
    ++rep.accel_still.segments;
    if (rep.has_gyro) {
      const Vec3 e_g = fw.gyro.Apply(y_g, temp_c) - omega_b;
      sum_g += e_g.cwiseAbs2();
      rep.gyro_still.max_abs = rep.gyro_still.max_abs.cwiseMax(e_g.cwiseAbs());
      ++rep.gyro_still.segments;
    }
  }
  if (rep.accel_still.segments > 0) {
    rep.accel_still.rms = (sum_a / rep.accel_still.segments).cwiseSqrt();
  }
  if (rep.gyro_still.segments > 0) rep.gyro_still.rms = (sum_g / rep.gyro_still.segments).cwiseSqrt();

  const std::vector<std::string> names = c.model.ParameterNames();
  const std::vector<double> values = model::ReportedValues(c.model, c.theta);
  std::size_t first = 0;
  for (const model::ModelTerm& term : c.model.terms()) {
    const model::EffectInfo& info = term.effect->info();
    const std::size_t n = static_cast<std::size_t>(info.size());
    const int t = static_cast<int>(&term - c.model.terms().data());
    const bool kept = info.linear_stage ||
                      (keeps_temperature && t == c.model.TemperatureBiasTerm(info.sensor));
    if (!kept && n > 0 && !term.probe) {
      DroppedEffect d;
      d.effect = info.name;
      for (std::size_t i = 0; i < n; ++i) {
        d.names.push_back(names[first + i]);
        d.values.push_back(values[first + i]);
        d.units.push_back(info.parameters[i].unit);
      }
      const model::Excitation& x = info.excitation;
      d.seen_at_rest = x.still_orientations || x.temperature || x.time;
      rep.dropped.push_back(std::move(d));
    }
    first += n;
  }
  if (rep.accel_still.segments == 0) {
    AddNotice(rep.notes, "no_still_segment", "no still segment to measure the error on");
  }
  if (!c.observability.unobservable.empty()) {
    AddNotice(rep.notes, "undetermined", std::to_string(c.observability.unobservable.size()) +
                        " direction(s) of the parameters are not determined by this session (see "
                        "the observability report): the exported values are one of many that "
                        "fit it equally, right for poses like the session's only");
  }
  return rep;
}

std::vector<std::string> ExportReport::Lines() const {
  std::vector<std::string> lines;
  lines.push_back(target + ": firmware correction minus plumb's, over " +
                  std::to_string(accel_still.segments) + " still segments (RMS / max per axis)");
  constexpr double kMgPerMS2 = 1e3 / units::kStandardGravity;
  lines.push_back("  accel RMS " + Triple(accel_still.rms, kMgPerMS2, 3) + " mg   max " +
                  Triple(accel_still.max_abs, kMgPerMS2, 3) + " mg");
  lines.push_back("        RMS " + Triple(accel_still.rms, 1.0, 5) + " m/s^2   max " +
                  Triple(accel_still.max_abs, 1.0, 5) + " m/s^2");
  if (has_gyro) {
    constexpr double kDegPerHour = units::kDegPerHourPerRadPerS;
    lines.push_back("  gyro  RMS " + Triple(gyro_still.rms, kDegPerHour, 2) + " deg/h   max " +
                    Triple(gyro_still.max_abs, kDegPerHour, 2) + " deg/h");
    lines.push_back("        RMS " + Triple(gyro_still.rms, 1.0, 7) + " rad/s   max " +
                    Triple(gyro_still.max_abs, 1.0, 7) + " rad/s");
  }
  lines.push_back("  not representable: accel up to " +
                  FixedText(accel_per_input.cwiseAbs().maxCoeff() * 1e6, 0) +
                  " ppm of the input (diagonal scale and offset only)" +
                  (has_gyro ? ", gyro up to " + FixedText(gyro_per_input.cwiseAbs().maxCoeff() * 1e6, 0) +
                                  " ppm of the rate (no gyro scale or misalignment)"
                            : std::string()));
  for (const DroppedEffect& d : dropped) {
    std::string text = "  dropped " + d.effect + ":";
    for (std::size_t i = 0; i < d.names.size(); ++i) {
      text += " " + d.names[i] + " " + SignificantText(d.values[i], 3) + (i + 1 < d.names.size() ? "," : "");
    }
    if (!d.seen_at_rest) text += " (acts in motion only: not in the still-segment error)";
    lines.push_back(text);
  }
  for (const Notice& note : notes) lines.push_back("  note: " + note.message);
  return lines;
}

}  // namespace plumb::exporter

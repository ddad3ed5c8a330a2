// plumb/paper/evaluation.cc — see evaluation.h.
#include "plumb/paper/evaluation.h"

#include <Eigen/LU>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "plumb/core/error.h"
#include "plumb/core/units.h"

namespace plumb::paper {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <typename T>
Compared<T> Compare(const T& benchmark, const T& proposed) {
  Compared<T> c;
  c.benchmark = benchmark;
  c.proposed = proposed;
  for (Eigen::Index i = 0; i < benchmark.size(); ++i) {
    c.error_pct.data()[i] = PercentError(proposed.data()[i], benchmark.data()[i]);
  }
  return c;
}

std::string Canonical(const std::string& name) {
  std::string out;
  for (char c : name) {
    if (c == '-' || c == '_' || c == ' ') continue;
    out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

bool Within(double value, double limit) { return std::isnan(limit) || std::abs(value) <= limit; }

/// Linear part applied to samples: x = A^-1 (y - b - d (t - t0)); NaN when A is singular.
struct Inverse {
  Mat3 A_inv = Mat3::Zero();
  bool ok = false;
};

Inverse Invert(const Mat3& A) {
  Inverse inv;
  Eigen::FullPivLU<Mat3> lu(A);
  inv.ok = lu.isInvertible() && std::abs(A.determinant()) > 1e-12 * std::pow(A.norm(), 3);
  if (inv.ok) inv.A_inv = lu.inverse();
  return inv;
}

}  // namespace

double PercentError(double proposed, double benchmark) {
  if (!std::isfinite(proposed) || !std::isfinite(benchmark) || benchmark == 0.0) return kNaN;
  return 100.0 * (proposed - benchmark) / std::abs(benchmark);
}

PaperTables MakePaperTables(const PaperBenchmarkResult& benchmark,
                            const PaperStaticResult& proposed) {
  PaperTables t;
  t.accel_bias = Compare(benchmark.accel_bias, proposed.accel.bias);
  t.accel_coupling = Compare(benchmark.accel_coupling_paper, proposed.accel.F_paper);
  t.has_gyro = proposed.has_gyro;
  if (t.has_gyro) {
    t.gyro_bias = Compare(benchmark.gyro_bias_b0, proposed.gyro.bias);
    t.gyro_bias_b1_benchmark = benchmark.gyro_bias_b1;
    t.gyro_coupling = Compare(benchmark.gyro_coupling_paper, proposed.gyro.E_paper);
  }
  return t;
}

const std::vector<PartLimits>& KnownParts() {
  // Figures as the datasheets print them (deg/s, %, mg), converted to SI here.
  auto part = [](const char* name, double gyro_zro_deg_s, double gyro_scale_pct,
                 double gyro_cross_pct, double accel_xy_mg, double accel_z_mg,
                 double accel_scale_pct, double accel_cross_pct, const char* source) {
    return PartLimits{name,
                      gyro_zro_deg_s * units::kRadPerDeg,
                      gyro_scale_pct / 100.0,
                      gyro_cross_pct / 100.0,
                      accel_xy_mg * units::kMilliG,
                      accel_z_mg * units::kMilliG,
                      accel_scale_pct / 100.0,
                      accel_cross_pct / 100.0,
                      source};
  };
  static const std::vector<PartLimits> parts = {
      part("MPU-6000", 20.0, 3.0, 2.0, 50.0, 80.0, 3.0, 2.0,
           "InvenSense MPU-6000/MPU-6050 Product Specification rev. 3.4, tables 6.1 and 6.2 "
           "(the paper's Table 5, ref. [12])"),
      part("MPU-9250", 5.0, 3.0, 2.0, 60.0, 80.0, 3.0, 2.0,
           "InvenSense MPU-9250 Product Specification PS-MPU-9250A-01 rev. 1.0, tables 1 and 2 "
           "(typical, component level)"),
      part("ICM-42688-P", 0.5, 0.5, 1.25, 20.0, 20.0, 0.5, 1.0,
           "TDK InvenSense ICM-42688-P datasheet DS-000347 rev. 1.2/1.8, tables 1 and 2 "
           "(typical; offsets and cross-axis board level, from characterisation)")};
  return parts;
}

const PartLimits& FindPart(const std::string& name) {
  const std::string want = Canonical(name);
  std::string known;
  for (const PartLimits& p : KnownParts()) {
    if (Canonical(p.name) == want) return p;
    known += (known.empty() ? "" : ", ") + p.name;
  }
  throw Error("unknown part '" + name + "'; known: " + known);
}

std::vector<LimitCheck> CheckDatasheet(const PartLimits& part, const Mat3& F, const Vec3& b_a,
                                       const Mat3& E, const Vec3& b_g, bool has_gyro) {
  std::vector<LimitCheck> out;
  auto add = [&](const std::string& quantity, double value, double limit) {
    out.push_back({quantity, std::abs(value), limit, Within(value, limit)});
  };
  auto matrix = [&](const std::string& sensor, const Mat3& M, double scale, double cross) {
    for (int i = 0; i < 3; ++i) {
      add(sensor + " scale " + kAxisName[i], M(i, i) - 1.0, scale);
    }
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        if (i == j) continue;
        add(sensor + " cross-axis " + kAxisName[i] + kAxisName[j],
            M(i, i) != 0.0 ? M(i, j) / M(i, i) : kNaN, cross);
      }
    }
  };
  for (int i = 0; i < 3; ++i) {
    add(std::string("accel.bias.") + kAxisName[i], b_a[i],
        i < 2 ? part.accel_bias_xy_m_s2 : part.accel_bias_z_m_s2);
  }
  matrix("accel", F, part.accel_scale, part.accel_cross_axis);
  if (has_gyro) {
    for (int i = 0; i < 3; ++i) {
      add(std::string("gyro.bias.") + kAxisName[i], b_g[i], part.gyro_bias_rad_s);
    }
    matrix("gyro", E, part.gyro_scale, part.gyro_cross_axis);
  }
  return out;
}

ReconstructedInputs ReconstructInputs(const ImuSeries& series,
                                      const PaperBenchmarkResult& benchmark,
                                      const PaperStaticResult& proposed, std::size_t stride) {
  if (stride < 1) throw Error("ReconstructInputs: stride must be >= 1");
  ReconstructedInputs r;
  const Inverse Fb = Invert(benchmark.F), Fp = Invert(proposed.F);
  const Inverse Eb = Invert(benchmark.E), Ep = Invert(proposed.E);
  const bool gyro = series.has_gyro() && proposed.has_gyro;
  auto singular = [&](const Inverse& inv, const std::string& what) {
    if (!inv.ok) r.notes.push_back(what + " is singular: its reconstructed inputs are NaN");
  };
  singular(Fb, "the benchmark F");
  singular(Fp, "the proposed F");
  if (gyro) {
    singular(Eb, "the benchmark E");
    singular(Ep, "the proposed E");
  }
  const Vec3 nan3 = Vec3::Constant(kNaN);
  Vec3 ss_f = Vec3::Zero(), ss_w = Vec3::Zero();
  std::size_t n = 0;
  for (std::size_t k = 0; k < series.size(); k += stride) {
    const Vec3 ya = series.acc[k].cast<double>();
    r.t_s.push_back(series.t_s[k]);
    r.f_benchmark.push_back(Fb.ok ? Vec3(Fb.A_inv * (ya - benchmark.b_a)) : nan3);
    r.f_proposed.push_back(Fp.ok ? Vec3(Fp.A_inv * (ya - proposed.b_a)) : nan3);
    ss_f += (r.f_proposed.back() - r.f_benchmark.back()).cwiseAbs2();
    if (gyro) {
      const Vec3 yg = series.gyr[k].cast<double>();
      const Vec3 bias_b =
          benchmark.b_g + benchmark.gyro_bias_drift * (series.t_s[k] - benchmark.t0_s);
      r.omega_benchmark.push_back(Eb.ok ? Vec3(Eb.A_inv * (yg - bias_b)) : nan3);
      r.omega_proposed.push_back(Ep.ok ? Vec3(Ep.A_inv * (yg - proposed.b_g)) : nan3);
      ss_w += (r.omega_proposed.back() - r.omega_benchmark.back()).cwiseAbs2();
    }
    ++n;
  }
  if (n > 0) {
    r.rms_f_difference = (ss_f / static_cast<double>(n)).cwiseSqrt();
    r.rms_omega_difference = gyro ? Vec3((ss_w / static_cast<double>(n)).cwiseSqrt()) : nan3;
  }
  return r;
}

}  // namespace plumb::paper

// Helpers for the report tests: a hand-made CalibrationResult with known values (so that the
// JSON can be checked key by key without running a fit), and a private temporary folder.
#pragma once

#include "support/temp_dir.h"

#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include "plumb/estimation/result.h"
#include "plumb/model/model.h"

namespace plumb::report::testing {

/// A result of model base+gyro_g_sensitivity: every parameter observable with sigma 1e-3
/// except accel.bias.z (unobservable) and gyro_g_sensitivity.G.zz (fixed); no site; two still
/// segments (the first with a known attitude) and one motion interval; dof = 0, so chi2/dof
/// is NaN.
inline estimation::CalibrationResult MakeResult() {
  estimation::CalibrationResult r;
  r.calibration.model = model::Model::Parse("base+gyro_g_sensitivity");
  r.calibration.model.t_ref_s = 100.0;
  r.calibration.has_gyro = true;
  const auto names = r.calibration.model.ParameterNames();
  for (std::size_t i = 0; i < names.size(); ++i) {
    estimation::ParameterEstimate p;
    p.name = names[i];
    const auto where = *r.calibration.model.FindParameter(names[i]);
    p.place = {where.first, where.second};
    p.unit = "u" + std::to_string(i);
    p.value = 0.01 * static_cast<double>(i);
    p.sigma = 1e-3;
    if (p.name == "accel.bias.z") {
      p.observable = false;
      p.sigma = std::numeric_limits<double>::quiet_NaN();
    }
    if (p.name == "gyro_g_sensitivity.G.zz") {
      p.fixed = true;
      p.sigma = std::numeric_limits<double>::quiet_NaN();
    }
    r.calibration.parameters.push_back(p);
  }
  // F = [1.01 0.02 0.03; 0 0.98 -0.01; 0 0 1.02], b_a = (0.1, -0.2, 0.3); E = [1.001 0.002
  // -0.003; 0.004 0.995 0.001; -0.002 0.003 1.004], b_g = (0.01, 0.02, -0.03): the blocks of
  // accel_linear and gyro_linear hold F - I and E - I (model/effects/*_linear.h).
  r.calibration.theta = r.calibration.model.ZeroParameters();
  r.calibration.theta[0] = {0.01, 0.02, 0.03, -0.02, -0.01, 0.02, 0.1, -0.2, 0.3};
  r.calibration.theta[1] = {0.001, 0.002, -0.003, 0.004, -0.005, 0.001, -0.002, 0.003, 0.004,
                            0.01,  0.02,  -0.03};
  r.fit.chi2 = 12.5;
  r.fit.dof = 0;
  r.fit.num_residuals = 18;
  r.fit.still_segments = 2;
  r.fit.motion_segments = 1;
  r.fit.converged = true;
  r.fit.iterations = 7;
  r.calibration.observability.rank = 40;
  r.calibration.observability.num_unknowns = 41;
  r.calibration.observability.unobservable = {"9.81 accel.bias.z + 1 accel.matrix.zz"};
  r.calibration.observability.determined = {{"accel.bias.z - 9.81 accel.matrix.zz", 0.5, 0.01}};
  r.calibration.site = geo::Site::Unknown();
  for (int k = 0; k < 2; ++k) {
    estimation::StillSegmentFit s;
    s.segment.begin = static_cast<std::size_t>(100 * k);
    s.segment.end = s.segment.begin + 50;
    s.segment.label = "pose " + std::to_string(k + 1);
    s.t_mid_s = 100.25 + k;
    s.acc_residual = Vec3(1e-3, -2e-3, 3e-3);
    s.gyr_residual = Vec3(1e-5, 2e-5, -3e-5);
    s.acc_whitened = Vec3(0.5, -1.0, 1.5);
    s.gyr_whitened = Vec3(0.1, 0.2, -0.3);
    s.R_n_b = Quat(Eigen::AngleAxisd(0.5 * k, Vec3::UnitZ()));
    s.attitude_known = k == 0;
    r.fit.still.push_back(s);
  }
  estimation::MotionFit m;
  m.from = 0;
  m.to = 1;
  m.duration_s = 2.5;
  m.rotation_residual = Vec3(1e-4, 0, -1e-4);
  m.whitened = Vec3(0.3, 0, -0.3);
  r.fit.motion.push_back(m);
  r.calibration.noise.acc = Vec3(0.01, 0.01, 0.012);
  r.calibration.noise.gyr = Vec3(7e-4, 7e-4, 8e-4);
  r.fit.warnings = {Notice{"site_unknown", "no site given", {Option::kSite}}};
  return r;
}

using ::plumb::testing::TempDir;

}  // namespace plumb::report::testing

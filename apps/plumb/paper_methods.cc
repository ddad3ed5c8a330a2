// apps/plumb/paper_methods.cc — see paper_methods.h.
#include "paper_methods.h"

#include <iomanip>
#include <map>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "fit_options.h"
#include "plumb/core/error.h"
#include "plumb/core/units.h"
#include "plumb/paper/backend.h"
#include "plumb/paper/static_procedure.h"
#include "plumb/report/json_report.h"
#include "plumb/report/summary.h"
#include "json_output.h"

namespace plumb::cli {
namespace {

nlohmann::json ToJson(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
nlohmann::json ToJson(const Mat3& m) {
  return {{m(0, 0), m(0, 1), m(0, 2)}, {m(1, 0), m(1, 1), m(1, 2)}, {m(2, 0), m(2, 1), m(2, 2)}};
}

std::string Row(const Eigen::RowVector3d& r) {
  std::ostringstream out;
  out << std::setprecision(6) << std::showpos << std::scientific;
  out << "[" << r(0) << " " << r(1) << " " << r(2) << "]";
  return out.str();
}

void PrintMatrix(const std::string& name, const Mat3& m) {
  std::cout << "  " << name << "\n";
  for (int i = 0; i < 3; ++i) std::cout << "    " << Row(m.row(i)) << "\n";
}

void PrintVector(const std::string& name, const Vec3& v) {
  std::cout << "  " << name << " " << Row(v.transpose()) << "\n";
}

void Finish(const nlohmann::json& doc, const std::vector<Notice>& notes,
            const std::string& json_path) {
  for (const Notice& n : notes) std::cout << "note: " << n.message << "\n";
  if (!json_path.empty()) {
    WriteJsonOutput(json_path, doc);
  }
}

/// Every forward quantity of a closed form by plumb's parameter name (accel.matrix.xy = F(x, y),
/// ...), the gyroscope's only when `gyro`.
std::map<std::string, double> ForwardValues(const Mat3& F, const Vec3& b_a, bool gyro,
                                            const Mat3& E, const Vec3& b_g) {
  std::map<std::string, double> v;
  const char* axis = "xyz";
  for (int i = 0; i < 3; ++i) {
    v[std::string("accel.bias.") + axis[i]] = b_a(i);
    if (gyro) v[std::string("gyro.bias.") + axis[i]] = b_g(i);
    for (int j = 0; j < 3; ++j) {
      const std::string ij = std::string(1, axis[i]) + axis[j];
      v["accel.matrix." + ij] = F(i, j);
      if (gyro) v["gyro.matrix." + ij] = E(i, j);
    }
  }
  return v;
}

/// The headline of a paper method's document (SPEC section 6): its configuration's result on
/// the backend with every parameter's value replaced by the closed form's (`values`, by name),
/// so that accel, gyro, effects and parameters are the closed form's answer, and sigma,
/// covariance, fit and observability the backend's on the same data (the closed form has no
/// noise model). A closed-form value of a parameter the model does not have must be 0 (the
/// lower triangle of an upper-triangular F); anything else is a programming error.
estimation::CalibrationResult ClosedFormHeadline(estimation::CalibrationResult r,
                                                 const std::map<std::string, double>& values,
                                                 const std::string& method) {
  estimation::Calibration& c = r.calibration;
  c.method = method;
  for (estimation::ParameterEstimate& p : c.parameters) {
    const auto value = values.find(p.name);
    const auto where = c.model.FindParameter(p.name);
    if (value == values.end() || !where) {
      throw Error(method + ": the closed form has no value for " + p.name);
    }
    const auto [t, i] = *where;
    const double nominal = c.model.terms()[static_cast<std::size_t>(t)]
                               .effect->info().parameters[static_cast<std::size_t>(i)].nominal;
    c.theta[static_cast<std::size_t>(t)][static_cast<std::size_t>(i)] = value->second - nominal;
    p.value = value->second;
  }
  for (const auto& [name, value] : values) {
    const bool gyro_dropped = !c.has_gyro && name.rfind("gyro", 0) == 0;
    if (!c.model.FindParameter(name) && !gyro_dropped && value != 0.0) {
      throw Error(method + ": the closed form's " + name + " is not in the model " +
                  c.model.spec());
    }
  }
  return r;
}

/// The document of a paper method: the keys of every calibrate document for the closed
/// form's answer (ClosedFormHeadline), marked where they are the backend's ("source"), with
/// the method's own detail (`detail`, its "backend" among them) under the method's name.
nlohmann::json PaperDocument(const estimation::CalibrationResult& headline,
                             const nlohmann::json& detail, const std::vector<Notice>& notes,
                             const Session& session, const std::vector<std::string>& inputs) {
  nlohmann::json doc = report::ToJson(headline);
  const std::string source = "backend";
  doc["covariance"]["source"] = source;
  doc["fit"]["source"] = source;
  doc["observability"]["source"] = source;
  // The still segments' data stay; their residuals and attitudes are the backend's fit, in
  // the method's "backend" document, as are the turns.
  for (nlohmann::json& s : doc["segments"]) {
    for (const char* key : {"acc_residual", "gyr_residual", "acc_whitened", "gyr_whitened",
                            "attitude_quaternion_wxyz", "attitude_known", "acc_walk", "gyr_walk"}) {
      s.erase(key);
    }
  }
  doc.erase("motion");
  doc["notes"] = Messages(notes);
  doc["notes"].push_back(
      "accel, gyro, effects and parameters values are the closed form's; sigma, covariance, "
      "fit, observability and gates are those of the same procedure on the backend (\"" +
      headline.calibration.method + "\".backend): the closed form has no noise model, and it "
      "uses the same means without weighting them, so its own uncertainty is not smaller");
  std::vector<std::string> warnings = Messages(session.warnings);
  for (const Notice& w : headline.fit.warnings) warnings.push_back(w.message);
  doc["warnings"] = warnings;
  doc["inputs"] = inputs;
  doc[headline.calibration.method] = detail;
  return doc;
}

}  // namespace

int RunPaperBenchmark(const Session& session, const std::vector<StillSegment>& still,
                      const std::vector<paper::MotionRange>& motion, const geo::Site& site,
                      const std::vector<std::string>& inputs, const std::string& json_path,
                      bool strict) {
  paper::PaperBenchmarkOptions options;
  options.gravity_m_s2 = site.gravity();
  const paper::PaperBenchmarkResult r =
      paper::CalibratePaperBenchmark(session.series, still, motion, options);
  const std::string au = session.series.acc_unit;
  const std::string gu = session.series.gyr_unit;

  std::cout << "paper-benchmark (the paper's section 4): " << r.still.size()
            << " still periods, " << r.turns.size() << " turns\n";
  for (int j = 0; j < 3; ++j) {
    std::cout << "  " << kAxisName[j] << " parallel: '"
              << r.still[r.parallel_index[j]].segment.label << "', antiparallel: '"
              << r.still[r.antiparallel_index[j]].segment.label << "', turns total "
              << r.total_angle_rad[j] * 180.0 / units::kPi << " deg\n";
  }
  std::cout << "Paper's convention (a_s = F a_p + b, a_p the gravity vector):\n";
  PrintVector("accelerometer bias, Eq. (3), " + au + ":", r.accel_bias);
  std::cout << "  Q, Eq. (4): " << r.Q << " " << au << "\n";
  PrintMatrix("accelerometer coupling (U+ - U-) / (2 Q):", r.accel_coupling_paper);
  PrintVector("gyroscope bias b0, Eq. (5), " + gu + ":", r.gyro_bias_b0);
  PrintVector("gyroscope bias b1, Eq. (5), " + gu + "/s:", r.gyro_bias_b1);
  PrintMatrix("gyroscope coupling (integrated output / total angle):", r.gyro_coupling_paper);
  std::cout << "Forward convention (y_a = F f_b + b_a, y_g = E omega_b + b_g + d_g (t - t0)), "
               "g = " << r.gravity_m_s2 << " m/s^2:\n";
  PrintMatrix("accel.matrix F = -(U+ - U-) / (2 g):", r.F);
  PrintVector("accel.bias, " + au + ":", r.b_a);
  PrintMatrix("gyro.matrix E:", r.E);
  PrintVector("gyro.bias (at the first sample), " + gu + ":", r.b_g);
  PrintVector("gyro_bias_drift.d, " + gu + "/s:", r.gyro_bias_drift);

  nlohmann::json detail;
  detail["paper_convention"] = {
      {"accel", {{"bias", ToJson(r.accel_bias)}, {"U_plus", ToJson(r.U_plus)},
                 {"U_minus", ToJson(r.U_minus)}, {"Q", r.Q},
                 {"coupling", ToJson(r.accel_coupling_paper)}}},
      {"gyro", {{"bias_b0", ToJson(r.gyro_bias_b0)}, {"bias_b1", ToJson(r.gyro_bias_b1)},
                {"t0_s", r.t0_s}, {"coupling", ToJson(r.gyro_coupling_paper)},
                {"total_angle_rad", ToJson(r.total_angle_rad)}}}};
  detail["gravity"] = r.gravity_m_s2;
  detail["notes"] = Messages(r.notes);

  std::cout << "\nThe same procedure on the backend (the faces' tilts known, headings estimated; "
               "turns at their known mean rate; model "
            << "accel_linear:full+gyro_linear+gyro_bias_drift):\n";
  const paper::PaperBenchmarkBackend backend =
      paper::CalibratePaperBenchmarkOnBackend(session.series, r, site);
  std::cout << report::CalibrationSummary(backend.result, session.source);
  PrintWarnings(backend.result.fit.warnings);
  detail["backend"] = report::ToJson(backend.result);
  std::map<std::string, double> values = ForwardValues(r.F, r.b_a, true, r.E, r.b_g);
  for (int i = 0; i < 3; ++i) {
    values[std::string("gyro_bias_drift.d.") + "xyz"[i]] = r.gyro_bias_drift(i);
  }
  estimation::CalibrationResult headline = ClosedFormHeadline(backend.result, values, "paper-benchmark");
  headline.calibration.model.t_ref_s = r.t0_s;  // Eq. (5)'s origin: the drift is zero there
  const nlohmann::json doc = PaperDocument(headline, detail, r.notes, session, inputs);
  if (const int code = StrictGateExit(backend.result.fit, session.source, strict)) return code;
  Finish(doc, r.notes, json_path);
  return 0;
}

int RunPaperStatic(const Session& session, std::size_t begin, std::size_t end,
                   const geo::Site& site, const std::vector<std::string>& inputs,
                   const std::string& json_path, bool strict) {
  const paper::PaperStaticResult r =
      paper::CalibratePaperStatic(session.series, begin, end, site, paper::PaperStaticOptions{});
  const std::string au = session.series.acc_unit;
  const std::string gu = session.series.gyr_unit;
  std::cout << "paper-static (the paper's section 5): samples [" << begin << ", " << end
            << "), " << r.rate_hz << " Hz, 0.5 Hz Butterworth high-pass\n";
  std::cout << "Paper's convention (a_s = F a_p + b, a_p the gravity vector):\n";
  PrintVector("accelerometer mean (step 1), " + au + ":", r.accel.mean);
  std::cout << "  g = |mean| (steps 2, 7): " << r.accel.norm << " " << au << "\n";
  PrintVector("high-passed mean R_f (step 5):", r.accel.filtered_mean);
  PrintVector("accelerometer bias (step 6), " + au + ":", r.accel.bias);
  PrintMatrix("accelerometer F (steps 8-10):", r.accel.F_paper);
  if (r.has_gyro) {
    PrintVector("gyroscope high-passed mean R_f (step 3):", r.gyro.filtered_mean);
    PrintVector("gyroscope bias (step 4), " + gu + ":", r.gyro.bias);
    PrintVector("omega_p = C_ecef^ned omega_e (step 6), rad/s:", r.gyro.omega_p);
    PrintMatrix("gyroscope E (steps 5-7):", r.gyro.E_paper);
  }
  std::cout << "Forward convention (y_a = F f_b + b_a, y_g = E omega_b + b_g):\n";
  PrintMatrix("accel.matrix F = -F_paper:", r.F);
  PrintVector("accel.bias, " + au + ":", r.b_a);
  if (r.has_gyro) {
    PrintMatrix("gyro.matrix E:", r.E);
    PrintVector("gyro.bias, " + gu + ":", r.b_g);
  }

  nlohmann::json detail;
  detail["paper_convention"]["accel"] = {
      {"mean", ToJson(r.accel.mean)}, {"g", r.accel.norm},
      {"filtered_mean", ToJson(r.accel.filtered_mean)}, {"bias", ToJson(r.accel.bias)},
      {"matrix", ToJson(r.accel.F_paper)}};
  if (r.has_gyro) {
    detail["paper_convention"]["gyro"] = {
        {"mean", ToJson(r.gyro.mean)}, {"filtered_mean", ToJson(r.gyro.filtered_mean)},
        {"bias", ToJson(r.gyro.bias)}, {"omega_p", ToJson(r.gyro.omega_p)},
        {"matrix", ToJson(r.gyro.E_paper)}};
  }
  detail["samples"] = {begin, end};
  detail["notes"] = Messages(r.notes);

  std::cout << "\nThe same procedure on the backend (one segment, attitude known level x north; "
               "the paper's constants held):\n";
  const paper::PaperStaticBackend backend =
      paper::CalibratePaperStaticOnBackend(session.series, begin, end, site);
  std::cout << report::CalibrationSummary(backend.fixed, session.source);
  PrintWarnings(backend.fixed.fit.warnings);
  auto join = [](const std::vector<std::string>& names) {
    std::string out;
    for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
    return out.empty() ? std::string("none") : out;
  };
  std::cout << "The paper's fixed constants, freed on the same data: unobservable: "
            << join(backend.fixed_unobservable)
            << "; observable: " << join(backend.fixed_observable) << "\n";
  detail["backend"] = report::ToJson(backend.fixed);
  detail["backend_freed"] = {{"unobservable", backend.fixed_unobservable},
                             {"observable", backend.fixed_observable},
                             {"result", report::ToJson(backend.freed)}};
  const estimation::CalibrationResult headline = ClosedFormHeadline(
      backend.fixed, ForwardValues(r.F, r.b_a, r.has_gyro, r.E, r.b_g), "paper-static");
  const nlohmann::json doc = PaperDocument(headline, detail, r.notes, session, inputs);
  if (const int code = StrictGateExit(backend.fixed.fit, session.source, strict)) return code;
  Finish(doc, r.notes, json_path);
  return 0;
}

}  // namespace plumb::cli

// apps/plumb/paper_methods.cc — see paper_methods.h.
#include "paper_methods.h"

#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commands.h"
#include "fit_options.h"
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

void Finish(const nlohmann::json& doc, const std::vector<std::string>& notes,
            const std::string& json_path) {
  for (const auto& n : notes) std::cout << "note: " << n << "\n";
  if (!json_path.empty()) {
    WriteJsonOutput(json_path, doc);
  }
}

/// The keys every calibrate document has (SPEC section 6): the schema version, and the
/// covariance and gates of the method's configuration of the backend (the closed forms have
/// none), the same as under "backend".
void AddSchema(nlohmann::json& doc, const estimation::CalibrationResult& backend) {
  doc["schema_version"] = report::kSchemaVersion;
  doc["covariance"] = report::CovarianceJson(backend);
  doc["covariance"]["source"] = "backend";
  doc["gates"] = report::GatesJson(backend.fit);
}

}  // namespace

int RunPaperBenchmark(const Session& session, const std::vector<StillSegment>& still,
                      const std::vector<paper::MotionRange>& motion, const geo::Site& site,
                      const std::string& json_path, bool strict) {
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

  nlohmann::json doc;
  doc["method"] = "paper-benchmark";
  doc["paper_convention"] = {
      {"accel", {{"bias", ToJson(r.accel_bias)}, {"U_plus", ToJson(r.U_plus)},
                 {"U_minus", ToJson(r.U_minus)}, {"Q", r.Q},
                 {"coupling", ToJson(r.accel_coupling_paper)}}},
      {"gyro", {{"bias_b0", ToJson(r.gyro_bias_b0)}, {"bias_b1", ToJson(r.gyro_bias_b1)},
                {"t0_s", r.t0_s}, {"coupling", ToJson(r.gyro_coupling_paper)},
                {"total_angle_rad", ToJson(r.total_angle_rad)}}}};
  doc["forward"] = {
      {"accel", {{"matrix", ToJson(r.F)}, {"bias", ToJson(r.b_a)}}},
      {"gyro", {{"matrix", ToJson(r.E)}, {"bias", ToJson(r.b_g)},
                {"bias_drift", ToJson(r.gyro_bias_drift)}, {"t_ref_s", r.t0_s}}},
      {"gravity", r.gravity_m_s2}};
  doc["notes"] = r.notes;

  std::cout << "\nThe same procedure on the backend (the faces' tilts known, headings estimated; "
               "turns at their known mean rate; model "
            << "accel_linear:full+gyro_linear+gyro_bias_drift):\n";
  const paper::PaperBenchmarkBackend backend =
      paper::CalibratePaperBenchmarkOnBackend(session.series, r, site);
  std::cout << report::CalibrationSummary(backend.result, session.source);
  doc["backend"] = report::ToJson(backend.result);
  AddSchema(doc, backend.result);
  if (const int code = StrictGateExit(backend.result.fit, session.source, strict)) return code;
  Finish(doc, r.notes, json_path);
  return 0;
}

int RunPaperStatic(const Session& session, std::size_t begin, std::size_t end,
                   const geo::Site& site, const std::string& json_path, bool strict) {
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

  nlohmann::json doc;
  doc["method"] = "paper-static";
  doc["paper_convention"]["accel"] = {
      {"mean", ToJson(r.accel.mean)}, {"g", r.accel.norm},
      {"filtered_mean", ToJson(r.accel.filtered_mean)}, {"bias", ToJson(r.accel.bias)},
      {"matrix", ToJson(r.accel.F_paper)}};
  doc["forward"]["accel"] = {{"matrix", ToJson(r.F)}, {"bias", ToJson(r.b_a)}};
  if (r.has_gyro) {
    doc["paper_convention"]["gyro"] = {
        {"mean", ToJson(r.gyro.mean)}, {"filtered_mean", ToJson(r.gyro.filtered_mean)},
        {"bias", ToJson(r.gyro.bias)}, {"omega_p", ToJson(r.gyro.omega_p)},
        {"matrix", ToJson(r.gyro.E_paper)}};
    doc["forward"]["gyro"] = {{"matrix", ToJson(r.E)}, {"bias", ToJson(r.b_g)}};
  }
  doc["site"] = {{"lat_deg", site.lat_deg}, {"lon_deg", site.lon_deg},
                 {"height_m", site.height_m}, {"source", site.source}};
  doc["notes"] = r.notes;

  std::cout << "\nThe same procedure on the backend (one segment, attitude known level x north; "
               "the paper's constants held):\n";
  const paper::PaperStaticBackend backend =
      paper::CalibratePaperStaticOnBackend(session.series, begin, end, site);
  std::cout << report::CalibrationSummary(backend.fixed, session.source);
  auto join = [](const std::vector<std::string>& names) {
    std::string out;
    for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
    return out.empty() ? std::string("none") : out;
  };
  std::cout << "The paper's fixed constants, freed on the same data: unobservable: "
            << join(backend.fixed_unobservable)
            << "; observable: " << join(backend.fixed_observable) << "\n";
  doc["backend"] = report::ToJson(backend.fixed);
  doc["backend_freed"] = {{"unobservable", backend.fixed_unobservable},
                          {"observable", backend.fixed_observable},
                          {"result", report::ToJson(backend.freed)}};
  AddSchema(doc, backend.fixed);
  if (const int code = StrictGateExit(backend.fixed.fit, session.source, strict)) return code;
  Finish(doc, r.notes, json_path);
  return 0;
}

}  // namespace plumb::cli

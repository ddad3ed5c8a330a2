// plumb.diagnose(session, model=..., **options) -> Diagnosis: which catalogue effects the model
// misses, as `plumb diagnose` finds them; Diagnosis.to_json() is its --json document.
#include <pybind11/stl.h>

#include "common.h"
#include "plumb/core/error.h"
#include "plumb/diagnostics/diagnose.h"
#include "plumb/diagnostics/residual_analysis.h"
#include "plumb/report/diagnosis_json.h"
#include "plumb/report/json_report.h"
#include "plumb/report/time_base_text.h"
#include "plumb/signal/time_base.h"

namespace plumb::python {
namespace {

const char* const kDiagnoseDoc = R"doc(Find which effects of the catalogue the model is missing:
the score test of every effect not in the model, ranked by evidence, the best confirmed by
refitting (`plumb diagnose`).

session: a Session; model: the spec diagnosed ('base'); site: as in calibrate().
Keywords: significance (0.01: the test's level), confirm (3: refit the best N significant
candidates), candidates (list of effect names, default: the catalogue); segments, init_still,
window, min_still, false_alarm, still_accel_only, gravity, heading (deg), temp_ref (degC).
Returns a Diagnosis; the diagnosed fit's warnings are also emitted as plumb.PlumbWarning.)doc";

struct PyDiagnosis {
  nlohmann::json document;  ///< report::DiagnosisJson
};

std::shared_ptr<PyDiagnosis> Diagnose(const PySession& s, const std::string& model,
                                      const py::object& site, const py::kwargs& kwargs) {
  Keywords k("diagnose", kwargs);
  FitInputs fit = PrepareFit(s, model, site, k, false);
  diagnostics::DiagnoseOptions options;
  options.significance = k.Take<double>("significance", options.significance);
  options.confirm = k.Take<int>("confirm", options.confirm);
  options.candidates = k.Take<std::vector<std::string>>("candidates", {});
  k.Finish();
  if (!(options.significance >= 1e-12 && options.significance <= 0.5)) {
    throw Error("diagnose: significance must be in [1e-12, 0.5]");
  }
  if (options.confirm < 0) throw Error("diagnose: confirm must be >= 0");
  options.calibration = fit.setup.options;
  options.calibration.method = "generalized";
  auto out = std::make_shared<PyDiagnosis>();
  py::gil_scoped_release release;
  const diagnostics::Diagnosis d =
      diagnostics::Diagnose(s.session.series, fit.setup.segments, fit.setup.model,
                            fit.setup.site, options);
  diagnostics::ResidualAnalysisOptions ra_options;
  ra_options.significance = options.significance;
  const diagnostics::ResidualAnalysis ra =
      diagnostics::AnalyseResiduals(s.session.series, d.fit, ra_options);
  out->document = report::DiagnosisJson(d, ra);
  out->document["time_base"] = report::TimeBaseJson(signal::AnalyseTimeBase(s.session.series.t_s));
  py::gil_scoped_acquire acquire;
  Warn(std::vector<Notice>(fit.setup.input_warnings.begin() +
                               static_cast<std::ptrdiff_t>(s.session.warnings.size()),
                           fit.setup.input_warnings.end()));
  Warn(d.fit.fit.warnings);
  return out;
}

/// "<plumb.Diagnosis base: chi2/dof 1.29, 12 candidates, 0 significant; recommendation:
/// none>".
std::string Repr(const PyDiagnosis& d) {
  const nlohmann::json& doc = d.document;
  std::size_t significant = 0;
  const nlohmann::json candidates = doc.value("candidates", nlohmann::json::array());
  for (const auto& c : candidates) significant += c.value("significant", false) ? 1 : 0;
  const nlohmann::json& fit = doc.contains("fit") ? doc["fit"] : nlohmann::json::object();
  const nlohmann::json chi2_dof = fit.value("chi2_dof", nlohmann::json());
  const nlohmann::json recommendation = doc.value("recommendation", nlohmann::json());
  return "<plumb.Diagnosis " + doc.value("model", std::string("?")) + ": chi2/dof " +
         (chi2_dof.is_number() ? Number(chi2_dof.get<double>()) : std::string("n/a")) + ", " +
         std::to_string(candidates.size()) + " candidates, " + std::to_string(significant) +
         " significant; recommendation: " +
         (recommendation.is_string() ? recommendation.get<std::string>() : std::string("none")) +
         ">";
}

}  // namespace

void RegisterDiagnose(py::module_& m) {
  py::class_<PyDiagnosis, std::shared_ptr<PyDiagnosis>> diagnosis(
      m, "Diagnosis", "What `plumb diagnose --json` writes, as Python objects.");
  DocumentMethods(diagnosis, "diagnose")
      .def_property_readonly("candidates",
                             [](const PyDiagnosis& d) { return ToPython(d.document["candidates"]); },
                             "The effects tested, best evidence first: effect, lm (predicted "
                             "fall of chi2), dof, evidence, significant, predicted_drop, "
                             "refit_drop, identifiable, recommended (its refit lowers the "
                             "chi2/dof of the diagnosed fit) ...")
      .def_property_readonly("recommendation",
                             [](const PyDiagnosis& d) { return ToPython(d.document["recommendation"]); },
                             "The model spec to fit next (the best recommended candidate added), "
                             "or None when no candidate lowers the fit's chi2/dof")
      .def_property_readonly("fit", [](const PyDiagnosis& d) { return ToPython(d.document["fit"]); },
                             "The diagnosed model's fit: chi2, dof, ...")
      .def("__repr__", &Repr)
      .def(py::pickle(
          [](const PyDiagnosis& d) {
            // CBOR keeps every number as it is (NaN included), so that to_json() is unchanged.
            const auto bytes = nlohmann::json::to_cbor(d.document);
            return py::make_tuple(1, py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
          },
          [](const py::tuple& t) {
            if (t.size() != 2 || t[0].cast<int>() != 1) {
              throw Error("Diagnosis: a pickled state of another version of plumb");
            }
            auto out = std::make_shared<PyDiagnosis>();
            const std::string cbor = t[1].cast<std::string>();
            out->document = nlohmann::json::from_cbor(cbor.begin(), cbor.end());
            return out;
          }));
  m.def("diagnose", &Diagnose, py::arg("session"), py::arg("model") = "base",
        py::arg("site") = py::none(), kDiagnoseDoc);
}

}  // namespace plumb::python

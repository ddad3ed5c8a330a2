// plumb.sweep_point(study, index) -> dict: one point of a sensitivity study run as `plumb sweep`
// runs it (every Monte Carlo run of the point, summarised), returning the document the command
// writes to DIR/points/point-NNNNN.json; sweep_point_json gives its text byte for byte, so that
// points run elsewhere (a cluster) and written with it merge with `plumb sweep merge`.
#include <pybind11/stl.h>

#include <filesystem>

#include "common.h"
#include "plumb/core/error.h"
#include "plumb/io/text/json_file.h"
#include "plumb/pipeline/study_template.h"
#include "plumb/report/json_report.h"
#include "plumb/study/run.h"
#include "plumb/study/study.h"
#include "plumb/study/study_file.h"
#include "plumb/study/summary.h"

namespace plumb::python {
namespace {

namespace fs = std::filesystem;

const char* const kStudyArg =
    "study: a study file's path, JSON or YAML (.yaml, .yml) as plumb sweep reads it (a "
    "session template relative to its folder), or the study as a dict (a template relative "
    "to the current folder).";

/// The study as the command reads it: parsed, with its session template read.
study::Study LoadStudy(const py::object& source) {
  std::string path = "<dict>";
  nlohmann::json doc;
  if (py::isinstance<py::dict>(source)) {
    doc = FromPython(source);
  } else {
    path = py::str(py::module_::import("os").attr("fspath")(source));
    doc = study::ReadStudyFile(path);
  }
  study::Study s = study::ParseStudy(doc, path);
  pipeline::ReadSessionTemplate(s, path == "<dict>" ? "" : fs::path(path).parent_path().string());
  return s;
}

/// Every run of point `index`, summarised: the point file's document.
nlohmann::json RunPoint(const study::Study& s, int index) {
  const std::vector<study::Point> points = study::DesignPoints(s);
  if (index < 0 || index >= static_cast<int>(points.size())) {
    throw Error("sweep_point: the study has points 0.." + std::to_string(points.size() - 1) +
                ", not " + std::to_string(index));
  }
  const study::Point& point = points[static_cast<std::size_t>(index)];
  std::vector<study::RunOutcome> outcomes;
  for (int r = 0; r < s.runs; ++r) outcomes.push_back(study::RunOnce(s, point, r));
  return study::PointJson(s, study::Summarise(point, outcomes, study::SensitivityFactors(s)));
}

nlohmann::json PointDocument(const py::object& source, int index) {
  const study::Study s = LoadStudy(source);
  py::gil_scoped_release release;
  return RunPoint(s, index);
}

}  // namespace

void RegisterSweep(py::module_& m) {
  m.def(
      "sweep_points",
      [](const py::object& source) { return study::DesignPoints(LoadStudy(source)).size(); },
      py::arg("study"),
      (std::string("The number of design points of a study (`plumb sweep` runs points 0..n-1).\n") +
       kStudyArg)
          .c_str());
  m.def(
      "sweep_point",
      [](const py::object& source, int index) { return ToPython(PointDocument(source, index)); },
      py::arg("study"), py::arg("index"),
      (std::string("Run point `index` (0-based) of a study: all its Monte Carlo runs, in order, "
                   "summarised (errors against the truth, sigmas, NEES per dof). Returns the "
                   "document `plumb sweep` writes to points/point-NNNNN.json, as a dict.\n") +
       kStudyArg)
          .c_str());
  m.def(
      "sweep_point_json",
      [](const py::object& source, int index) {
        return report::JsonText(PointDocument(source, index));
      },
      py::arg("study"), py::arg("index"),
      "As sweep_point, the document as text: byte for byte the command's point file (write it "
      "as DIR/points/point-NNNNN.json, with the study as DIR/study.json, for `plumb sweep "
      "merge`).");
  m.def(
      "study_json",
      [](const py::object& source) { return report::JsonText(LoadStudy(source).source); },
      py::arg("study"), "The study as `plumb sweep` writes it to DIR/study.json (text).");
}

}  // namespace plumb::python

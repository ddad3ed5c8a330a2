// Keyword arguments, sites and JSON between Python and C++: see common.h.
#include <pybind11/stl.h>

#include "common.h"
#include "plumb/core/error.h"

namespace plumb::python {
namespace {

const char* Keyword(Option option) {
  switch (option) {
    case Option::kTimeWindow: return "from_s/to_s";
    case Option::kSegments: return "segments";
    case Option::kRate: return "rate";
    case Option::kDropNan: return "drop_nan";
    case Option::kAccUnit: return "acc_unit";
    case Option::kAccScale: return "acc_scale";
    case Option::kAccOffset: return "acc_offset";
    case Option::kGyrUnit: return "gyr_unit";
    case Option::kGyrScale: return "gyr_scale";
    case Option::kGyrOffset: return "gyr_offset";
    case Option::kSite: return "site=(lat_deg, lon_deg, height_m)";
    case Option::kHeading: return "heading";
    case Option::kLevelNorth: return "level_north";
    case Option::kGravity: return "gravity";
    case Option::kMaxIterations: return "max_iterations";
    case Option::kEstimateWalk: return "estimate_rw";
    case Option::kAccelWalk: return "accel_rw";
    case Option::kGyroWalk: return "gyro_rw";
    case Option::kAccelInstability: return "accel_bi";
    case Option::kGyroInstability: return "gyro_bi";
    case Option::kSigma: return "sigma";
    case Option::kCalibrationJson: return "Result.save";
    case Option::kTopic: return "topic";
    case Option::kClock: return "clock";
    case Option::kImus: return "imus";
    case Option::kNoiseFrom:
    case Option::kExport:
    case Option::kExportUndetermined:
    case Option::kKeepGyroOffsets:
    case Option::kSystemId:
    case Option::kTruthJson: return "";  // the command's only
  }
  return "";
}

bool Placeholder(std::string_view value) {
  for (const char c : value) {
    if (c < 'A' || c > 'Z') return false;
  }
  return true;
}

}  // namespace

std::string SpellKeyword(Option option, std::string_view value) {
  const char* keyword = Keyword(option);
  if (*keyword == '\0') return LibrarySpelling(option, value);
  if (value.empty()) return keyword;
  const std::string text(value);
  return std::string(keyword) + "=" + (Placeholder(value) ? text : "\"" + text + "\"");
}

std::string SpellKeywordInText(Option option, std::string_view value) {
  // A switch reads as the keyword set: drop_nan=True, as the command's --drop-nan.
  const bool flag = option == Option::kDropNan || option == Option::kLevelNorth ||
                    option == Option::kEstimateWalk || option == Option::kSigma;
  if (flag && value.empty()) return std::string(Keyword(option)) + "=True";
  return SpellKeyword(option, value);
}

Keywords::Keywords(std::string function, const py::kwargs& kwargs)
    : function_(std::move(function)), kwargs_(kwargs) {}

bool Keywords::Given(const std::string& name) const {
  return kwargs_.contains(name.c_str()) && !kwargs_[name.c_str()].is_none();
}

void Keywords::Fail(const std::string& name, const py::object& value) const {
  throw Error(function_ + ": " + name + "=" + py::str(py::repr(value)).cast<std::string>() +
              " has the wrong type (" + py::str(py::type::of(value).attr("__name__")).cast<std::string>() +
              ")");
}

void Keywords::Finish() const {
  std::string unknown;
  for (const auto& item : kwargs_) {
    const std::string name = py::str(item.first).cast<std::string>();
    if (known_.count(name) == 0) unknown += (unknown.empty() ? "" : ", ") + name;
  }
  if (unknown.empty()) return;
  std::string names;
  for (const std::string& k : known_) names += (names.empty() ? "" : ", ") + k;
  throw Error(function_ + ": unknown option(s) " + unknown + "; the options are " + names);
}

std::optional<SiteInput> SiteFromPython(const py::object& site) {
  if (site.is_none()) return std::nullopt;
  SiteInput s;
  s.source = "flags";
  try {
    if (py::isinstance<py::dict>(site)) {
      const py::dict d = site;
      s.lat_deg = d["lat_deg"].cast<double>();
      s.lon_deg = d["lon_deg"].cast<double>();
      if (d.contains("height_m")) s.height_m = d["height_m"].cast<double>();
      return s;
    }
    const auto v = site.cast<std::vector<double>>();
    if (v.size() == 2 || v.size() == 3) {
      s.lat_deg = v[0];
      s.lon_deg = v[1];
      if (v.size() == 3) s.height_m = v[2];
      return s;
    }
  } catch (const py::error_already_set&) {
  } catch (const py::cast_error&) {
  }
  throw Error("site must be (lat_deg, lon_deg[, height_m]) or a dict with lat_deg, lon_deg[, "
              "height_m], got " + py::str(py::repr(site)).cast<std::string>());
}

py::object ToPython(const nlohmann::json& doc) {
  return py::module_::import("json").attr("loads")(doc.dump(-1, ' ', false,
                                                            nlohmann::json::error_handler_t::replace));
}

nlohmann::json FromPython(const py::handle& object) {
  const std::string text = py::module_::import("json").attr("dumps")(object).cast<std::string>();
  return nlohmann::json::parse(text);
}

}  // namespace plumb::python

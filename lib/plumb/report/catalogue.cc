#include "plumb/report/catalogue.h"

#include <cstdio>
#include <sstream>
#include <vector>

#include "plumb/report/json_report.h"

namespace plumb::report {
namespace {

std::vector<std::string> Selected(const model::Registry& registry, const std::string& only) {
  if (only.empty()) return registry.Names();
  registry.Make(only);  // throws naming the known effects when unknown
  return {only};
}

std::vector<std::string> ExcitationList(const model::Excitation& e) {
  std::vector<std::string> out;
  if (e.still_orientations) out.push_back("still poses in several orientations");
  if (e.rotation) out.push_back("turns between still poses");
  if (e.angular_acceleration) out.push_back("angular acceleration");
  if (e.temperature) out.push_back("a varying temperature");
  if (e.time) out.push_back("a long session");
  return out;
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

std::string EffectText(const model::EffectInfo& info) {
  std::ostringstream os;
  os << info.name << (info.linear_stage ? " (base)" : "") << " ["
     << (info.sensor == model::Sensor::kAccel ? "accelerometer" : "gyroscope") << "]\n";
  os << "  term:  " << info.term << "\n";
  const auto needs = ExcitationList(info.excitation);
  if (!needs.empty()) os << "  needs: " << Join(needs) << "\n";
  char line[200];
  for (int i = 0; i < info.size(); ++i) {
    const auto& p = info.parameters[static_cast<std::size_t>(i)];
    std::snprintf(line, sizeof line, "    %-34s %-22s typical %.2g\n",
                  info.ParameterName(i).c_str(), p.unit.c_str(), p.typical);
    os << line;
  }
  return os.str();
}

}  // namespace

std::string CatalogueText(const model::Registry& registry, const std::string& only) {
  std::ostringstream os;
  if (only.empty()) {
    os << "Effects of the error model; write a model as base+EFFECT[:OPTION]+... "
          "(e.g. base+gyro_g_sensitivity+accel_temperature_bias:2).\n\n";
  }
  for (const auto& name : Selected(registry, only)) {
    os << EffectText(registry.Make(name)->info()) << "\n";
  }
  return os.str();
}

nlohmann::json CatalogueJson(const model::Registry& registry, const std::string& only) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& name : Selected(registry, only)) {
    const auto effect = registry.Make(name);
    const auto& info = effect->info();
    nlohmann::json params = nlohmann::json::array();
    for (int i = 0; i < info.size(); ++i) {
      const auto& p = info.parameters[static_cast<std::size_t>(i)];
      params.push_back(
          {{"name", info.ParameterName(i)}, {"unit", p.unit}, {"typical", Number(p.typical)}});
    }
    out.push_back({{"name", info.name},
                   {"base", info.linear_stage},
                   {"sensor", info.sensor == model::Sensor::kAccel ? "accel" : "gyro"},
                   {"term", info.term},
                   {"excitation", ExcitationList(info.excitation)},
                   {"parameters", params}});
  }
  return out;
}

}  // namespace plumb::report

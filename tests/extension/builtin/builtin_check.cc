// Part of the Extension.BuiltinTakesOneFileAndOneLine test (run_builtin.cmake): with
// accel_scale_temperature.h in lib/plumb/model/effects/ and its name in effects.cmake, the
// library knows the effect by name with no Register() call in this program. Prints what it
// checks; returns 1 on the first failure.
#include <cmath>
#include <iostream>
#include <string>

#include "plumb/model/model.h"
#include "plumb/model/registry.h"

namespace {

bool Check(bool ok, const std::string& what) {
  std::cout << (ok ? "ok:     " : "FAILED: ") << what << "\n";
  return ok;
}

}  // namespace

int main() {
  using plumb::model::Model;
  using plumb::model::Registry;
  const auto& registry = Registry::Global();
  if (!Check(registry.Contains("accel_scale_temperature"),
             "Registry::Global() holds accel_scale_temperature")) {
    return 1;
  }
  const Model m = Model::Parse("base+accel_scale_temperature");
  if (!Check(m.spec() == "base+accel_scale_temperature", "spec reads back: " + m.spec())) {
    return 1;
  }
  const auto names = m.ParameterNames();
  if (!Check(names.back() == "accel_scale_temperature.s.z", "last parameter " + names.back())) {
    return 1;
  }
  // s.x = 2e-4 /degC, 10 degC above T_ref, x axis up: the x reading grows by 0.2 %.
  plumb::model::ParameterBlocks theta = m.ZeroParameters();
  theta[static_cast<std::size_t>(m.FindTerm("accel_scale_temperature"))][0] = 2e-4;
  plumb::model::SensorInput<double> in;
  in.f_b = plumb::Vec3(9.8, 0.0, 0.0);
  in.dtemp_c = 10.0;
  const double y_x = m.Predict(theta, in).acc.x();
  if (!Check(std::abs(y_x - 9.8 * 1.002) < 1e-12, "y_a.x = " + std::to_string(y_x))) return 1;
  return 0;
}

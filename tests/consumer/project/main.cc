// A program using the installed plumb: parse a model, predict, resolve a site, and reach the
// readers (plumb::io, the interface target of every io module).
#include <plumb/core/error.h>
#include <plumb/geo/site.h>
#include <plumb/io/input/open_inputs.h>
#include <plumb/model/model.h>

#include <cmath>
#include <cstdio>

int main() {
  const auto model = plumb::model::Model::Parse("base+gyro_g_sensitivity");
  plumb::model::SensorInput<double> in;
  in.f_b = plumb::Vec3(0, 0, -9.81);
  const auto out = model.Predict(model.ZeroParameters(), in);
  const auto site = plumb::geo::Site::At(51.64, -1.2, 100.0, "flags");
  bool io_ok = false;
  try {
    plumb::io::OpenInputs({});
  } catch (const plumb::Error&) {
    io_ok = true;  // no input
  }
  const bool ok = std::abs(out.acc.z() + 9.81) < 1e-12 && site.gravity() > 9.8 && io_ok;
  std::printf("%s: %d parameters, gravity %.6f\n", model.spec().c_str(), model.num_parameters(),
              site.gravity());
  return ok ? 0 : 1;
}

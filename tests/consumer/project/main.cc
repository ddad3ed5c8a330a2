// A program using the installed plumb: parse a model, predict, and resolve a site.
#include <plumb/geo/site.h>
#include <plumb/model/model.h>

#include <cmath>
#include <cstdio>

int main() {
  const auto model = plumb::model::Model::Parse("base+gyro_g_sensitivity");
  plumb::model::SensorInput<double> in;
  in.f_b = plumb::Vec3(0, 0, -9.81);
  const auto out = model.Predict(model.ZeroParameters(), in);
  const auto site = plumb::geo::Site::At(51.64, -1.2, 100.0, "flags");
  const bool ok = std::abs(out.acc.z() + 9.81) < 1e-12 && site.gravity() > 9.8;
  std::printf("%s: %d parameters, gravity %.6f\n", model.spec().c_str(), model.num_parameters(),
              site.gravity());
  return ok ? 0 : 1;
}

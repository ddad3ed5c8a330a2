#include "plumb/peers/plumb_result.h"

#include "plumb/core/error.h"

namespace plumb::peers {

PlumbResult PlumbResultFromDocument(const document::CalibrationDocument& d) {
  if (!d.accel) {
    throw InputError(d.path, "key 'accel'", "missing; expected {\"matrix\": ..., \"bias\": ...}");
  }
  PlumbResult r;
  static_cast<document::CalibrationDocument&>(r) = d;
  r.accel_matrix = d.accel->matrix;
  r.accel_bias = d.accel->bias;
  r.has_gyro = d.gyro.has_value();
  if (d.gyro) {
    r.gyro_matrix = d.gyro->matrix;
    r.gyro_bias = d.gyro->bias;
  }
  return r;
}

PlumbResult ReadPlumbResult(const std::string& path) {
  return PlumbResultFromDocument(document::ReadCalibrationDocumentFile(path));
}

const PlumbParameter* FindParameter(const PlumbResult& result, const std::string& name) {
  for (const auto& p : result.parameters) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

}  // namespace plumb::peers

#include "plumb/peers/plumb_result.h"

#include "plumb/core/error.h"

namespace plumb::peers {

PlumbResult PlumbResultFromDocument(const document::CalibrationDocument& d) {
  if (!d.accel) {
    throw InputError(d.path, "key 'accel'", "missing; expected {\"matrix\": ..., \"bias\": ...}");
  }
  PlumbResult r;
  r.path = d.path;
  r.method = d.method;
  r.model = d.model_spec;
  r.accel_matrix = d.accel->matrix;
  r.accel_bias = d.accel->bias;
  r.has_gyro = d.gyro.has_value();
  if (d.gyro) {
    r.gyro_matrix = d.gyro->matrix;
    r.gyro_bias = d.gyro->bias;
  }
  r.parameters = d.parameters;
  r.segments = d.segments;
  r.gravity_m_s2 = d.gravity_m_s2;
  r.site_source = d.site_source;
  r.chi2_dof = d.chi2_dof;
  r.dof = d.dof;
  r.noise_accel = d.noise_accel;
  r.inputs = d.inputs;
  r.covariance_names = d.covariance_names;
  r.covariance = d.covariance;
  r.sigma_scaled_by_chi2 = d.sigma_scaled_by_chi2;
  r.determined = d.determined;
  r.determined_covariance = d.determined_covariance;
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

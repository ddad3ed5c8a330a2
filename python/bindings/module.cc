// The extension plumb._plumb: every area's bindings registered on one module. The package
// plumb (python/plumb/__init__.py) re-exports it.
#include <glog/logging.h>

#include "common.h"
#include "plumb/report/version.h"

PYBIND11_MODULE(_plumb, m) {
  // Ceres reports through glog; plumb reports itself, so only fatal messages may print (as in
  // the command's main).
  if (!google::IsGoogleLoggingInitialized()) {
    FLAGS_minloglevel = google::GLOG_FATAL;
    FLAGS_logtostderr = true;
    google::InitGoogleLogging("plumb");
  }
  // The library's messages name options as this module's keywords (acc_unit="g").
  plumb::SetOptionSpeller(&plumb::python::SpellKeywordInText);
  m.doc() = "plumb: calibrate an IMU's accelerometer and gyroscope from real logs, with honest "
            "uncertainty (the library behind the plumb command). SI units throughout: s, m/s^2, "
            "rad/s, degC.";
  m.attr("__version__") = plumb::report::Version();
  plumb::python::RegisterErrors(m);
  plumb::python::RegisterSession(m);
  plumb::python::RegisterCalibrate(m);
  plumb::python::RegisterDiagnose(m);
  plumb::python::RegisterSimulate(m);
  plumb::python::RegisterSweep(m);
  plumb::python::RegisterApply(m);
}

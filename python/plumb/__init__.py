"""plumb: calibrate an IMU's accelerometer and gyroscope from real logs, with honest uncertainty.

The Python face of the plumb library (the extension plumb._plumb, built with pybind11 by the
project's CMake). SI units throughout: s, m/s^2, rad/s, degC. See docs/python.md.

    import plumb
    session = plumb.open("data/mikoff/imu0.log", columns="ax,ay,az,gx,gy,gz", rate=100)
    result = plumb.calibrate(session, model="base")
    result.parameters["accel.bias.x"].value, result.parameters["accel.bias.x"].sigma
"""

from ._plumb import (  # noqa: F401
    Calibration,
    Diagnosis,
    Error,
    InputError,
    InsufficientDataError,
    Result,
    Session,
    Simulation,
    __version__,
    calibrate,
    diagnose,
    load_calibration,
    open,
    simulate,
    study_json,
    sweep_point,
    sweep_point_json,
    sweep_points,
    write_csv,
)

__all__ = [
    "Calibration", "Diagnosis", "Error", "InputError", "InsufficientDataError", "Result",
    "Session", "Simulation", "calibrate", "diagnose", "load_calibration", "open", "simulate",
    "study_json", "sweep_point", "sweep_point_json", "sweep_points", "write_csv",
]

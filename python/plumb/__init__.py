"""plumb: calibrate an IMU's accelerometer and gyroscope from real logs, with honest uncertainty.

The Python face of the plumb library (the extension plumb._plumb, built with pybind11 by the
project's CMake). SI units throughout: s, m/s^2, rad/s, degC. See docs/python.md.

    import plumb
    session = plumb.open("data/mikoff/imu0.log", columns="ax,ay,az,gx,gy,gz", rate=100)
    result = plumb.calibrate(session, model="base")
    result.parameters["accel.bias.x"].value, result.parameters["accel.bias.x"].sigma
    f_b, omega_b = result.calibration.apply(session.acc, session.gyr)

`plumb.open` is not in __all__ (`from plumb import *` would shadow the builtin open): call it
as plumb.open.
"""

from ._plumb import (  # noqa: F401
    BoardImu,
    Calibration,
    Diagnosis,
    Error,
    InputError,
    InsufficientDataError,
    MissingFileError,
    PlumbWarning,
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
    "BoardImu", "Calibration", "Diagnosis", "Error", "InputError", "InsufficientDataError",
    "MissingFileError", "PlumbWarning", "Result", "Session", "Simulation", "calibrate",
    "diagnose", "load_calibration", "simulate", "study_json", "sweep_point", "sweep_point_json",
    "sweep_points", "write_csv",
]


def _from_dataframe(cls, df, time="time", acc=("ax", "ay", "az"), gyr=("gx", "gy", "gz"),
                    temp=None, *, acc_unit="m/s^2", gyr_unit="rad/s", drop_nan=False,
                    source="DataFrame"):
    """A session from a pandas DataFrame's columns, as Session.from_arrays makes one (the same
    checks, units and errors; pandas is imported only here).

    time: the column of sample times, s; None: the index (numbers, or datetimes: seconds since
          the epoch).
    acc: the three accelerometer columns (x, y, z) in acc_unit; gyr: the three gyroscope
         columns in gyr_unit, or None (accelerometer only); temp: the temperature column
         (degC) or None.
    acc_unit, gyr_unit, drop_nan, source: as from_arrays.
    Raises plumb.InputError naming the argument and the column when a column is missing.
    """
    import pandas as pd  # lazily: plumb does not need pandas

    if not isinstance(df, pd.DataFrame):
        raise TypeError(f"from_dataframe: df must be a pandas DataFrame, got {type(df).__name__}")

    def column(argument, name):
        if name not in df.columns:
            e = InputError(f"{source}: {argument}: no column {name!r} in the DataFrame "
                           f"(its columns: {', '.join(map(str, df.columns))}); give "
                           f"{argument}=... the column name(s)")
            e.file, e.where, e.option, e.options = source, "", None, ()
            raise e
        return df[name].to_numpy(dtype="float64")

    def triad(argument, names):
        if names is None:
            return None
        names = tuple(names)
        if len(names) != 3:
            raise InputError(f"{source}: {argument} must name three columns (x, y, z), "
                             f"got {names!r}")
        return __import__("numpy").column_stack([column(argument, n) for n in names])

    if time is None:
        index = df.index
        if isinstance(index, pd.DatetimeIndex):
            t = (index - pd.Timestamp(0, tz=index.tz)).total_seconds().to_numpy(dtype="float64")
        else:
            t = index.to_numpy(dtype="float64")
    else:
        t = column("time", time)
    return cls.from_arrays(t, triad("acc", acc), triad("gyr", gyr),
                           None if temp is None else column("temp", temp),
                           acc_unit=acc_unit, gyr_unit=gyr_unit, drop_nan=drop_nan,
                           source=source)


Session.from_dataframe = classmethod(_from_dataframe)
del _from_dataframe
